"""swirl from Python: build, run, look at and steer particle simulations.

swirl is a C++20 engine for SPH fluids and Barnes–Hut gravity (README.md);
this package drives the same engine as the ``swirl`` CLI, in-process:

    import swirl
    scene = swirl.Scene.from_file("examples/plummer.toml", overrides=["particles.0.count=2048"])
    sim = swirl.Simulation(scene)
    sim.run(until=1.0, every=0.25, callback=lambda s: print(s.time, s.diagnostics()["total_energy"]))
    x = sim.particles.position.x          # numpy view of the C++ memory, no copy

Names:
    Scene            a validated scene (from a file, TOML text or a dict)
    Simulation       a scene's simulation, stepped from Python; from_arrays for your own particles
    Particles, VectorField, FieldArray
                     the particle fields as zero-copy numpy views, checked against reordering
    run, resume      runs into a run folder as ``swirl run`` (frames, diagnostics, checkpoints)
    read_diagnostics a run folder's diagnostics.csv as numpy arrays
    render           a run folder's frame as an RGB numpy image (and a PNG), as ``swirl render``
    bench            a ``swirl bench`` suite, its results as a dict (BenchResult)
    cli              the whole command-line tool in this process: ``swirl.cli(["run", ...])``
    set_threads, threads
    SceneError (ValueError), SimulationError (RuntimeError), IoError (OSError), StaleViewError (RuntimeError)

docs/python.md in the repository is the full page.
"""

from . import _swirl
from ._cli import BenchResult, bench, cli
from ._run import read_diagnostics, render, resume, run
from ._scene import Scene
from ._simulation import Simulation
from ._views import FieldArray, Particles, StaleViewError, VectorField

SceneError = _swirl.SceneError
SceneError.__doc__ = "A scene that the loader refused: the message names the file, the key and the reason (a ValueError)."
SimulationError = _swirl.SimulationError
SimulationError.__doc__ = ("A blow-up the guard caught (non-finite state, a particle leaving the box, a step beyond "
                           "the stability condition): the message names the step, time, particle and a fix.")
IoError = _swirl.IoError
IoError.__doc__ = "A file or run folder that could not be read or written (an OSError)."

__version__ = _swirl.__version__


def set_threads(n):
    """Sets the threads swirl's parallel loops use from now on (1 <= n <= a machine limit).

    Results are bit-identical for any count. Default: all cores, or ``OMP_NUM_THREADS``.
    """
    _swirl.set_thread_count(int(n))


def threads():
    """The threads swirl's parallel loops use now; int."""
    return _swirl.thread_count()


__all__ = ["Scene", "Simulation", "Particles", "VectorField", "FieldArray", "run", "resume", "read_diagnostics", "render",
           "bench", "BenchResult", "cli",
           "set_threads", "threads", "SceneError", "SimulationError", "IoError", "StaleViewError", "__version__"]
