#!/usr/bin/env python3
"""The DFSPH benchmark of docs/performance/dfsph.md: swirl's DFSPH, the
thesis's solver (wcsph) and SPlisHSPlasH's DFSPH on the same dam break
(bench/dfsph/dam_break.toml), run alternately and repeated, on the same
threads.

    /usr/bin/python3 tools/bench_dfsph.py --out /tmp/dfsph-bench \
        --sizes 1e5 --until 0.1 --repeats 2
    /usr/bin/python3 tools/bench_dfsph.py --out /tmp/dfsph-bench \
        --sizes 1e6 --until 0.01 --repeats 2
    /usr/bin/python3 tools/bench_dfsph.py --out /tmp/dfsph-bench --table-only

The peer needs a venv with the pysplishsplash wheel (tools/bench_dfsph_peer.py
says how); --peer-python names its python (or --no-peer).

Per run: the wall time of the steps (swirl: the run's wall time less its
frame writing, its start()'s first evaluation included; the peer: its
stepping loop), the CPU time of the steps (all threads; swirl's process less
that of a run which only starts and writes the same two frames, the peer's
stepping loop), steps, simulated time, the
solves' iterations per step, the average compression
mean(max(ρ − ρ0, 0))/ρ0 of the fluid at the end (and for DFSPH the solver's
own figures), and the load average (`uptime`) before and after. Nothing here
asserts a time: it records them. Results: OUT/results.json and
OUT/results.md (medians and ratios of medians).
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "bench/dfsph/dam_break.toml"
# Fluid spacing and h = 2 spacings for each size (the column 0.32 x 0.48 x 0.40 m).
SIZES = {"1e5": (0.008, 0.016), "1e6": (0.004, 0.008)}


def load() -> str:
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def size_flags(size: str) -> list[str]:
    spacing, h = SIZES[size]
    return ["--set", f"particles.0.spacing={spacing}", "--set", f"sph.smoothing_length={h}"]


def frame_figures(path: Path, rho0: float = 1000.0) -> dict:
    """Of a swirl CSV frame: the mean and largest max(ρ − ρ0, 0)/ρ0 over the fluid, its
    count, its fastest speed and how many fluid particles lie beyond the walls' particles."""
    total, worst, n, vmax = 0.0, 0.0, 0, 0.0
    fluid_xyz, lo, hi = [], [float("inf")] * 3, [float("-inf")] * 3
    with open(path, newline="") as f:
        first = f.readline()
        if not first.startswith("#"):
            f.seek(0)
        reader = csv.reader(f)
        header = next(reader)
        idens, ikind = header.index("density"), header.index("kind")
        ix = [header.index(c) for c in ("x", "y", "z")]
        iv = [header.index(c) for c in ("velocity_x", "velocity_y", "velocity_z")]
        for row in reader:
            p = [float(row[i]) for i in ix]
            if row[ikind] != "0":
                lo = [min(a, b) for a, b in zip(lo, p)]
                hi = [max(a, b) for a, b in zip(hi, p)]
                continue
            fluid_xyz.append(p)
            c = max(float(row[idens]) - rho0, 0.0) / rho0
            total += c
            worst = max(worst, c)
            n += 1
            vmax = max(vmax, sum(float(row[i]) ** 2 for i in iv) ** 0.5)
    outside = sum(1 for p in fluid_xyz if any(p[a] < lo[a] or p[a] > hi[a] for a in range(3)))
    return {"final_compression": total / n if n else 0.0, "final_max_compression": worst, "fluid_particles": n,
            "max_speed_end": vmax, "fluid_outside_walls_end": outside}


def run_child(cmd: list[str], env: dict, log: Path) -> tuple[int, float, float]:
    """Run a command; return (exit status, wall seconds, CPU seconds of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    with open(log, "w") as out:
        rc = subprocess.call(cmd, env=env, stdout=out, stderr=subprocess.STDOUT)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return rc, wall, cpu


def initial_frame(args, size: str) -> Path:
    out = args.out / f"ic_{size}"
    frame = out / "particles_000000.csv"
    if frame.exists():
        return frame
    cmd = [str(args.swirl), "run", str(SCENE), "--threads", str(args.threads), "--steps", "1", "--out", str(out),
           "--overwrite", "--set", "simulation.dt_max=1e-5", "--set", 'output.format="csv"'] + size_flags(size)
    subprocess.check_call(cmd, stdout=subprocess.DEVNULL)
    return frame


def frames_cpu(args, size: str) -> float:
    """CPU seconds of a swirl run that only starts and writes its two CSV frames (one 10 µs
    step): what swirl's CPU time carries besides its steps. Measured once per size."""
    cached = args.out / f"frames_cpu_{size}.json"
    if cached.exists():
        return json.loads(cached.read_text())["cpu_seconds"]
    out = args.out / f"frames_cpu_{size}"
    cmd = [str(args.swirl), "run", str(SCENE), "--threads", str(args.threads), "--steps", "1", "--out", str(out),
           "--overwrite", "--set", "simulation.dt_max=1e-5", "--set", 'output.format="csv"'] + size_flags(size)
    rc, wall, cpu = run_child(cmd, dict(os.environ, OMP_NUM_THREADS=str(args.threads)), args.out / f"frames_cpu_{size}.log")
    if rc != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({rc})")
    for f in out.glob("particles_*.csv"):
        f.unlink()
    cached.write_text(json.dumps({"cpu_seconds": cpu, "wall_seconds": wall, "load": load()}) + "\n")
    return cpu


