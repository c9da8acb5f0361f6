#!/usr/bin/env python3
"""swirl's gravity against two CPU peers with a Python API, at matched accuracy
(issue 23, Speed; docs/performance/gravity-peers.md).

Peers, from PyPI, each in its own venv of Debian's Python 3.11 (this script
runs them there, in a subprocess, on the particles it drew):

    # FMM3D as published: the manylinux wheel (x86-64 baseline: SSE2, no FMA, no OpenMP)
    /usr/bin/python3 -m venv /tmp/gravity-peers
    /tmp/gravity-peers/bin/pip install fmm3dpy==2.1.0 pytreegrav==1.5.0
    # FMM3D built here from its PyPI source for this CPU, with OpenMP
    apt-get install gfortran
    /tmp/gravity-peers/bin/pip install meson-python meson ninja
    PATH=/tmp/gravity-peers/bin:$PATH FFLAGS="-O3 -march=native -funroll-loops -fopenmp" \
        CFLAGS="-O3 -march=native" LDFLAGS=-fopenmp /tmp/gravity-peers/bin/pip wheel --no-deps \
        --no-binary :all: --no-build-isolation -w /tmp/fmm3d-native fmm3dpy==2.1.0
    /usr/bin/python3 -m venv /tmp/gravity-peers-native
    /tmp/gravity-peers-native/bin/pip install /tmp/fmm3d-native/fmm3dpy-2.1.0-*.whl

  FMM3D (fmm3dpy, the Flatiron Institute's fast multipole library):
        lfmm3d(eps, sources, charges, pg=2), the Laplace potential and
        gradient of point charges, scaled by 4π to G = 1 (the library's kernel
        is 1/(4π r)); its accuracy parameter eps.
  pytreegrav (a Barnes–Hut tree code in Numba): Accel(pos, m, h = 0, theta,
        parallel = threads > 1); its accuracy parameter theta.
  swirl `swirl bench bh-scale`: Barnes–Hut (quadrupole, Barnes' criterion,
        leaves of 16, group walk) and the FMM (p = 3 and 5, leaves of 64),
        double precision, ε = 0, its accuracy parameter θ.

Every code gets a Plummer sphere of N equal masses in Hénon units (scale
radius 3π/16, mass cut 0.999, unsoftened: ε = 0): swirl's own generator in
its bench, this script's numpy draw of the same distribution for the peers.
Error: the median over 2000 sampled particles of |a − a_direct| / |a_direct|,
a_direct the direct sum in double (each code's sample against its own
reference). Time: the wall time of one force evaluation (tree or FMM set-up
included), the median of --repeats after one untimed warm-up (Numba's
compilation, first-touch allocations), then the median over rounds. The
codes run alternately: round r in the order swirl, the FMM3D builds,
pytreegrav; the next round reversed.

Matched accuracy: for each code and each target median error (1e-4 and
1e-3), the fastest of its configurations whose median error is at or below
the target (no interpolation: a configuration that reaches the target).

  OMP_NUM_THREADS=1 /usr/bin/python3 tools/bench_gravity_peers.py --sizes 32768,1048576 --threads 1 \
      --fmm3d /tmp/gravity-peers/bin/python=FMM3D-wheel --fmm3d /tmp/gravity-peers-native/bin/python=FMM3D-native \
      --pytreegrav /tmp/gravity-peers/bin/python --out bench/results/gravity-peers-2026-12-05
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def plummer(n: int, rng: np.random.Generator):
    a = 3 * np.pi / 16
    x = rng.random(n) * 0.999
    x = np.where(x > 0, x, 1e-300)
    r = a / np.sqrt(x ** (-2.0 / 3.0) - 1.0)
    u = rng.random((n, 2))
    ct = 2 * u[:, 0] - 1
    ph = 2 * np.pi * u[:, 1]
    st = np.sqrt(1 - ct * ct)
    pos = np.stack([r * st * np.cos(ph), r * st * np.sin(ph), r * ct], axis=1)
    pos -= pos.mean(axis=0)
    return np.ascontiguousarray(pos), np.full(n, 1.0 / n)


def direct(pos, m, sample):
    chunk = max(1, (1 << 22) // len(m))  # targets per pass: (chunk, N, 3) doubles at most ~100 MB
    ref = np.zeros((len(sample), 3))
    for c in range(0, len(sample), chunk):
        idx = sample[c:c + chunk]
        d = pos[None, :, :] - pos[idx, None, :]
        r2 = (d * d).sum(-1)
        r2[np.arange(len(idx)), idx] = 1.0
        w = m[None, :] / (r2 * np.sqrt(r2))
        w[np.arange(len(idx)), idx] = 0.0
        ref[c:c + chunk] = np.einsum("bj,bjk->bk", w, d)
    return ref


def median_error(acc, ref, sample):
    return float(np.median(np.linalg.norm(acc[sample] - ref, axis=1) / np.linalg.norm(ref, axis=1)))


def timed(fn, repeats):
    fn()  # warm-up: compilation, allocations
    times, result = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def run_fmm3d(pos, m, ref, sample, eps_list, repeats, threads, label="FMM3D"):
    import fmm3dpy
    src = np.asfortranarray(pos.T)
    rows = []
    for eps in eps_list:
        sec, out = timed(lambda: fmm3dpy.lfmm3d(eps=eps, sources=src, charges=m, pg=2), repeats)
        # the gradient of Σ m/(4π r): a/(4π) (a = −∇φ, φ = −Σ m/r)
        acc = 4 * np.pi * out.grad.T
        rows.append({"code": label, "config": f"eps={eps:g}", "threads": threads, "ms": 1e3 * sec,
                     "error_median": median_error(acc, ref, sample)})
    return rows


def run_pytreegrav(pos, m, ref, sample, thetas, repeats, threads):
    from pytreegrav import Accel
    h = np.zeros(len(m))
    rows = []
    for th in thetas:
        sec, acc = timed(lambda: Accel(pos, m, h, theta=th, parallel=threads > 1, G=1.0), repeats)
        rows.append({"code": "pytreegrav", "config": f"theta={th:g}", "threads": threads, "ms": 1e3 * sec,
                     "error_median": median_error(acc, ref, sample)})
    return rows


def in_interpreter(python, peer, label, data, params, repeats, threads):
    """Runs one peer in another Python (another build of it) on the saved particles."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "rows.json"
        cmd = [python, __file__, "--worker", peer, "--worker-label", label, "--worker-data", str(data),
               "--worker-params", params, "--repeats", str(repeats), "--threads", str(threads),
               "--worker-out", str(out)]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
        return json.loads(out.read_text())


