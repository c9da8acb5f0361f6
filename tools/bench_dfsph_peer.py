#!/usr/bin/env python3
"""Run the DFSPH benchmark's dam break in SPlisHSPlasH, the peer of
docs/performance/dfsph.md, and time it.

SPlisHSPlasH's official build is the PyPI wheel `pysplishsplash` (2.19.0:
single precision, its AVX kernels). Set it up once, with Debian's Python 3.11:

    /usr/bin/python3 -m venv /tmp/splash-venv
    /tmp/splash-venv/bin/pip install pysplishsplash==2.19.0

and run this script with that venv's python. The wheel bundles its own
libGLdispatch, which the system's libGLX (pulled in through libGL by the
wheel's libGLU) calls at load time and crashes on (a segfault in
__glDispatchInit on `import pysplishsplash`); preloading the system's
libGLdispatch avoids it. The script re-executes itself with
LD_PRELOAD=/lib/x86_64-linux-gnu/libGLdispatch.so.0 when that library exists.

Input: the fluid particles of swirl's frame 0 of the same scene
(a CSV frame: `swirl run bench/dfsph/dam_break.toml --steps 1
--set simulation.dt_max=1e-5 --set 'output.format="csv"'`), so both codes
start from the very same fluid: written as a Houdini ASCII .geo point file
beside the scene (bench/splishsplash/dam_break.json, its particleRadius set to
half the spacing), and the fluid's masses set to swirl's (ρ0 / Σ W of the
lattice) instead of SPlisHSPlasH's 0.8·(2r)³·ρ0, which starts a lattice 20 %
under-dense. The walls (--walls): SPlisHSPlasH's own Akinci particles (its
regular triangle sampling, 1.5 r apart) of the box on which swirl's wall
particles lie (the default), or swirl's wall particles themselves (one layer
at the fluid's spacing 2r). Its volume maps (Bender et al. 2019) were tried
and left out: on this box the first steps compressed the fluid by 1-11 %,
whichever way the map was placed; their set-up needs more care than this
benchmark had.

Output (--json): the wall time of the stepping loop (SPlisHSPlasH's
deferred initialisation included, the scene loading and this script's
per-step bookkeeping excluded), steps, simulated time, the iterations of both
solves per step, and the average compression mean(max(ρ − ρ0, 0))/ρ0 of the
fluid's densities (SPlisHSPlasH's, computed at each step's start).
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time
from pathlib import Path

GLDISPATCH = "/lib/x86_64-linux-gnu/libGLdispatch.so.0"


def reexec_with_preload() -> None:
    if os.path.exists(GLDISPATCH) and GLDISPATCH not in os.environ.get("LD_PRELOAD", ""):
        env = dict(os.environ)
        env["LD_PRELOAD"] = (GLDISPATCH + " " + env.get("LD_PRELOAD", "")).strip()
        os.execve(sys.executable, [sys.executable] + sys.argv, env)


def read_frame(path: Path):
    """(fluid positions, fluid masses, boundary positions) of a swirl CSV frame: particles_NNNNNN.csv
    and, since swirl writes boundary particles to their own series, boundary_NNNNNN.csv beside it
    (older frames held both kinds in one file, told apart by the kind field)."""
    fluid, masses, walls = [], [], []
    boundary = path.with_name(path.name.replace("particles_", "boundary_", 1))
    for file in [path] + ([boundary] if boundary != path and boundary.exists() else []):
        with open(file, newline="") as f:
            first = f.readline()
            if not first.startswith("#"):
                f.seek(0)
            reader = csv.reader(f)
            header = next(reader)
            ix, iy, iz = header.index("x"), header.index("y"), header.index("z")
            im, ik = header.index("mass"), header.index("kind")
            for row in reader:
                p = (row[ix], row[iy], row[iz])
                if row[ik] == "0":
                    fluid.append(p)
                    masses.append(float(row[im]))
                else:
                    walls.append(p)
    if not walls:
        raise SystemExit(f"{path}: no boundary particles (kind != 0) in it or in {boundary.name}")
    return fluid, masses, walls


def write_geo(path: Path, points) -> None:
    """Houdini ASCII geometry, the form Partio's GEO reader takes (it needs one point attribute)."""
    with open(path, "w") as f:
        f.write("PGEOMETRY V5\n")
        f.write(f"NPoints {len(points)} NPrims 0\n")
        f.write("NPointGroups 0 NPrimGroups 0\n")
        f.write("NPointAttrib 1 NVertexAttrib 0 NPrimAttrib 0 NAttrib 0\n")
        f.write("PointAttrib\nid 1 int 0\n")
        for i, (x, y, z) in enumerate(points):
            f.write(f"{x} {y} {z} 1 ({i})\n")
        f.write("beginExtra\nendExtra\n")


