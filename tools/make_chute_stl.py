#!/usr/bin/env python3
"""Writes examples/chute.stl: the chute of examples/tap.toml.

A flat plate 300 mm long (x), 200 mm wide (y) and 10 mm thick (z), in
millimetres (the scene scales it by 0.001 and tilts it): a closed box of 8
corners and 12 triangles, every facet counter-clockwise seen from outside, its
normal pointing out. ASCII STL.

Usage: tools/make_chute_stl.py [OUT]   (default examples/chute.stl)
"""
import sys
from pathlib import Path

SIZE = (300, 200, 10)


def vertices():
    return [(SIZE[0] * (k & 1), SIZE[1] * ((k >> 1) & 1), SIZE[2] * ((k >> 2) & 1)) for k in range(8)]


def triangles():
    # Faces as quads counter-clockwise from outside, split along their first diagonal.
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    out = []
    for a, b, c, d in quads:
        out.append((a, b, c))
        out.append((a, c, d))
    return out


def normal(p, q, r):
    u = [q[i] - p[i] for i in range(3)]
    v = [r[i] - p[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    length = sum(c * c for c in n) ** 0.5
    return [c / length + 0.0 for c in n]


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "examples" / "chute.stl"
    v = vertices()
    lines = ["solid chute"]
    for t in triangles():
        n = normal(*(v[i] for i in t))
        lines.append("  facet normal {:g} {:g} {:g}".format(*n))
        lines.append("    outer loop")
        for i in t:
            lines.append("      vertex {:g} {:g} {:g}".format(*v[i]))
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append("endsolid chute")
    out.write_text("\n".join(lines) + "\n")
    print(f"wrote {out}: {len(triangles())} triangles")


if __name__ == "__main__":
    main()
