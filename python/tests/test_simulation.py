"""Stepping, run(until, every, callback), Ctrl-C, from_arrays (with a fuzz of bad input), diagnostics."""

import os
import signal
import threading
import time

import numpy as np
import pytest


def test_step_and_clock(swirl, tiny_scene):
    sim = swirl.Simulation(tiny_scene)
    assert sim.steps == 0 and sim.time == 0 and sim.count == 27
    sim.step()
    sim.step(4)
    assert sim.steps == 5 and sim.time == pytest.approx(0.005) and sim.dt == pytest.approx(0.001)
    with pytest.raises(ValueError):
        sim.step(-1)


def test_falling_under_gravity(swirl, tiny_scene):
    # No interactions: z(t) = z0 - g t^2 / 2 with velocity Verlet, exactly up to rounding.
    sim = swirl.Simulation(tiny_scene)
    z0 = sim.particles.position.z.copy()
    sim.step(10)
    t = sim.time
    np.testing.assert_allclose(sim.particles.position.z, z0 - 0.5 * 9.81 * t * t, rtol=0, atol=1e-6)


def test_run_until_every_time_and_steps(swirl, tiny_scene):
    sim = swirl.Simulation(tiny_scene)
    times = []
    assert sim.run(until=0.0101, every=0.002, callback=lambda s: times.append(round(s.time, 9))) is False
    assert sim.steps == 11  # the first step whose time is >= until
    assert times == [0.002, 0.004, 0.006, 0.008, 0.01]
    steps = []
    sim.run(steps=9, every=3, callback=lambda s: steps.append(s.steps))
    assert steps == [14, 17, 20] and sim.steps == 20
    with pytest.raises(ValueError, match="already at"):
        sim.run(until=0.001)
    with pytest.raises(ValueError, match="one of them"):
        sim.run()


def test_callback_stops_and_changes_state(swirl, tiny_scene):
    sim = swirl.Simulation(tiny_scene)

    def stop_at_5(s):
        s.particles.velocity.z[:] = 0.0  # a user "force": the state can be changed here
        return s.steps < 5

    assert sim.run(until=1.0, callback=stop_at_5) is True
    assert sim.steps == 5
    assert np.all(sim.particles.velocity.z.copy() == 0.0)

    class Boom(Exception):
        pass

    def boom(s):
        raise Boom("from the callback")

    with pytest.raises(Boom):
        sim.run(steps=3, callback=boom)
    assert sim.steps == 6  # stopped after the step whose callback raised


def test_keyboard_interrupt_stops_after_the_current_step(swirl, sph_scene):
    sim = swirl.Simulation(sph_scene)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.run(steps=10**7)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 30
    steps = sim.steps
    assert 0 < steps < 10**7
    # The state is consistent: stepping goes on.
    sim.step(2)
    assert sim.steps == steps + 2
    assert np.isfinite(sim.particles.position.x.copy()).all()


def test_diagnostics_and_metrics(swirl, nbody_scene, sph_scene):
    sim = swirl.Simulation(nbody_scene)
    d0 = sim.diagnostics()
    assert d0["relative_energy_error"] == 0.0 and d0["potential_energy"] < 0
    sim.step(8)
    d = sim.diagnostics()
    assert abs(d["relative_energy_error"]) < 1e-3
    assert d["total_energy"] == pytest.approx(d["kinetic_energy"] + d["potential_energy"])
    assert sim.metrics()["sorts"] >= 1
    assert sim.phases()["forces"] > 0
    fluid = swirl.Simulation(sph_scene)
    fluid.step(2)
    diag = fluid.diagnostics()
    assert "relative_energy_error" not in diag  # walls with restitution < 1 do not conserve energy
    assert len(diag) > 12  # the SPH solver's own columns


def test_blow_up_raises_simulation_error(swirl, sph_scene):
    bad = swirl.Scene.from_toml(sph_scene.toml, overrides=["simulation.dt=0.01"])
    sim = swirl.Simulation(bad)
    with pytest.raises(swirl.SimulationError, match="blow-up"):
        sim.step(50)


