"""swirl.Simulation: a scene's simulation, stepped from Python."""

import numbers
import os
import pathlib
import weakref

import numpy as np

from . import _swirl
from ._scene import Scene
from ._views import Particles


def _check_array(name, a, ndim, n=None):
    """The checks of from_arrays: a C-contiguous float32/float64 ndarray of the right shape, all finite."""
    if not isinstance(a, np.ndarray):
        raise TypeError(f"{name} must be a numpy array, not a {type(a).__name__}")
    if a.dtype not in (np.float32, np.float64):
        raise TypeError(f"{name} has dtype {a.dtype}: give float32 or float64")
    shape = "(n, 3)" if ndim == 2 else "(n,)"
    if a.ndim != ndim or (ndim == 2 and a.shape[1] != 3):
        raise ValueError(f"{name} has shape {a.shape}: it must be {shape}")
    if n is not None and a.shape[0] != n:
        raise ValueError(f"{name} has {a.shape[0]} rows but positions has {n}: one per particle")
    if not a.flags.c_contiguous:
        raise ValueError(f"{name} is not C-contiguous (a slice or a transpose?): pass np.ascontiguousarray({name})")
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))[0]
        where = ", ".join(str(int(i)) for i in bad)
        raise ValueError(f"{name}[{where}] is {a[tuple(bad)]}, not a finite number")
    return np.asarray(a, dtype=np.float64)


def _check_int_array(name, a, n):
    """An integer field of from_arrays: a C-contiguous (n,) array of any integer dtype, every value in int32."""
    if a.ndim != 1:
        raise ValueError(f"{name} has shape {a.shape}: an integer field must be (n,)")
    if a.shape[0] != n:
        raise ValueError(f"{name} has {a.shape[0]} rows but positions has {n}: one per particle")
    if not a.flags.c_contiguous:
        raise ValueError(f"{name} is not C-contiguous (a slice or a transpose?): pass np.ascontiguousarray({name})")
    info = np.iinfo(np.int32)
    if a.size and (a.min() < info.min or a.max() > info.max):
        bad = int(np.argmax((a < info.min) | (a > info.max)))
        raise ValueError(f"{name}[{bad}] is {a[bad]}: integer fields are stored as int32 "
                         f"({info.min} .. {info.max})")
    return np.ascontiguousarray(a, dtype=np.int32)


def _forces(sim, forces):
    """(name, fn(t)) pairs for the engine from the user's forces: dict name -> f, or a list of callables."""
    if forces is None:
        return []
    if callable(forces):
        forces = [forces]
    if isinstance(forces, dict):
        items = forces.items()
    else:  # named by __name__; a lambda by its place
        items = []
        for k, f in enumerate(forces):
            name = getattr(f, "__name__", "")
            items.append((name if isinstance(name, str) and name.isidentifier() else f"force{k}", f))
    ref = weakref.ref(sim)  # no cycle between the engine's force and this object
    out, seen = [], set()
    for name, f in items:
        if not isinstance(name, str) or not name.isidentifier():
            raise ValueError(f"force name {name!r}: give a Python identifier (it names the phase forces.python.<name>)")
        if name in seen:
            raise ValueError(f"two forces named {name!r}: give them different names (a dict name -> function)")
        if not callable(f):
            raise TypeError(f"force {name!r} is not callable as f(sim, t)")
        seen.add(name)

        def call(t, f=f):
            f(ref(), t)

        out.append((f"python.{name}", call))
    return out