def run_driver(binary, label, pos, m, ref, sample, eps_list, repeats, threads, tmp):
    """FMM3D through its C interface (tools/peers/fmm3d_driver.c), e.g. built with its vectorised kernels."""
    n = len(m)
    data, grad_file = Path(tmp) / f"fmm3d-in-{n}.bin", Path(tmp) / "fmm3d-grad.bin"
    if not data.exists():
        with open(data, "wb") as f:
            f.write(np.int64(n).tobytes())
            f.write(np.ascontiguousarray(pos, dtype=np.float64).tobytes())  # source(3, n): x, y, z per source
            f.write(np.ascontiguousarray(m, dtype=np.float64).tobytes())
    rows = []
    for eps in eps_list:
        r = subprocess.run([binary, str(data), repr(eps), str(repeats), str(grad_file)], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"failed: {binary}: {r.stderr}")
        # the library's kernel is 1/(4π r) here too: its gradient of Σ m/(4π r) is a/(4π)
        grad = 4 * np.pi * np.fromfile(grad_file, dtype=np.float64).reshape(n, 3)
        rows.append({"code": label, "config": f"eps={eps:g}", "threads": threads, "ms": 1e3 * float(r.stdout),
                     "error_median": median_error(grad, ref, sample)})
    return rows


def worker(a):
    d = np.load(a.worker_data)
    pos, m, sample, ref = d["pos"], d["m"], d["sample"], d["ref"]
    params = [float(x) for x in a.worker_params.split(",")]
    if a.worker == "fmm3d":
        rows = run_fmm3d(pos, m, ref, sample, params, a.repeats, a.threads, a.worker_label)
    else:
        rows = run_pytreegrav(pos, m, ref, sample, params, a.repeats, a.threads)
    Path(a.worker_out).write_text(json.dumps(rows))


