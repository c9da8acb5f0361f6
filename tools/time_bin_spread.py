#!/usr/bin/env python3
"""What block time steps could save on a model, before running it.

Reads one Gadget-format HDF5 snapshot (a swirl frame with output.format =
"hdf5", or initial conditions from another code), computes every particle's
acceleration |a| and tidal tensor T = ∂²Φ/∂x∂x by the softened direct sum
(float64, Plummer softening ε, G = 1), and for each per-particle step condition

  acceleration  Δt_i ∝ sqrt(ε / |a_i|)      (swirl's block steps today)
  tidal         Δt_i ∝ 1 / sqrt(‖T_i‖_F)    (Dehnen & Read 2011;
                                             Grudić & Hopkins 2020)

prints the particles per power-of-two bin and the ceiling of the saving: a
global step at the finest particle's step evaluates 2^k_max forces per
particle per cycle, block steps Σ 2^k_i / N, so their ratio is the most block
steps can save at equal steps for the finest particle (before any loss of
accuracy from mixing bins: docs/performance/block-steps.md). The ratio does
not depend on η.

  /usr/bin/python3 tools/time_bin_spread.py out/run/particles_000003.h5 --softening 0.02

O(N²) time and O(N·chunk) memory: meant for N up to a few 10⁴.
"""
import argparse
import sys

import h5py
import numpy as np


def field(x, m, eps, chunk=256):
    n = len(m)
    accel = np.zeros(n)
    tidal = np.zeros(n)
    for s in range(0, n, chunk):
        e = min(s + chunk, n)
        d = x[None, :, :] - x[s:e, None, :]  # source − target
        r2 = (d ** 2).sum(-1) + eps ** 2
        rows = np.arange(e - s)
        inv3 = m[None, :] * r2 ** -1.5
        inv3[rows, np.arange(s, e)] = 0  # no self term
        inv5 = 3 * m[None, :] * r2 ** -2.5
        inv5[rows, np.arange(s, e)] = 0
        accel[s:e] = np.linalg.norm((d * inv3[..., None]).sum(1), axis=1)
        T = np.eye(3)[None] * inv3.sum(1)[:, None, None] - np.einsum("bj,bjk,bjl->bkl", inv5, d, d)
        tidal[s:e] = np.sqrt((T ** 2).sum((1, 2)))
    return accel, tidal


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("snapshot")
    ap.add_argument("--softening", type=float, required=True, help="ε of the run (nbody.softening)")
    ap.add_argument("--part-type", default="PartType1")
    ap.add_argument("--max-particles", type=int, default=65536)
    a = ap.parse_args()
    if not a.softening > 0:
        sys.exit("--softening: the acceleration condition needs ε > 0")
    with h5py.File(a.snapshot, "r") as f:
        if a.part_type not in f:
            sys.exit(f"{a.snapshot}: no group {a.part_type}")
        g = f[a.part_type]
        x = g["Coordinates"][:].astype(np.float64)
        m = g["Masses"][:].astype(np.float64)
    if len(m) > a.max_particles:
        sys.exit(f"{a.snapshot}: {len(m)} particles, more than --max-particles {a.max_particles} (O(N²))")
    accel, tidal = field(x, m, a.softening)
    print(f"{a.snapshot}: {len(m)} particles, ε = {a.softening}")
    for name, rate in (("acceleration", np.sqrt(accel / a.softening)), ("tidal", np.sqrt(tidal))):
        rate = rate[rate > 0]
        k = np.ceil(np.log2(rate / rate.min())).astype(int)  # 0 = the coarsest bin in use
        per_bin = np.bincount(k.max() - k)  # finest first
        ceiling = 2.0 ** k.max() / np.mean(2.0 ** k)
        print(f"  {name:12s} ceiling {ceiling:5.2f}  (max/mean rate {rate.max() / rate.mean():5.2f}); "
              f"particles per bin, finest first: {' '.join(str(c) for c in per_bin)}")


if __name__ == "__main__":
    main()