def run_swirl(args, size: str, method: str, rep: int) -> dict:
    out = args.out / f"swirl_{method}_{size}_{rep}"
    summary = args.out / f"swirl_{method}_{size}_{rep}.json"
    cmd = [str(args.swirl), "run", str(SCENE), "--threads", str(args.threads), "--until", str(args.until),
           "--out", str(out), "--overwrite", "--summary-json", str(summary), "--on-blowup=warn",
           "--set", 'output.format="csv"', "--set", f'sph.method="{method}"'] + size_flags(size)
    env = dict(os.environ, OMP_NUM_THREADS=str(args.threads))
    load_before = load()
    rc, wall, cpu = run_child(cmd, env, args.out / f"swirl_{method}_{size}_{rep}.log")
    load_after = load()
    s = json.loads(summary.read_text())
    output = s["phase_seconds"].get("output", 0.0)
    frames = sorted(out.glob("particles_*.csv"))
    figures = frame_figures(frames[-1])
    metrics = {k: v for k, v in s.items() if k.startswith("dfsph_")}
    r = {
        "code": f"swirl {method}", "size": size, "rep": rep, "exit": rc, **figures,
        "particles": s["particles"], "steps": s["steps"], "sim_time": s["sim_time"],
        "wall_seconds": s["wall_seconds"] - output, "output_seconds": output, "process_wall": wall,
        "cpu_seconds": cpu, "failed_checks": len(s.get("failed_checks", [])),
        "load_before": load_before, "load_after": load_after, "phase_seconds": s["phase_seconds"],
        "min_dt": s.get("smallest_dt"), "largest_dt": s.get("largest_dt"), **metrics,
    }
    for f in frames[1:-1]:
        f.unlink()
    if not args.keep:
        for f in frames:
            f.unlink()
    return r


def run_peer(args, size: str, rep: int, frame: Path) -> dict:
    out = args.out / f"peer_{size}_{rep}"
    result = args.out / f"peer_{size}_{rep}.json"
    cmd = [str(args.peer_python), str(ROOT / "tools/bench_dfsph_peer.py"), "--frame", str(frame),
           "--spacing", str(SIZES[size][0]), "--until", str(args.until), "--out", str(out), "--json", str(result),
           "--walls", args.peer_walls]
    env = dict(os.environ, OMP_NUM_THREADS=str(args.threads))
    load_before = load()
    rc, wall, cpu = run_child(cmd, env, args.out / f"peer_{size}_{rep}.log")
    load_after = load()
    if rc != 0:
        raise SystemExit(f"the peer failed (exit {rc}): see {args.out / f'peer_{size}_{rep}.log'}")
    r = json.loads(result.read_text())
    for name in ("fluid.geo", "walls.geo"):
        (out / name).unlink(missing_ok=True)
    r.update({"code": peer_label(r), "size": size, "rep": rep, "process_wall": wall, "cpu_seconds": cpu,
              "load_before": load_before, "load_after": load_after})
    return r


PEER = "SPlisHSPlasH dfsph"
PEER_SWIRL_WALLS = "SPlisHSPlasH dfsph, swirl's walls"


def peer_label(r: dict) -> str:
    # Results from before the peer sampled its own walls carry no "walls": they had swirl's.
    return PEER_SWIRL_WALLS if r.get("walls", "swirl's particles") == "swirl's particles" else PEER


FRAMES_CPU: dict = {}


def stepping_cpu(r: dict) -> float:
    """CPU seconds of the steps: the peer's loop as it measured it (older results: the whole
    process); swirl's process less a run that only starts and writes its two frames."""
    if r["code"].startswith(PEER):
        return r.get("cpu_seconds_in_process", r["cpu_seconds"])
    return r["cpu_seconds"] - FRAMES_CPU.get(r["size"], 0.0)


def median(rows, key):
    vals = [r[key] for r in rows if r.get(key) is not None]
    return statistics.median(vals) if vals else None


