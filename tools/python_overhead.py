"""What stepping from Python costs over the swirl CLI: docs/performance/python.md.

Runs the same SPH scene (the dam break at ~35 000 particles) alternately
  cli      build/swirl run --steps N: stepping time = wall_seconds - the output phase
           (the summary's own figures: set-up and the two frames are left out)
  step(N)  swirl.Simulation(scene).step(N): one call, the loop in C++
  step(1)  a Python for loop of N sim.step(1) calls (the GIL taken and released each step)
  callback sim.run(steps=N, every=1, callback=f) with f reading one field view each step
and prints the median of each and its ratio to the CLI's median. Run with the
module's venv: build-python/venv/bin/python tools/python_overhead.py [--rounds 5] [--steps 100] [--threads N]
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

REPO = pathlib.Path(__file__).resolve().parents[1]
import swirl


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--steps", type=int, default=100)
    parser.add_argument("--spacing", type=float, default=0.012, help="the water block's spacing (0.012 m: ~35 000)")
    parser.add_argument("--cli", default=str(REPO / "build" / "swirl"))
    parser.add_argument("--threads", type=int, default=None, help="threads for both (default: all cores)")
    args = parser.parse_args()
    if args.threads:
        swirl.set_threads(args.threads)

    sets = [f"particles.0.spacing={args.spacing}", "output.interval=0"]
    scene_file = REPO / "examples" / "dam_break.toml"
    scene = swirl.Scene.from_file(scene_file, overrides=sets)
    count = swirl.Simulation(scene).count
    print(f"dam break, {count} particles, {args.steps} steps, {swirl.threads()} threads, {args.rounds} rounds")

    def cli():
        with tempfile.TemporaryDirectory() as tmp:
            summary = pathlib.Path(tmp) / "summary.json"
            words = [args.cli, "run", str(scene_file), *[w for s in sets for w in ("--set", s)],
                     "--steps", str(args.steps), "--out", os.path.join(tmp, "run"), "--summary-json", str(summary),
                     "--threads", str(swirl.threads())]
            subprocess.run(words, check=True, capture_output=True)
            s = json.loads(summary.read_text())
            assert s["particles"] == count and s["steps"] == args.steps
            return s["wall_seconds"] - s["phase_seconds"].get("output", 0.0)

    def step_n():
        sim = swirl.Simulation(scene)
        t = time.perf_counter()
        sim.step(args.steps)
        return time.perf_counter() - t

    def step_1():
        sim = swirl.Simulation(scene)
        t = time.perf_counter()
        for _ in range(args.steps):
            sim.step(1)
        return time.perf_counter() - t

    def callback():
        sim = swirl.Simulation(scene)
        seen = []
        t = time.perf_counter()
        sim.run(steps=args.steps, every=1, callback=lambda s: seen.append(float(s.particles.position.z[0])))
        elapsed = time.perf_counter() - t
        assert len(seen) == args.steps
        return elapsed

    ways = {"cli": cli, "step(N)": step_n, "step(1)": step_1, "callback": callback}
    times = {name: [] for name in ways}
    for r in range(args.rounds):
        for name, way in ways.items():
            times[name].append(way())
        print(f"round {r + 1}: " + ", ".join(f"{n} {times[n][-1]:.3f} s" for n in ways), flush=True)
    base = statistics.median(times["cli"])
    print("\n| way | median s | over the CLI |\n|---|---|---|")
    for name in ways:
        m = statistics.median(times[name])
        print(f"| {name} | {m:.3f} | {100 * (m / base - 1):+.2f} % |")


if __name__ == "__main__":
    main()
