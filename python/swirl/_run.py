"""Runs into run folders, as ``swirl run`` makes them (frames, diagnostics, checkpoints)."""

import csv
import numbers
import os

import numpy as np

from . import _swirl
from ._scene import Scene


def _positive_int(name, value):
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise ValueError(f"{name}={value!r}: give a whole number >= 1")
    return int(value)


def _positive_float(name, value):
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name}={value!r}: give a finite number > 0")
    return float(value)


def _hooks(scene, forces, callback, every):
    """The run's Python forces and callback: (forces, callback(), every_steps, every_time, attach(native)), and the
    Simulation object the user's functions see (on the run's own simulation, cut off when the run ends)."""
    from ._simulation import Simulation, _forces

    if callback is not None and not callable(callback):
        raise TypeError("callback must be callable as callback(sim)")
    if every is not None and callback is None:
        raise ValueError("every= is when the callback is called: give a callback too")
    every_steps = every_time = None
    if callback is not None:
        if every is None or isinstance(every, numbers.Integral) and not isinstance(every, bool):
            every_steps = _positive_int("every", 1 if every is None else every)
        else:
            every_time = _positive_float("every", every)
    view = Simulation.__new__(Simulation)
    view._scene = scene
    view._native = None
    engine_forces = _forces(view, forces)

    def attach(native):
        view._native = native

    call = None if callback is None else (lambda: callback(view))
    return (engine_forces, call, every_steps, every_time, attach), view


def _run(scene, out, resume, steps, until, threads, overwrite, checkpoint_every, checkpoint_every_steps,
         checkpoint_keep, on_blowup, progress, forces=None, callback=None, every=None):
    if steps is not None and until is not None:
        raise ValueError("give steps=N or until=T, not both")
    if threads is None:
        threads = 0
    elif isinstance(threads, bool) or not isinstance(threads, numbers.Integral) or threads < 1:
        raise ValueError(f"threads={threads!r}: give a whole number >= 1 (or None: all cores)")
    if progress is not None and not callable(progress):
        raise TypeError("progress must be callable as progress(dict)")
    hooks, view = _hooks(scene, forces, callback, every)
    return _swirl.run_scene(scene._scene, os.fspath(out), resume, _positive_int("steps", steps),
                            _positive_float("until", until), int(threads), bool(overwrite),
                            _positive_float("checkpoint_every", checkpoint_every),
                            _positive_int("checkpoint_every_steps", checkpoint_every_steps),
                            _positive_int("checkpoint_keep", checkpoint_keep), on_blowup, progress, *hooks)


def run(scene, out, *, steps=None, until=None, threads=None, overwrite=False, checkpoint_every=None,
        checkpoint_every_steps=None, checkpoint_keep=2, on_blowup="stop", progress=None, forces=None,
        callback=None, every=None):
    """Runs a scene into the run folder ``out``, as ``swirl run SCENE --out OUT`` does; returns the summary dict.

    The same run loop as the CLI (sim/run.cpp): frames ``particles_NNNNNN.vtp``
    (or .csv) at ``output.interval`` with ``particles.pvd``, ``diagnostics.csv``,
    ``scene.toml``, the manifest, and checkpoints in ``out/checkpoints/``.
    ``scene``: a ``swirl.Scene`` or a scene file path.
    ``steps`` / ``until``: run that many steps, or to that simulated time,
    instead of the scene's end (``--steps`` / ``--until``).
    ``threads``: threads for this run (default: all cores or ``OMP_NUM_THREADS``).
    ``overwrite``: replace a run already in ``out`` (only the files its manifest lists).
    ``checkpoint_every`` (simulated time) / ``checkpoint_every_steps`` /
    ``checkpoint_keep`` (default 2): as the CLI's checkpoint options.
    ``on_blowup``: ``"stop"`` (default), ``"warn"`` or ``"off"``.
    ``progress(d)``: called after every step with ``step``, ``first_step``,
    ``total_steps``, ``time``, ``wall_seconds``; returning False stops the run.

    Steering a run that writes its folder: ``forces`` are forces written in
    Python, as for ``Simulation(scene, forces=...)``, added to the run's
    simulation; ``callback(sim)`` is called after the steps ``every`` selects
    (an int: every that many steps, default 1; a float: at every multiple of
    that simulated time, where adaptive steps land) with ``sim``, a
    ``swirl.Simulation`` on the run's own particles: it reads and changes
    fields (views are fresh there), ``sim.diagnostics()``, ``sim.write_frame``,
    and stops the run by returning False (a checkpoint is written). It cannot
    step (the run does), and it is cut off when the run ends (using it then
    raises). Frames at the same step are written before the callback;
    checkpoints after it, so ``swirl.resume(out, forces=..., callback=...)``
    with the same functions goes on bit-identically.

    Ctrl-C (or an exception from ``progress``, ``callback`` or a force) stops the run after the
    current step, writes a checkpoint (``swirl.resume(out)`` continues), and
    is raised. A blow-up does not raise: the summary's ``error`` says it, as
    the CLI's summary does, and every frame and checkpoint before it is kept.
    The summary has the keys of ``swirl run --summary-json``.
    """
    if isinstance(scene, (str, os.PathLike)):
        scene = Scene.from_file(scene)
    if not isinstance(scene, Scene):
        raise TypeError(f"run(scene, ...): give a swirl.Scene or a scene file path, not a {type(scene).__name__}")
    return _run(scene, out, False, steps, until, threads, overwrite, checkpoint_every, checkpoint_every_steps,
                checkpoint_keep, on_blowup, progress, forces, callback, every)


