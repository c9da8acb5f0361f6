#!/usr/bin/env python3
"""The MPI path against threads on one machine (issue 19's strong-scaling yardstick).

Runs one scene as 1 rank x T threads and as R ranks x (T/R) threads (mpirun),
alternately, ROUNDS times, and prints the medians of the stepping time (the
run's wall time less its frame writing) and of the steps alone (less also the
first evaluation, phase "start") and of each phase, with the ratio of
medians (ranks / threads). Results are the runs' --summary-json files in OUT.

    /usr/bin/python3 tools/bench_ranks.py --swirl build/swirl --scene bench/dfsph/dam_break.toml \\
        --set 'sph.method="wcsph"' --set particles.0.spacing=0.004 --set sph.smoothing_length=0.008 \\
        --steps 20 --rounds 3 --out /tmp/ranks

Both codes use the same binary (built with -DSWIRL_MPI=ON); --other BIN adds
another build's ranks run to every round (two builds compared alternately). As root, the
OpenMPI variables that allow it are set for mpirun here.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path


def run(cmd, summary: Path, env) -> dict:
    t0 = time.time()
    done = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit(f"failed ({done.returncode}): {' '.join(map(str, cmd))}\n{done.stderr[-2000:]}")
    result = json.loads(summary.read_text())
    result["outside_seconds"] = time.time() - t0
    return result


def stepping(summary: dict) -> float:
    return summary["wall_seconds"] - summary.get("phase_seconds", {}).get("output", 0.0)


def steps_only(summary: dict) -> float:
    """Stepping less the first evaluation (phase "start": on ranks also the first distribution)."""
    return stepping(summary) - summary.get("phase_seconds", {}).get("start", 0.0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--swirl", default="build/swirl")
    ap.add_argument("--mpiexec", default="mpiexec")
    ap.add_argument("--scene", required=True)
    ap.add_argument("--set", action="append", default=[], help="a scene override, as swirl run --set")
    ap.add_argument("--steps", type=int, required=True)
    ap.add_argument("--threads", type=int, default=2, help="the machine's cores: T")
    ap.add_argument("--ranks", type=int, default=2, help="R (T/R threads each)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--other", action="append", default=[], metavar="BIN",
                    help="another build's swirl, run as R ranks too in every round (its medians and ratio "
                         "against the threaded run printed beside): compares two builds alternately")
    ap.add_argument("--out", type=Path, required=True)
    args = ap.parse_args()

    args.out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    sets = [a for s in args.set for a in ("--set", s)]
    per_rank = max(1, args.threads // args.ranks)
    others = {f"ranks:{b}": b for b in args.other}
    results = {"threads": [], "ranks": [], **{m: [] for m in others}}
    for r in range(args.rounds):
        for mode in results:
            out = args.out / f"{mode.replace('/', '_').replace(':', '_')}_{r}"
            summary = Path(f"{out}.json")
            common = ["run", args.scene, *sets, "--steps", str(args.steps), "--out", str(out), "--overwrite",
                      "--summary-json", str(summary)]
            if mode == "threads":
                cmd = [args.swirl, *common, "--threads", str(args.threads)]
            else:
                cmd = [args.mpiexec, "-n", str(args.ranks), "--bind-to", "none", others.get(mode, args.swirl),
                       *common, "--threads", str(per_rank)]
            load = os.getloadavg()[0]
            s = run(cmd, summary, env)
            s["load_before"] = load
            results[mode].append(s)
            print(f"[{time.strftime('%H:%M:%S')}] round {r} {mode}: {stepping(s):.2f} s stepping "
                  f"(load {load:.2f})", flush=True)
    (args.out / "results.json").write_text(json.dumps(results, indent=1))

    med = {m: statistics.median(stepping(s) for s in results[m]) for m in results}
    print(f"\n1 rank x {args.threads} threads against {args.ranks} ranks x {per_rank}: "
          f"stepping {med['threads']:.2f} s against {med['ranks']:.2f} s, ratio {med['ranks'] / med['threads']:.3f}")
    print("runs:", ", ".join(f"{stepping(s):.2f}" for s in results["threads"]), "|",
          ", ".join(f"{stepping(s):.2f}" for s in results["ranks"]))
    steps = {m: statistics.median(steps_only(s) for s in results[m]) for m in results}
    print(f"the steps alone (less the first evaluation, phase start): {steps['threads']:.2f} s against "
          f"{steps['ranks']:.2f} s, ratio {steps['ranks'] / steps['threads']:.3f}")
    for m in others:
        print(f"{m}: stepping {med[m]:.2f} s (ratio {med[m] / med['threads']:.3f}), the steps alone "
              f"{steps[m]:.2f} s (ratio {steps[m] / steps['threads']:.3f})")
    phases = sorted({p for m in results for s in results[m] for p in s.get("phase_seconds", {})})
    print(f"\n| phase | 1 x {args.threads} (s) | {args.ranks} x {per_rank} (s) |\n|---|---:|---:|")
    for p in phases:
        a = statistics.median(s.get("phase_seconds", {}).get(p, 0.0) for s in results["threads"])
        b = statistics.median(s.get("phase_seconds", {}).get(p, 0.0) for s in results["ranks"])
        print(f"| {p} | {a:.2f} | {b:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
