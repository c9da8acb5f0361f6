#!/usr/bin/env python3
"""The weak-scaling model of docs/scaling.md: efficiency of a distributed
swirl run on P nodes, from measured per-node compute and the traffic each
step sends. Every input is a flag; the defaults are the ones the page states.

    python3 tools/scaling_model.py                   # the page's table
    python3 tools/scaling_model.py --alpha 2e-6 --beta 25e9 --overhead 1.3
"""
import argparse
import math


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=float, default=1e7, help="particles per node")
    ap.add_argument("--overhead", type=float, default=1.1, help="intra-node MPI overhead c (1 = none)")
    ap.add_argument("--sph-step", type=float, default=0.93, help="s per step of the thesis's SPH at n, one node")
    ap.add_argument("--dfsph-iteration", type=float, default=0.8, help="s per DFSPH solve iteration at n, one node")
    ap.add_argument("--gravity-step", type=float, default=23.0, help="s per Barnes-Hut step at n, one node")
    ap.add_argument("--replay", type=float, default=5e-6, help="s per replayed remote group (gravity export)")
    ap.add_argument("--alpha", type=float, nargs="*", default=[1.5e-6, 25e-6], help="latencies, s")
    ap.add_argument("--beta", type=float, nargs="*", default=[12e9, 1.1e9], help="bandwidths, B/s")
    ap.add_argument("--nodes", type=int, nargs="*", default=[8, 64, 1000])
    a = ap.parse_args()
    n = a.n
    g = 1.5 * 6 * 2.5 / n ** (1 / 3)          # ghosts per own particle
    f = 0.34 * (65536 / n) ** (1 / 3)         # gravity import per own particle
    nets = list(zip(a.alpha, a.beta))
    print(f"n = {n:.3g} per node; ghosts g = {g:.4f}; gravity import f = {f:.4f}; c = {a.overhead}")
    header = ["P"]
    for what in ("SPH", "DFSPH it.", "gravity"):
        for al, be in nets:
            header.append(f"{what} (a={al:g}, b={be:g})")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for P in a.nodes:
        row = [str(P)]
        cols = {}
        for al, be in nets:
            # SPH: exchange 1 and 2 (96 B a ghost), 6 P-wide collectives.
            sph = a.overhead * a.sph_step + 96 * g * n / be + 6 * P * al
            # DFSPH iteration: v and kappa/rho (32 B a ghost), the block-sum all-gather.
            blocks = (1023 + n / 1024 + 2) * 8
            dfsph = a.overhead * a.dfsph_iteration + 32 * g * n / be + P * al + P * blocks / be
            # Gravity: boxes all-gathered (56 B a group of 256), export (f n items of ~49 B), replay.
            grav = (a.overhead * a.gravity_step + P * n / 256 * 56 / be + f * n * 49 / be + 2 * P * al
                    + (P - 1) * n / 256 * a.replay)
            cols[(al, be)] = (a.sph_step / sph, a.dfsph_iteration / dfsph, a.gravity_step / grav)
        for k in range(3):
            for net in nets:
                row.append(f"{cols[net][k]:.2f}")
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