class Simulation:
    """A running simulation of a scene: particles, solvers, stepper and clock.

    ``Simulation(scene)`` builds exactly what ``swirl run`` builds for the
    scene (the same particles, solvers, stepper and guard; sim/build.hpp) and
    computes the initial forces. ``scene`` is a ``swirl.Scene`` or a path to
    a scene file.

    Stepping: ``step(n=1)`` takes n steps; ``run(until=t, ...)`` steps to a
    time, calling a callback on the way. The engine runs with the GIL
    released, on the threads of ``swirl.set_threads`` (default: all cores or
    ``OMP_NUM_THREADS``, as the CLI); results are bit-identical for any
    thread count. Ctrl-C stops after the current step with
    ``KeyboardInterrupt``; the state is that after the step, consistent.

    Reading and writing the state: ``particles`` (zero-copy views of every
    field, checked against reordering; see ``swirl.Particles``),
    ``diagnostics()`` (energies, momenta, the solvers' figures),
    ``write_frame(path)`` (a .vtp/.csv frame as ``swirl run`` writes it).

    A blow-up (a non-finite state, a particle leaving the box, a step beyond
    the stability condition) raises ``swirl.SimulationError`` naming the
    step, the particle and a fix, as the CLI reports it.

    ``forces``: forces written in Python, added after the scene's own: a
    dict ``{name: f}`` or a list of functions (named by ``__name__``; a
    lambda by its place, ``force<k>``). The engine calls ``f(sim, t)`` at
    every force evaluation (for the initial state, then once per step) once
    the accelerations were zeroed and the scene's solvers added theirs; ``f``
    adds its acceleration (m/s², or N-body units) at time ``t`` into
    ``sim.particles.acceleration`` with numpy over the views, which are fresh
    there. Its cost is the phase ``forces.python.<name>`` of ``sim.phases()``
    (seconds). Energy is then not known to be conserved (no relative energy
    error). An exception in ``f`` propagates and leaves the simulation
    unusable (its state is inside a step).

    Example::

        sim = swirl.Simulation(swirl.Scene.from_file("examples/plummer.toml"))
        sim.run(until=2.0, every=0.5, callback=lambda s: print(s.time, s.diagnostics()["total_energy"]))
        r = np.hypot(sim.particles.position.x, sim.particles.position.y)   # views, no copy
    """

    __slots__ = ("_native", "_scene", "_renderer", "_renderer_key", "__weakref__")

    def __init__(self, scene, forces=None):
        if isinstance(scene, (str, os.PathLike)):
            scene = Scene.from_file(scene)
        if not isinstance(scene, Scene):
            raise TypeError(f"Simulation(scene): give a swirl.Scene or a scene file path, not a {type(scene).__name__}")
        self._scene = scene
        self._native = _swirl.Simulation(scene._scene, _forces(self, forces))
        self._native.start()

    @classmethod
    def from_arrays(cls, scene, positions, velocities=None, masses=None, forces=None, fields=None):
        """A simulation of the scene's physics with these particles instead of its ``[[particles]]``.

        ``positions``: (n, 3) array (m, or N-body length); ``velocities``:
        (n, 3) (m/s), default at rest; ``masses``: (n,) array (kg), or one
        number for every particle (required). Arrays must be numpy float32 or
        float64, C-contiguous, finite, of matching lengths; anything else
        raises TypeError or ValueError naming the array. The particles get
        ids 0..n-1 in the order given, and are checked as a scene file's
        ``kind = "list"`` source is (inside the box, ...): ``SceneError``.
        The fields are stored in the scene's precision (``scene.precision``)
        whatever the arrays' dtype. Every other setting (dt, solvers, box,
        output) is the scene's. ``forces``: as for ``Simulation()``.
        ``fields``: extra named fields, a dict name -> (n,) or (n, 3) array
        (float32/float64, C-contiguous, finite; in the order of
        ``positions``), or an (n,) array of any integer dtype with values
        that fit int32 (stored as int32: a material, a label): they travel
        with the particles through every reorder, are written to frames and
        checkpoints, and are read back through ``sim.particles[name]``. A
        built-in name is refused.
        """
        if isinstance(scene, (str, os.PathLike)):
            scene = Scene.from_file(scene)
        if not isinstance(scene, Scene):
            raise TypeError(f"from_arrays(scene, ...): give a swirl.Scene, not a {type(scene).__name__}")
        pos = _check_array("positions", positions, 2)
        n = pos.shape[0]
        if n == 0:
            raise ValueError("positions is empty: give at least one particle")
        vel = None if velocities is None else _check_array("velocities", velocities, 2, n)
        if masses is None:
            raise TypeError("from_arrays needs masses: an (n,) array, or one number for all particles")
        if isinstance(masses, numbers.Real) and not isinstance(masses, bool):
            mass = np.full(n, float(masses))
            if not np.isfinite(mass[0]) or mass[0] <= 0:
                raise ValueError(f"masses = {masses}: a mass must be finite and > 0")
        else:
            mass = _check_array("masses", masses, 1, n)
        extra, extra_int = [], []
        for name, a in (fields or {}).items():
            if not isinstance(name, str) or not name:
                raise ValueError(f"field name {name!r}: give a non-empty string")
            if not isinstance(a, np.ndarray) or a.ndim not in (1, 2):
                raise ValueError(f"field {name!r}: give an (n,) or (n, 3) numpy array")
            if a.dtype.kind in "iu":
                extra_int.append((name, _check_int_array(name, a, n)))
            else:
                extra.append((name, _check_array(name, a, a.ndim, n)))
        self = cls.__new__(cls)
        self._scene = scene
        self._native = _swirl.Simulation.from_arrays(scene._scene, pos, vel, mass, _forces(self, forces), extra,
                                                     extra_int)
        self._native.start()
        return self

    # -- stepping ----------------------------------------------------------
    def step(self, n=1):
        """Takes ``n`` steps (default 1). The GIL is released while stepping; Ctrl-C stops after the current step."""
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 0:
            raise ValueError(f"step(n): n must be a whole number >= 0, not {n!r}")
        self._native.step(int(n))
        return self

    def run(self, until=None, *, steps=None, every=None, callback=None):
        """Steps until simulated time ``until`` (or ``steps`` more steps), calling ``callback`` on the way.

        ``until``: a time (s, or N-body time) past the current one; with a
        fixed dt the run ends at the first step whose time is >= until (the
        rounding of the CLI's ``--until``), with adaptive steps exactly at it.
        ``steps``: instead of ``until``, this many steps.
        ``every``: when ``callback`` is called: a float is an interval of
        simulated time (after the first step whose time is >= k·every, as the
        frame writer's schedule; adaptive steps land on those times), an int
        a number of steps; default: after every step.
        ``callback(sim)``: sees the state (``sim.particles`` views are fresh
        there) and may change it (write into the fields: a force, a kick);
        returning ``False`` stops the run; an exception stops it and
        propagates. Returns True when the callback stopped the run, else False.
        """
        if (until is None) == (steps is None):
            raise ValueError("run(): give until=T or steps=N (one of them)")
        if until is not None:
            if isinstance(until, bool) or not isinstance(until, numbers.Real) or not np.isfinite(until):
                raise ValueError(f"run(until={until!r}): until must be a finite time")
            if until <= self.time:
                raise ValueError(f"run(until={until}): the simulation is already at t = {self.time:g}; give a later time")
        if steps is not None and (isinstance(steps, bool) or not isinstance(steps, numbers.Integral) or steps < 0):
            raise ValueError(f"run(steps={steps!r}): steps must be a whole number >= 0")
        every_time = every_steps = None
        if every is None:
            every_steps = 1
        elif isinstance(every, bool):
            raise ValueError("run(every=...): give a time interval (float) or a step count (int)")
        elif isinstance(every, numbers.Integral):
            if every < 1:
                raise ValueError(f"run(every={every}): a step count must be >= 1")
            every_steps = int(every)
        elif isinstance(every, numbers.Real):
            if not (np.isfinite(every) and every > 0):
                raise ValueError(f"run(every={every}): a time interval must be finite and > 0")
            every_time = float(every)
        else:
            raise ValueError(f"run(every={every!r}): give a time interval (float) or a step count (int)")
        if callback is not None and not callable(callback):
            raise TypeError("run(callback=...): the callback must be callable as callback(sim)")
        call = None if callback is None else (lambda: callback(self))
        return self._native.run(None if until is None else float(until), None if steps is None else int(steps),
                                every_time, every_steps, call)

    # -- state ---------------------------------------------------------------
    @property
    def scene(self):
        """The ``swirl.Scene`` this simulation was built from."""
        return self._scene

    @property
    def time(self):
        """Simulated time (s, or N-body time); fixed dt: steps·dt exactly."""
        return self._native.time

    @property
    def steps(self):
        """Steps taken so far; int."""
        return self._native.steps

    @property
    def epoch(self):
        """The particle order's counter: changes whenever the particles were reordered or resized (views check it)."""
        return self._native.epoch

    @property
    def dt(self):
        """The step last taken (0 before the first)."""
        return self._native.last_dt

    @property
    def next_dt(self):
        """The step the next ``step()`` takes: the fixed dt, or the adaptive choice."""
        return self._native.proposed_dt

    @property
    def precision(self):
        """``"float"`` or ``"double"``: the particle fields' type (numpy float32 / float64)."""
        return self._native.precision

    @property
    def count(self):
        """Number of particles; int."""
        return self._native.count

    def __len__(self):
        return self._native.count

    @property
    def particles(self):
        """The particle fields as zero-copy numpy views (``swirl.Particles``), e.g. ``sim.particles.position.x``."""
        return Particles(self)

    def diagnostics(self):
        """The figures of one row of the CLI's diagnostics.csv, as a dict.

        ``time``, ``step``, ``kinetic_energy``, ``potential_energy``,
        ``total_energy`` (J, or N-body units), ``relative_energy_error``
        (against the initial state; only when every force and wall conserves
        energy), ``momentum_x/y/z``, ``angular_momentum_x/y/z`` (about the
        origin), then every solver's own columns (SPH: density errors, mean
        neighbours, ...).
        """
        return self._native.diagnostics()

    def metrics(self):
        """The solvers' figures of the CLI's summary (e.g. ``mean_neighbours``, ``sorts``), as a dict."""
        return self._native.metrics()

    def phases(self):
        """Seconds spent per phase so far (``forces``, ``forces.sort``, ...), as the CLI's summary; dict."""
        return self._native.phases()

    def write_frame(self, path, format=None):
        """Writes the current state as a frame, with the writer ``swirl run`` uses; returns the paths written.

        ``format``: ``"vtp"`` (ParaView) or ``"csv"``; default from the path's suffix.
        Fields in storage order, with their ids. As in a run, boundary particles
        (walls and obstacles of particles) go to a file of their own beside it:
        ``boundary_NNNNNN.vtp`` for ``particles_NNNNNN.vtp`` (``swirl render`` reads
        the two together), else ``<stem>_boundary.vtp``.
        """
        path = os.fspath(path)
        if format is None:
            format = os.path.splitext(path)[1].lstrip(".").lower()
        return [pathlib.Path(p) for p in self._native.write_frame(path, format)]

    def render(self, *, view="front", color=None, size=(1280, 720), range=None, projection=None, png=None):
        """Draws the current state as ``swirl render`` draws a frame; returns an (height, width, 3) uint8 RGB image.

        No run folder or frame file is needed. The arguments are ``swirl.render``'s:
        ``view`` ``"front"``, ``"top"`` or ``"iso"``; ``color`` ``"speed"``,
        ``"density"``, ``"pressure"`` or ``"mass"`` (default: density for gravity
        scenes, else speed); ``size`` (width, height) in pixels, each >= 64;
        ``range`` (lo, hi) of the colours; ``projection`` ``"ortho"`` or
        ``"perspective"``; ``png`` also writes the picture there. The first call
        fixes the camera and the colours from the state it sees (as a run's first
        frame does for ``swirl render``); later calls with the same arguments keep
        them, so pictures taken from a callback make a movie that does not flicker.
        Other arguments fix them anew.
        """
        try:
            width, height = (int(x) for x in size)
        except (TypeError, ValueError):
            raise ValueError(f"size={size!r}: give (width, height) in pixels") from None
        if range is not None:
            range = tuple(float(x) for x in range)
        key = (view, color, width, height, range, projection)
        if getattr(self, "_renderer_key", None) != key:
            self._renderer = _swirl.StateRenderer(self._native, view, projection, color, width, height, range)
            self._renderer_key = key
        return self._renderer.draw(self._native, None if png is None else os.fspath(png))["image"]

    def __repr__(self):
        return (f"<swirl.Simulation {self._scene.file!r}: {self.count} particles ({self.precision}), "
                f"step {self.steps}, t = {self.time:g}>")
