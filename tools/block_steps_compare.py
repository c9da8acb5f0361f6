#!/usr/bin/env python3
"""Block time steps against the global adaptive step at matched energy error.

Runs `swirl run` on a scene with simulation.time_steps = "block" and with
dt = "adaptive" for several values of eta each, alternating the two methods
(rounds x methods x etas), and prints per run: eta, |dE/E| at the end,
particle-force evaluations, sub-steps, wall seconds (median over rounds).
Then, for each block run, the global run of nearest energy error, and the
ratios of evaluations and wall time. Writes a CSV with every run.

  /usr/bin/python3 tools/block_steps_compare.py --scene examples/galaxy_collision.toml \\
      --set 'nbody.scheme="global"' --until 28 --etas 0.05,0.1,0.2,0.4 --rounds 3 --out out/block-steps

The figures quoted in docs/performance/block-steps.md come from this script.
"""
import argparse
import csv
import pathlib
import re
import shutil
import statistics
import subprocess
import sys


def run(swirl, scene, sets, until, threads, method, eta, dt, max_bin, out):
    if out.exists():
        shutil.rmtree(out)
    cmd = [swirl, "run", scene, "--until", str(until), "--threads", str(threads), "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    cmd += ["--set", f"simulation.eta={eta}"]
    if method == "block":
        cmd += ["--set", 'simulation.time_steps="block"', "--set", f"simulation.dt={dt}",
                "--set", f"simulation.max_bin={max_bin}"]
    else:
        cmd += ["--set", 'simulation.dt="adaptive"', "--set", f"simulation.dt_max={dt}"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    text = r.stdout + r.stderr

    def metric(name, default=None):
        m = re.search(rf"^\s*{name}\s+(\S+)", text, re.M)
        if not m:
            if default is not None:
                return default
            sys.exit(f"no '{name}' in the summary of {' '.join(cmd)}:\n{text}")
        return float(m.group(1).rstrip("s"))

    return {
        "method": method, "eta": eta,
        "energy_error": abs(metric("relative_energy_error")),
        "evaluations": metric("particle_force_evaluations"),
        "sub_steps": metric("block_sub_steps", 0.0),
        "wall_seconds": metric("wall time"),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--swirl", default="build/swirl")
    ap.add_argument("--scene", required=True)
    ap.add_argument("--set", action="append", default=[], help="a scene override, as swirl run --set")
    ap.add_argument("--until", type=float, required=True)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--dt", type=float, default=0.0625, help="block: the largest step; global: dt_max")
    ap.add_argument("--max-bin", type=int, default=16)
    ap.add_argument("--etas", default="0.05,0.1,0.2,0.4")
    ap.add_argument("--global-etas", default=None, help="etas of the global runs (default: --etas)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--out", default="out/block-steps")
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    etas = {"block": [float(x) for x in a.etas.split(",")],
            "global": [float(x) for x in (a.global_etas or a.etas).split(",")]}
    runs = {}
    for r in range(a.rounds):
        for method in ("block", "global") if r % 2 == 0 else ("global", "block"):
            for eta in etas[method]:
                res = run(a.swirl, a.scene, a.set, a.until, a.threads, method, eta, a.dt, a.max_bin, out / "run")
                runs.setdefault((method, eta), []).append(res)
                print(f"round {r} {method:6s} eta={eta:<6g} |dE/E|={res['energy_error']:.3e} "
                      f"evaluations={res['evaluations']:.4g} wall={res['wall_seconds']:.2f}s", flush=True)
    rows = []
    for (method, eta), rs in sorted(runs.items()):
        rows.append({"method": method, "eta": eta, "energy_error": rs[0]["energy_error"],
                     "evaluations": rs[0]["evaluations"], "sub_steps": rs[0]["sub_steps"],
                     "wall_median": statistics.median(x["wall_seconds"] for x in rs),
                     "walls": " ".join(f"{x['wall_seconds']:.2f}" for x in rs)})
    with open(out / "runs.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print("\nmethod  eta     |dE/E|     evaluations  sub-steps  wall (median)")
    for x in rows:
        print(f"{x['method']:7s} {x['eta']:<7g} {x['energy_error']:.3e}  {x['evaluations']:11.4g}  "
              f"{x['sub_steps']:9.0f}  {x['wall_median']:.2f} s")
    # Matched accuracy: interpolate the global runs' log cost against log error
    # at each block run's error (the errors of the two rarely coincide).
    import math
    glob = sorted((x for x in rows if x["method"] == "global"), key=lambda x: x["energy_error"])
    print("\nblock run -> global cost interpolated at the same |dE/E|: evaluations ratio, wall ratio (global / block)")
    for b in (x for x in rows if x["method"] == "block"):
        e = b["energy_error"]
        pair = None
        for lo, hi in zip(glob, glob[1:]):
            if lo["energy_error"] <= e <= hi["energy_error"]:
                pair = (lo, hi)
        if not pair:
            print(f"  eta={b['eta']:<6g} |dE/E|={e:.3e}: outside the global runs' range")
            continue
        lo, hi = pair
        f = (math.log(e) - math.log(lo["energy_error"])) / (math.log(hi["energy_error"]) - math.log(lo["energy_error"]))
        def interp(k):
            return math.exp(math.log(lo[k]) + f * (math.log(hi[k]) - math.log(lo[k])))
        print(f"  eta={b['eta']:<6g} |dE/E|={e:.3e}: evaluations {interp('evaluations') / b['evaluations']:.2f}x, "
              f"wall {interp('wall_median') / b['wall_median']:.2f}x")


if __name__ == "__main__":
    main()