def table(results: list[dict]) -> str:
    lines = ["| size | code | runs | fluid (+ boundary) | steps | mean Δt (ms) | wall s / sim s (median; runs) | "
             "wall s / step | CPU s / sim s | density it./step | divergence it./step | final mean compression | "
             "load (before–after) |", "|" + "---|" * 13]
    by = {}
    for r in results:
        if r["code"].startswith(PEER):
            r["code"] = peer_label(r)
        by.setdefault((r["size"], r["code"]), []).append(r)
    for (size, code), rows in sorted(by.items()):
        per_sim = [r["wall_seconds"] / r["sim_time"] for r in rows]
        cpu_sim = [stepping_cpu(r) / r["sim_time"] for r in rows]
        per_step = [r["wall_seconds"] / r["steps"] for r in rows]
        if code.startswith(PEER):
            it = median(rows, "mean_density_iterations")
            itv = median(rows, "mean_divergence_iterations")
            boundary = rows[0].get("boundary_particles")
        else:
            it = median(rows, "dfsph_mean_density_iterations")
            itv = median(rows, "dfsph_mean_divergence_iterations")
            boundary = rows[0]["particles"] - rows[0]["fluid_particles"]
        lines.append(
            f"| {size} | {code} | {len(rows)} | {rows[0]['fluid_particles']} (+{boundary}) | {rows[0]['steps']} | "
            f"{1e3 * rows[0]['sim_time'] / rows[0]['steps']:.3f} | {statistics.median(per_sim):.0f} "
            f"({', '.join(f'{x:.0f}' for x in per_sim)}) | {statistics.median(per_step):.2f} | "
            f"{statistics.median(cpu_sim):.0f} | {'–' if it is None else f'{it:.1f}'} | "
            f"{'–' if itv is None else f'{itv:.1f}'} | {100 * median(rows, 'final_compression'):.3f} % | "
            f"{'; '.join(r['load_before'].split()[0] + '–' + r['load_after'].split()[0] for r in rows)} |")
    lines.append("")
    for size in sorted({r["size"] for r in results}):
        med = {}
        for code in ("swirl dfsph", "swirl wcsph", PEER, PEER_SWIRL_WALLS):
            rows = by.get((size, code))
            if rows:
                med[code] = (statistics.median(r["sim_time"] / r["wall_seconds"] for r in rows),
                             statistics.median(r["sim_time"] / stepping_cpu(r) for r in rows))
        for a, b in (("swirl dfsph", PEER), ("swirl dfsph", PEER_SWIRL_WALLS), ("swirl dfsph", "swirl wcsph")):
            if a in med and b in med:
                lines.append(f"- {size}: simulated seconds per wall second, {a} / {b} = "
                             f"{med[a][0] / med[b][0]:.2f} (per CPU second: {med[a][1] / med[b][1]:.2f})")
    return "\n".join(lines) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--sizes", default="1e5", help="comma-separated: 1e5 (120 000 fluid), 1e6 (960 000)")
    ap.add_argument("--until", type=float, default=0.1, help="simulated seconds per run")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--first-rep", type=int, default=0, help="number the rounds from this (to add rounds to OUT)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--codes", default="dfsph,wcsph,peer", help="which, in this order each round")
    ap.add_argument("--swirl", type=Path, default=ROOT / "build/swirl")
    ap.add_argument("--peer-python", type=Path, default=Path("/tmp/dfsphbench-venv/bin/python"))
    ap.add_argument("--keep", action="store_true", help="keep the last CSV frame of each swirl run")
    ap.add_argument("--peer-walls", default="akinci", choices=("akinci", "swirl"),
                    help="the peer's walls (tools/bench_dfsph_peer.py --walls)")
    ap.add_argument("--table-only", action="store_true", help="run nothing: tabulate OUT/results.json")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    results_file = args.out / "results.json"
    results = json.loads(results_file.read_text()) if results_file.exists() else []
    codes = [] if args.table_only else args.codes.split(",")
    for size in args.sizes.split(",") if codes else []:
        frame = initial_frame(args, size)
        for rep in range(args.first_rep, args.first_rep + args.repeats):
            for code in codes:
                tag = f"{size} rep {rep} {code}"
                print(f"[{time.strftime('%H:%M:%S')}] {tag} (load {load()})", flush=True)
                r = run_peer(args, size, rep, frame) if code == "peer" else run_swirl(args, size, code, rep)
                r["until"] = args.until
                r["date"] = time.strftime("%Y-%m-%dT%H:%M:%S%z")
                results.append(r)
                results_file.write_text(json.dumps(results, indent=1) + "\n")
                print(f"    {r['steps']} steps, {r['wall_seconds']:.1f} s wall, {r['cpu_seconds']:.1f} s CPU, "
                      f"final compression {100 * r['final_compression']:.4f} %", flush=True)
    for size in sorted({r["size"] for r in results}):
        FRAMES_CPU[size] = frames_cpu(args, size)
    (args.out / "results.md").write_text(table(results))
    print(table(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