def test_from_arrays(swirl, tiny_scene):
    rng = np.random.default_rng(1)
    pos = rng.uniform(0.1, 0.9, size=(100, 3))
    vel = rng.normal(size=(100, 3)).astype(np.float32)
    sim = swirl.Simulation.from_arrays(tiny_scene, pos, vel, masses=2.0)
    assert sim.count == 100 and sim.precision == "float"
    np.testing.assert_array_equal(sim.particles.sorted_by_id("position"), pos.astype(np.float32))
    np.testing.assert_array_equal(sim.particles.sorted_by_id("velocity"), vel)
    np.testing.assert_array_equal(sim.particles.mass.copy(), 2.0)
    sim.step(3)
    assert sim.steps == 3
    double = swirl.Scene.from_toml(tiny_scene.toml, overrides=['simulation.precision="double"'])
    sim = swirl.Simulation.from_arrays(double, pos, None, np.full(100, 0.5, dtype=np.float32))
    assert sim.particles.position.x.dtype == np.float64
    np.testing.assert_array_equal(sim.particles.sorted_by_id("position"), pos)
    with pytest.raises(swirl.SceneError, match=r"positions\[0\]"):
        swirl.Simulation.from_arrays(tiny_scene, pos + 5.0, masses=1.0)  # outside the box


def test_from_arrays_clear_errors(swirl, tiny_scene):
    pos = np.full((4, 3), 0.5)
    cases = [
        (dict(positions=pos.astype(np.int64), masses=1.0), TypeError, "dtype int64"),
        (dict(positions=pos.tolist(), masses=1.0), TypeError, "numpy array"),
        (dict(positions=pos[:, :2], masses=1.0), ValueError, r"shape \(4, 2\)"),
        (dict(positions=np.full((4, 6), 0.5)[:, ::2], masses=1.0), ValueError, "C-contiguous"),
        (dict(positions=np.where(np.eye(4, 3) > 0, np.nan, 0.5), masses=1.0), ValueError, r"positions\[0, 0\] is nan"),
        (dict(positions=pos, velocities=np.zeros((3, 3)), masses=1.0), ValueError, "3 rows but positions has 4"),
        (dict(positions=pos, masses=np.ones(5)), ValueError, "5 rows"),
        (dict(positions=pos, masses=-1.0), ValueError, "> 0"),
        (dict(positions=pos, masses=np.array([1.0, 1.0, 0.0, 1.0])), ValueError, r"masses\[2\]"),
        (dict(positions=pos), TypeError, "needs masses"),
        (dict(positions=np.zeros((0, 3)), masses=1.0), ValueError, "empty"),
    ]
    for kwargs, error, message in cases:
        with pytest.raises(error, match=message):
            swirl.Simulation.from_arrays(tiny_scene, **kwargs)


def test_from_arrays_fuzz(swirl, tiny_scene):
    """Random shapes, dtypes, layouts and values: an exception or a working simulation, never a crash."""
    rng = np.random.default_rng(22)
    dtypes = [np.float32, np.float64, np.int32, np.int64, np.float16, np.complex64, np.bool_, object]
    built = refused = 0
    for trial in range(400):
        n = int(rng.integers(0, 6))
        arrays = []
        for _ in range(3):
            ndim = int(rng.integers(0, 4))
            shape = tuple(int(x) for x in rng.integers(0, 5, size=ndim))
            if rng.random() < 0.7:
                shape = (n, 3) if len(arrays) < 2 else (n,)
            dtype = dtypes[int(rng.integers(0, 2))] if rng.random() < 0.8 else dtypes[int(rng.integers(2, len(dtypes)))]
            a = rng.uniform(0.05, 0.95, size=shape).astype(dtype)
            r = rng.random()
            if r < 0.1 and a.ndim == 2:
                a = np.asfortranarray(a)
            elif r < 0.2 and a.ndim >= 1:
                a = a[::-1]
            elif r < 0.25 and a.size and a.dtype.kind == "f":
                a.flat[0] = np.inf
            arrays.append(a)
        velocities = None if rng.random() < 0.3 else arrays[1]
        try:
            sim = swirl.Simulation.from_arrays(tiny_scene, arrays[0], velocities, arrays[2])
        except (TypeError, ValueError):
            refused += 1
            continue
        sim.step(1)
        built += 1
    assert built > 10 and refused > 100, (built, refused)
    print(f"from_arrays fuzz: {built} built, {refused} refused")


