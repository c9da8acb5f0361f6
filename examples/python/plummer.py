"""A Plummer sphere from Python: energy error and Lagrangian radii against time.

The cluster of examples/plummer.toml (G = 1 units), at fewer stars, stepped
with a callback every 0.25 time units that reads the diagnostics (the total
energy's relative error) and computes the radii holding 10 %, 50 % and 90 %
of the mass about the centre of mass from the zero-copy views. A Plummer
sphere in equilibrium keeps its Lagrangian radii (up to noise), and the
leapfrog keeps the energy error small and bounded.

    build-python/venv/bin/python examples/python/plummer.py [--count 2048] [--until 10]

About 20 s here at the defaults.
"""

import argparse
import os
import pathlib

import numpy as np
import swirl

REPO = pathlib.Path(__file__).resolve().parents[2]
FRACTIONS = (0.1, 0.5, 0.9)


def lagrangian_radii(sim):
    p = sim.particles
    m = p.mass.copy().astype(np.float64)
    x = np.stack([p.position.x.copy(), p.position.y.copy(), p.position.z.copy()], axis=1).astype(np.float64)
    centre = (m[:, None] * x).sum(axis=0) / m.sum()
    r = np.linalg.norm(x - centre, axis=1)
    order = np.argsort(r)
    cumulative = np.cumsum(m[order]) / m.sum()
    return [r[order][np.searchsorted(cumulative, f)] for f in FRACTIONS]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/python/plummer")
    parser.add_argument("--count", type=int, default=2048, help="stars")
    parser.add_argument("--until", type=float, default=10.0, help="end time (N-body units)")
    args = parser.parse_args()

    scene = swirl.Scene.from_file(REPO / "examples" / "plummer.toml", overrides=[f"particles.0.count={args.count}"])
    sim = swirl.Simulation(scene)
    rows = []

    def record(s):
        rows.append([s.time, s.diagnostics()["relative_energy_error"], *lagrangian_radii(s)])

    record(sim)
    sim.run(until=args.until, every=0.25, callback=record)
    rows = np.array(rows)

    os.makedirs(args.out, exist_ok=True)
    np.savetxt(os.path.join(args.out, "plummer.csv"), rows, delimiter=",",
               header="time,relative_energy_error,r10,r50,r90", comments="")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(6, 6), sharex=True)
    top.plot(rows[:, 0], rows[:, 1])
    top.set_ylabel(r"$(E - E_0)/|E_0|$")
    top.set_title(f"Plummer sphere, {sim.count} stars (Barnes-Hut)")
    for k, f in enumerate(FRACTIONS):
        bottom.plot(rows[:, 0], rows[:, 2 + k], label=f"{int(f * 100)} % of the mass")
    bottom.set_yscale("log")
    bottom.set_xlabel("time (N-body units)")
    bottom.set_ylabel("Lagrangian radius")
    bottom.legend()
    fig.tight_layout()
    png = os.path.join(args.out, "plummer.png")
    fig.savefig(png, dpi=120)
    print(f"{sim.steps} steps; energy error {rows[-1, 1]:.2e}; half-mass radius {rows[0, 3]:.3f} -> {rows[-1, 3]:.3f}; "
          f"plot: {png}")


if __name__ == "__main__":
    main()