def write_box_obj(path: Path, lo, hi) -> None:
    """The tank as a closed box mesh (SPlisHSPlasH loads a mesh for every rigid body; with
    a particle file its Akinci boundary uses the particles only)."""
    v = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    quads = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    with open(path, "w") as f:
        for p in v:
            f.write("v {} {} {}\n".format(*p))
        for a, b, c, d in quads:
            f.write(f"f {a} {b} {c}\nf {a} {c} {d}\n")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frame", required=True, type=Path, help="swirl's CSV frame 0 of bench/dfsph/dam_break.toml")
    ap.add_argument("--spacing", required=True, type=float, help="the fluid's spacing (m): particleRadius = spacing/2")
    ap.add_argument("--scene", type=Path, default=Path(__file__).resolve().parent.parent / "bench/splishsplash/dam_break.json")
    ap.add_argument("--until", type=float, required=True, help="simulated time to run (s)")
    ap.add_argument("--out", type=Path, required=True, help="work folder (scene, point files, SPlisHSPlasH's log)")
    ap.add_argument("--json", type=Path, help="write the results here")
    ap.add_argument("--default-mass", action="store_true", help="keep SPlisHSPlasH's own masses, 0.8·(2r)³·ρ0")
    ap.add_argument("--walls", choices=("akinci", "swirl"), default="akinci",
                    help="akinci: SPlisHSPlasH samples the tank's faces itself (Akinci 2012 particles, its default "
                         "sampling); swirl: swirl's wall particles (one layer at the fluid's spacing)")
    ap.add_argument("--max-iterations", type=int, help="override the solves' iteration cap (the scene's 100)")
    args = ap.parse_args()
    reexec_with_preload()

    import numpy as np
    import pysplishsplash as sph

    args.out.mkdir(parents=True, exist_ok=True)
    fluid, masses, walls = read_frame(args.frame)
    write_geo(args.out / "fluid.geo", fluid)
    wall_xyz = np.array(walls, dtype=float)
    write_box_obj(args.out / "tank.obj", wall_xyz.min(axis=0), wall_xyz.max(axis=0))
    scene = json.loads(args.scene.read_text())
    if args.walls == "swirl":
        write_geo(args.out / "walls.geo", walls)
    else:  # SPlisHSPlasH samples the tank's faces itself (where swirl's wall particles lie)
        for body in scene["RigidBodies"]:
            body.pop("particleFile", None)
    scene["Configuration"]["particleRadius"] = args.spacing / 2
    scene["Configuration"]["stopAt"] = args.until
    if args.max_iterations:
        scene["Configuration"]["DFSPH"]["maxIterations"] = args.max_iterations
        scene["Configuration"]["DFSPH"]["maxIterationsV"] = args.max_iterations
    scene_file = args.out / "dam_break.json"
    scene_file.write_text(json.dumps(scene, indent=1))

    base = sph.Exec.SimulatorBase()
    base.init(["splash", "--no-gui", "--no-cache", "--no-initial-pause", "--stopAt", str(args.until),
               "--output-dir", str(args.out / "output"), str(scene_file)], "swirl bench (SPlisHSPlasH)")
    steps = []
    bookkeeping = [0.0]
    state = {}

    def on_step():
        t0 = time.perf_counter()
        sim = sph.Simulation.getCurrent()
        ts = sim.getTimeStep()
        tm = sph.TimeManager.getCurrent()
        rho = state["density"]
        compression = float(np.maximum(rho - state["rho0"], 0.0).mean() / state["rho0"])
        steps.append({
            "wall": t0,
            "time": tm.getTime(),
            "dt": tm.getTimeStepSize(),
            "iterations": ts.getValueInt(sph.TimeStepDFSPH.SOLVER_ITERATIONS),
            "iterations_v": ts.getValueInt(sph.TimeStepDFSPH.SOLVER_ITERATIONS_V),
            "compression": compression,
        })
        bookkeeping[0] += time.perf_counter() - t0

    base.setTimeStepCB(on_step)
    base.initSimulation()
    sim = sph.Simulation.getCurrent()
    fm = sim.getFluidModel(0)
    n = fm.numActiveParticles()
    if n != len(fluid):
        raise SystemExit(f"SPlisHSPlasH has {n} fluid particles, the frame {len(fluid)}")
    # Particle order: SPlisHSPlasH keeps the file's order until its first z-sort, and every
    # swirl fluid particle of the lattice has the same mass, so a plain assignment is exact.
    if not args.default_mass:
        mass = np.array(fm.getFieldBuffer("mass"), copy=False)
        mass[:n] = np.asarray(masses, dtype=mass.dtype)  # the buffer may be longer than n
    state["density"] = np.array(fm.getFieldBuffer("density"), copy=False)[:n]
    state["rho0"] = fm.getDensity0()

    start = time.perf_counter()
    cpu_start = time.process_time()
    base.runSimulation()
    wall = time.perf_counter() - start - bookkeeping[0]
    cpu = time.process_time() - cpu_start
    # Where the fluid ended: its fastest particle and those beyond the walls' particles.
    x = np.array(fm.getFieldBuffer("position"), copy=False)[:n]
    v = np.array(fm.getFieldBuffer("velocity"), copy=False)[:n]
    lo, hi = wall_xyz.min(axis=0), wall_xyz.max(axis=0)
    outside = int(np.count_nonzero(np.any((x < lo) | (x > hi), axis=1)))
    max_speed = float(np.sqrt((v.astype(float) ** 2).sum(axis=1)).max())
    base.cleanup()

    boundary = None  # SPlisHSPlasH's log says how many boundary particles it made
    for log in (args.out / "output" / "log").glob("*.txt"):
        for line in log.read_text(errors="replace").splitlines():
            if "Number of boundary particles:" in line:
                boundary = int(line.rsplit(":", 1)[1])
    it = [s["iterations"] for s in steps]
    itv = [s["iterations_v"] for s in steps]
    comp = [s["compression"] for s in steps]
    sim_time = steps[-1]["time"] if steps else 0.0
    result = {
        "code": "SPlisHSPlasH " + getattr(sph, "__version__", "2.19.0 (pysplishsplash wheel)"),
        "fluid_particles": n,
        "boundary_particles": boundary,
        "walls": {"akinci": "SPlisHSPlasH's Akinci sampling", "swirl": "swirl's particles"}[args.walls],
        "threads": int(os.environ.get("OMP_NUM_THREADS", "0")) or os.cpu_count(),
        "steps": len(steps),
        "sim_time": sim_time,
        "wall_seconds": wall,
        "seconds_per_step": wall / max(1, len(steps)),
        "wall_per_sim_second": wall / sim_time if sim_time > 0 else None,
        "mean_dt": sim_time / max(1, len(steps)),
        "min_dt": min((s["dt"] for s in steps), default=None),
        "cpu_seconds_in_process": cpu,
        "max_speed_end": max_speed,
        "fluid_outside_walls_end": outside,
        "mean_density_iterations": sum(it) / max(1, len(it)),
        "max_density_iterations": max(it, default=0),
        "mean_divergence_iterations": sum(itv) / max(1, len(itv)),
        "max_divergence_iterations": max(itv, default=0),
        "mean_compression": sum(comp) / max(1, len(comp)),
        "max_compression": max(comp, default=0.0),
        "final_compression": comp[-1] if comp else None,
        "masses": "SPlisHSPlasH's 0.8·(2r)³·ρ0" if args.default_mass else "swirl's (ρ0 / Σ W of the lattice)",
        "max_iterations": scene["Configuration"]["DFSPH"]["maxIterations"],
    }
    text = json.dumps(result, indent=1)
    print(text)
    if args.json:
        args.json.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