def test_from_arrays_named_fields_travel_with_the_particles(swirl, nbody_scene):
    # The Plummer stars, again, with a tag per star and a vector field: they follow each star through the re-sorts.
    stars = swirl.Simulation(nbody_scene).particles.sorted_by_id()
    n = len(stars["mass"])
    tag = np.arange(n, dtype=np.float64) * 10.0
    spin = np.ascontiguousarray(np.stack([tag, -tag, tag + 1], axis=1))
    sim = swirl.Simulation.from_arrays(nbody_scene, stars["position"], stars["velocity"], stars["mass"],
                                       fields={"tag": tag, "spin": spin})
    sim.step(10)
    assert "tag" in sim.particles.names and isinstance(sim.particles.spin, swirl.VectorField)
    np.testing.assert_array_equal(sim.particles.sorted_by_id("tag"), tag)
    np.testing.assert_array_equal(sim.particles.sorted_by_id("spin"), spin)
    # The field of each particle, in storage order: the tag is 10 x its id.
    np.testing.assert_array_equal(sim.particles.tag.copy(), sim.particles.id.copy() * 10.0)
    with pytest.raises(ValueError, match="built-in"):
        swirl.Simulation.from_arrays(nbody_scene, stars["position"], masses=1.0, fields={"density": tag})
    with pytest.raises(ValueError, match=r"has 3 rows"):
        swirl.Simulation.from_arrays(nbody_scene, stars["position"], masses=1.0, fields={"tag": tag[:3]})


def test_from_arrays_integer_fields(swirl, nbody_scene, tmp_path):
    # An integer label per star (any integer dtype in, int32 stored): it follows each star and goes into frames.
    stars = swirl.Simulation(nbody_scene).particles.sorted_by_id()
    n = len(stars["mass"])
    label = (np.arange(n, dtype=np.int64) % 7) - 3
    sim = swirl.Simulation.from_arrays(nbody_scene, stars["position"], stars["velocity"], stars["mass"],
                                       fields={"label": label, "tag": label.astype(np.float64)})
    sim.step(10)
    assert sim.particles.label.dtype == np.int32
    np.testing.assert_array_equal(sim.particles.sorted_by_id("label"), label)
    np.testing.assert_array_equal(sim.particles.label.copy(), sim.particles.tag.copy().astype(np.int32))
    sim.write_frame(tmp_path / "f.vtp")
    assert b'Name="label"' in (tmp_path / "f.vtp").read_bytes()
    with pytest.raises(ValueError, match=r"label\[2\] is 4294967296: integer fields are stored as int32"):
        swirl.Simulation.from_arrays(nbody_scene, stars["position"], masses=1.0,
                                     fields={"label": np.array([0, 1, 2**32] + [0] * (n - 3))})
    with pytest.raises(ValueError, match=r"integer field must be \(n,\)"):
        swirl.Simulation.from_arrays(nbody_scene, stars["position"], masses=1.0,
                                     fields={"label": np.zeros((n, 3), dtype=np.int32)})
    with pytest.raises(ValueError, match="built-in"):
        swirl.Simulation.from_arrays(nbody_scene, stars["position"], masses=1.0,
                                     fields={"mass": np.zeros(n, dtype=np.int32)})


def test_two_python_threads_step_two_simulations(swirl, sph_scene, nbody_scene):
    # The GIL is released while stepping: two threads step at once, and each result is the sequential one.
    import threading

    def final(scene, steps):
        sim = swirl.Simulation(scene)
        sim.step(steps)
        return sim.particles.sorted_by_id("position")

    expected = [final(sph_scene, 30), final(nbody_scene, 30)]
    results = [None, None]

    def work(k, scene):
        results[k] = final(scene, 30)

    threads = [threading.Thread(target=work, args=(0, sph_scene)), threading.Thread(target=work, args=(1, nbody_scene))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for got, want in zip(results, expected):
        np.testing.assert_array_equal(got, want)
