#!/usr/bin/python3
"""Renders one swirl .vtp frame to a PNG (3-D scatter coloured by speed).

Usage: render_frame.py FRAME.vtp OUT.png [--box xmin ymin zmin xmax ymax zmax] [--title TEXT]
Needs Debian's python3-vtk9 and python3-matplotlib. Used for the README picture:
  make demo
  tools/render_frame.py out/demo/particles_000020.vtp docs/images/dam_break.png --box 0 0 0 1 0.5 0.6
  (falling_block.png: examples/falling_block.toml, frame 18, --box 0 0 0 1 1 1)
"""
import argparse

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("frame")
    ap.add_argument("out")
    ap.add_argument("--box", type=float, nargs=6)
    ap.add_argument("--title", default=None)
    args = ap.parse_args()

    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(args.frame)
    reader.Update()
    poly = reader.GetOutput()
    x = vtk_to_numpy(poly.GetPoints().GetData()).astype(float)
    speed = np.linalg.norm(vtk_to_numpy(poly.GetPointData().GetArray("velocity")).astype(float), axis=1)
    time = poly.GetFieldData().GetArray("TimeValue").GetValue(0)

    fig = plt.figure(figsize=(6, 5), dpi=110)
    ax = fig.add_subplot(projection="3d")
    sc = ax.scatter(x[:, 0], x[:, 1], x[:, 2], c=speed, s=2, cmap="viridis", depthshade=False)
    if args.box:
        lo, hi = np.array(args.box[:3]), np.array(args.box[3:])
        ax.set_xlim(lo[0], hi[0]); ax.set_ylim(lo[1], hi[1]); ax.set_zlim(lo[2], hi[2])
        for a in range(3):  # the box's twelve edges
            for b in (lo, hi):
                for c in (lo, hi):
                    p, q = np.array(lo, dtype=float), np.array(hi, dtype=float)
                    o = [i for i in range(3) if i != a]
                    p[o[0]] = q[o[0]] = b[o[0]]
                    p[o[1]] = q[o[1]] = c[o[1]]
                    ax.plot(*zip(p, q), color="0.6", lw=0.6)
    ax.set_xlabel("x (m)"); ax.set_ylabel("y (m)"); ax.set_zlabel("z (m)")
    fig.colorbar(sc, ax=ax, shrink=0.6, label="speed (m/s)")
    ax.set_title(args.title or f"{len(x)} particles, t = {time:.2f} s")
    fig.tight_layout()
    fig.savefig(args.out)


if __name__ == "__main__":
    main()
