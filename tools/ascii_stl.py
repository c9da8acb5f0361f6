"""ASCII STL writing shared by the scripts that make the example meshes
(tools/make_step_block_stl.py, tools/make_chute_stl.py)."""


def facet_normal(p, q, r):
    """The unit normal of triangle (p, q, r), counter-clockwise seen from its front."""
    u = [q[i] - p[i] for i in range(3)]
    v = [r[i] - p[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    length = sum(c * c for c in n) ** 0.5
    return [c / length + 0.0 for c in n]


def write_ascii_stl(path, name, vertices, triangles):
    """Writes the triangles (index triples into vertices) as the solid `name`."""
    lines = [f"solid {name}"]
    for t in triangles:
        n = facet_normal(*(vertices[i] for i in t))
        lines.append("  facet normal {:g} {:g} {:g}".format(*n))
        lines.append("    outer loop")
        for i in t:
            lines.append("      vertex {:g} {:g} {:g}".format(*vertices[i]))
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append(f"endsolid {name}")
    path.write_text("\n".join(lines) + "\n")
    print(f"wrote {path}: {len(triangles)} triangles")