def peer_versions(python):
    code = ("import json, platform; from importlib.metadata import version as v; "
            "print(json.dumps({p: v(p) for p in ('fmm3dpy', 'pytreegrav', 'numba', 'numpy') "
            "if __import__('importlib.util').util.find_spec(p)} | {'python': platform.python_version()}))")
    r = subprocess.run([python, "-c", code], capture_output=True, text=True)
    return json.loads(r.stdout) if r.returncode == 0 else {"error": r.stderr.strip()}


def run_swirl(swirl, n, threads, repeats, bh_openings, fmm_openings, seed, fmm_buckets=(64,)):
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, args in (
            ("BH", ["--methods", "barnes_hut", "--multipoles", "quadrupole", "--criteria", "barnes", "--bucket", "16",
                    "--opening", ",".join(map(str, bh_openings))]),
            ("FMM", ["--methods", "fmm", "--fmm-orders", "3,5", "--fmm-buckets", ",".join(map(str, fmm_buckets)),
                     "--opening", ",".join(map(str, fmm_openings))]),
        ):
            out = Path(tmp) / label
            cmd = [swirl, "bench", "bh-scale", "--sizes", str(n), "--threads", str(threads), "--softening", "0",
                   "--sample", "2000", "--repeats", str(repeats), "--seed", str(seed), "--out", str(out)] + args
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
            with open(out / "bh-scale.csv") as f:
                for row in csv.DictReader(f):
                    config = f"{row['method']} θ={float(row['opening']):g}"
                    if row["method"] == "fmm":
                        config = f"fmm p={row['order']} θ={float(row['opening']):g}"
                        if len(fmm_buckets) > 1:
                            config += f" leaves {row['bucket']}"
                    rows.append({"code": "swirl", "config": config, "threads": threads,
                                 "ms": float(row["ms_per_evaluation"]), "error_median": float(row["error_median"])})
    return rows


