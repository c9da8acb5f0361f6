"""Two Plummer spheres colliding, rendered to a PNG sequence.

The scene of examples/galaxy_collision.toml at fewer stars and a shorter
time, run into a run folder exactly as `swirl run` makes it (swirl.run), then
every frame drawn as `swirl render` draws it (swirl.render), the surface
density seen from above. Make a movie with
`ffmpeg -i OUT/png/frame_%04d.png collision.mp4`.

    build-python/venv/bin/python examples/python/galaxy_collision.py [--count 4096] [--until 20]

About 40 s here at the defaults.
"""

import argparse
import os
import pathlib

import swirl

REPO = pathlib.Path(__file__).resolve().parents[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/python/galaxy_collision")
    parser.add_argument("--count", type=int, default=4096, help="stars in both spheres")
    parser.add_argument("--until", type=float, default=20.0, help="end time (N-body units)")
    args = parser.parse_args()

    scene = swirl.Scene.from_file(REPO / "examples" / "galaxy_collision.toml",
                                  overrides=[f"particles.0.count={args.count}", "output.interval=1.0"])
    run_dir = os.path.join(args.out, "run")
    summary = swirl.run(scene, run_dir, until=args.until, overwrite=True)
    if summary["error"]:
        raise SystemExit(summary["error"])
    png_dir = os.path.join(args.out, "png")
    os.makedirs(png_dir, exist_ok=True)
    for k in range(summary["frames"]):
        swirl.render(run_dir, k, view="top", size=(640, 480), png=os.path.join(png_dir, f"frame_{k:04d}.png"))
    print(f"{summary['steps']} steps in {summary['wall_seconds']:.1f} s; {summary['frames']} pictures in {png_dir}")


if __name__ == "__main__":
    main()