def resume(run_dir, *, steps=None, until=None, threads=None, checkpoint_every=None, checkpoint_every_steps=None,
           checkpoint_keep=2, on_blowup="stop", progress=None, forces=None, callback=None, every=None):
    """Continues the run in ``run_dir`` from its newest valid checkpoint, as ``swirl run --resume RUN_DIR``.

    The scene is the one saved there (``run_dir/scene.toml``); the result is
    bit-identical to a run that never stopped. ``steps``: that many more steps;
    ``until``: to that time; default: where the first invocation would have
    ended. Other arguments as ``swirl.run``; a run made with ``forces`` or a
    ``callback`` goes on as it would have only if it is given the same ones.
    Returns the summary dict.
    """
    scene = Scene.from_file(os.path.join(os.fspath(run_dir), "scene.toml"))
    return _run(scene, run_dir, True, steps, until, threads, False, checkpoint_every, checkpoint_every_steps,
                checkpoint_keep, on_blowup, progress, forces, callback, every)


def read_diagnostics(run_dir):
    """A run folder's ``diagnostics.csv`` as a dict of numpy arrays, one per column (``limited_by``: str)."""
    with open(os.path.join(os.fspath(run_dir), "diagnostics.csv"), newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    out = {}
    for k, name in enumerate(header):
        column = [r[k] for r in body]
        out[name] = np.array(column) if name == "limited_by" else np.array(column, dtype=np.float64)
    return out


def render(run_dir, frame=-1, *, view="front", color=None, size=(1280, 720), range=None, projection=None, png=None):
    """Draws frame ``frame`` of a run folder as ``swirl render`` does; returns an (height, width, 3) uint8 RGB image.

    ``frame``: the frame's number (negative counts from the end; default the
    last). ``view``: ``"front"``, ``"top"`` or ``"iso"``; ``color``:
    ``"speed"``, ``"density"``, ``"pressure"`` or ``"mass"`` (default: density
    for gravity runs, else speed); ``size``: (width, height) in pixels, each
    >= 64; ``range``: (lo, hi) colour range (log10 surface density for the
    gravity density view), default from the run's first frame, as the CLI;
    ``projection``: ``"ortho"`` or ``"perspective"`` (default: perspective for
    iso). ``png``: also write the picture there (the CLI's PNG bytes).
    """
    if isinstance(frame, bool) or not isinstance(frame, numbers.Integral):
        raise ValueError(f"frame={frame!r}: give a frame number")
    try:
        width, height = (int(x) for x in size)
    except (TypeError, ValueError):
        raise ValueError(f"size={size!r}: give (width, height) in pixels") from None
    if range is not None:
        lo, hi = (float(x) for x in range)
        range = (lo, hi)
    result = _swirl.render_frame(os.fspath(run_dir), int(frame), view, projection, color, width, height, range,
                                 None if png is None else os.fspath(png))
    return result["image"]
