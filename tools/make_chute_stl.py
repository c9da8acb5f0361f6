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

from ascii_stl import write_ascii_stl

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


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent / "examples" / "chute.stl"
    write_ascii_stl(out, "chute", vertices(), triangles())


if __name__ == "__main__":
    main()
