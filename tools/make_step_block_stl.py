#!/usr/bin/env python3
"""Writes examples/step_block.stl: the stepped block of examples/dam_break_mesh.toml.

A block with two steps, in millimetres (the scene scales it by 0.001): in x-z
the L-shaped profile (0, 0), (240, 0), (240, 80), (120, 80), (120, 160),
(0, 160), extruded from y = 0 to 200. Its ends are fanned from the inner corner
(120, 80), so that no vertex lies on another triangle's edge; every facet is
counter-clockwise seen from outside, its normal pointing out. ASCII STL, the
same geometry as tests/scene/mesh_test_util.hpp's step_block().

Usage: tools/make_step_block_stl.py [OUT]   (default examples/step_block.stl)
"""
import sys
from pathlib import Path

from ascii_stl import write_ascii_stl

PROFILE = [(0, 0), (240, 0), (240, 80), (120, 80), (120, 160), (0, 160)]
WIDTH = 200


def vertices():
    return [(x, y, z) for y in (0, WIDTH) for (x, z) in PROFILE]


def triangles():
    out = []
    # The profile runs counter-clockwise in (x, z), whose normal x × z is -y:
    # the fan faces out at y = 0 as it is and is reversed at y = WIDTH.
    for a, b in [(4, 5), (5, 0), (0, 1), (1, 2)]:
        out.append((3, a, b))
        out.append((9, 6 + b, 6 + a))
    for k in range(6):  # the sides: y × (b - a) points out of the profile
        a, b = k, (k + 1) % 6
        out.append((a, 6 + b, b))
        out.append((a, 6 + a, 6 + b))
    return out


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "examples" / "step_block.stl"
    write_ascii_stl(out, "step_block", vertices(), triangles())


if __name__ == "__main__":
    main()