def best_at(rows, code, target):
    ok = [r for r in rows if r["code"] == code and r["error_median"] <= target]
    return min(ok, key=lambda r: r["ms"]) if ok else None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--swirl", default="build/swirl")
    ap.add_argument("--sizes", default="32768,1048576")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--fmm3d", action="append", default=[], metavar="PYTHON=LABEL",
                    help="a Python with an fmm3dpy build, and its label (repeatable)")
    ap.add_argument("--fmm3d-driver", action="append", default=[], metavar="BINARY=LABEL",
                    help="tools/peers/fmm3d_driver.c built against an FMM3D library, and its label (repeatable)")
    ap.add_argument("--fmm3d-eps", default="1e-2,1e-3,1e-4")
    ap.add_argument("--pytreegrav", default=None, metavar="PYTHON", help="a Python with pytreegrav")
    ap.add_argument("--pytreegrav-theta", default="0.2,0.3,0.5,0.7,0.9")
    ap.add_argument("--pytreegrav-max", type=int, default=1 << 17, help="largest N pytreegrav runs at")
    ap.add_argument("--bh-opening", default="0.4,0.5,0.6,0.7,0.8")
    ap.add_argument("--fmm-opening", default="0.5,0.6,0.7,0.8")
    ap.add_argument("--fmm-buckets", default="64",
                    help="swirl's FMM leaf sizes (nbody.bucket_size; a list is a dimension of its configurations)")
    ap.add_argument("--out", default="bench/results/gravity-peers")
    ap.add_argument("--worker", choices=["fmm3d", "pytreegrav"], help=argparse.SUPPRESS)
    ap.add_argument("--worker-label", help=argparse.SUPPRESS)
    ap.add_argument("--worker-data", help=argparse.SUPPRESS)
    ap.add_argument("--worker-params", help=argparse.SUPPRESS)
    ap.add_argument("--worker-out", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if os.environ.get("OMP_NUM_THREADS") != str(a.threads):
        sys.exit(f"set OMP_NUM_THREADS={a.threads} (FMM3D's threads) for --threads {a.threads}")
    os.environ["NUMBA_NUM_THREADS"] = str(a.threads)
    if a.worker:
        worker(a)
        return
    fmm3d = [tuple(f.split("=", 1)) for f in a.fmm3d]
    drivers = [tuple(f.split("=", 1)) for f in a.fmm3d_driver]
    fmm3d_labels = [label for _, label in fmm3d + drivers]
    codes = ["swirl"] + fmm3d_labels + (["pytreegrav"] if a.pytreegrav else [])
    versions = {label: peer_versions(py) | {"python_path": py} for py, label in fmm3d}
    if a.pytreegrav:
        versions["pytreegrav"] = peer_versions(a.pytreegrav) | {"python_path": a.pytreegrav}
    for binary, label in drivers:
        versions[label] = {"driver": binary, "built": "FMM3D from the fmm3dpy 2.1.0 source: make lib FAST_KER=ON OMP=ON"}
    versions["swirl"] = subprocess.run([a.swirl, "--version"], capture_output=True, text=True).stdout.strip()
    rows, lines = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for n in (int(s) for s in a.sizes.split(",")):
            rng = np.random.default_rng(a.seed)
            pos, m = plummer(n, rng)
            sample = rng.choice(n, 2000, replace=False)
            ref = direct(pos, m, sample)
            data = Path(tmp) / f"plummer-{n}.npz"
            np.savez(data, pos=pos, m=m, sample=sample, ref=ref)
            runners = [lambda: run_swirl(a.swirl, n, a.threads, a.repeats, [float(t) for t in a.bh_opening.split(",")],
                                         [float(t) for t in a.fmm_opening.split(",")], a.seed,
                                         [int(b) for b in a.fmm_buckets.split(",")])]
            for py, label in fmm3d:
                runners.append(lambda py=py, label=label: in_interpreter(py, "fmm3d", label, data, a.fmm3d_eps,
                                                                         a.repeats, a.threads))
            eps_list = [float(e) for e in a.fmm3d_eps.split(",")]
            for binary, label in drivers:
                runners.append(lambda binary=binary, label=label: run_driver(binary, label, pos, m, ref, sample, eps_list,
                                                                             a.repeats, a.threads, tmp))
            if a.pytreegrav and n <= a.pytreegrav_max:
                runners.append(lambda: in_interpreter(a.pytreegrav, "pytreegrav", "pytreegrav", data,
                                                      a.pytreegrav_theta, a.repeats, a.threads))
            merged = {}
            for r in range(a.rounds):
                for run in (runners if r % 2 == 0 else runners[::-1]):
                    for g in run():
                        g.update(n=n, round=r)
                        rows.append(g)
                        merged.setdefault((g["code"], g["config"]), []).append(g)
            # the median over rounds of each configuration's time
            summary = [{"n": n, "code": c, "config": cfg, "ms": statistics.median(x["ms"] for x in v),
                        "error_median": v[0]["error_median"]} for (c, cfg), v in merged.items()]
            lines.append(f"\nN = {n}, {a.threads} thread(s), median of {a.rounds} rounds")
            lines.append(f"{'code':14s} {'config':18s} {'ms':>9s} {'median err':>11s}")
            for s in sorted(summary, key=lambda s: (codes.index(s["code"]), s["config"])):
                lines.append(f"{s['code']:14s} {s['config']:18s} {s['ms']:9.1f} {s['error_median']:11.3g}")
            for target in (1e-4, 1e-3):
                best = {c: best_at(summary, c, target) for c in codes}
                line = f"at median <= {target:g}: " + ", ".join(
                    f"{c} {b['ms']:.1f} ms ({b['config']})" if b else f"{c} -" for c, b in best.items())
                for label in fmm3d_labels:
                    if best["swirl"] and best[label]:
                        line += f"; swirl / {label} = {best['swirl']['ms'] / best[label]['ms']:.3f}"
                lines.append(line)
            print("\n".join(lines[-(len(summary) + 4):]), flush=True)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    stem = f"{a.threads}t"
    with open(out / f"runs-{stem}.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["n", "round", "code", "config", "threads", "ms", "error_median"])
        w.writeheader()
        w.writerows(rows)
    (out / f"summary-{stem}.txt").write_text("\n".join(lines) + "\n")
    versions["date"] = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    versions["machine"] = platform.processor() or platform.machine()
    (out / f"versions-{stem}.json").write_text(json.dumps(versions, indent=1) + "\n")


if __name__ == "__main__":
    main()
