"""Zero-copy views: the same memory as the C++ fields, writes reach the engine, reorders are caught."""

import numpy as np
import pytest


def test_views_share_the_cpp_memory(swirl, tiny_scene):
    sim = swirl.Simulation(tiny_scene)
    n = sim._native
    for name, components in [("position", 3), ("velocity", 3), ("acceleration", 3), ("mass", 1), ("density", 1)]:
        for c in range(components):
            view = sim.particles[name][c] if components == 3 else sim.particles[name]
            a = np.asarray(view)
            assert a.ctypes.data == n.data_pointer(name, c), (name, c)
            assert np.shares_memory(a, view.array)
            assert a.dtype == np.float32 and a.shape == (sim.count,)
    x = sim.particles.position.x
    assert np.shares_memory(x, sim.particles.position.x)  # two views, one array
    x[3] = 0.125
    assert n.value("position", 0, 3) == 0.125  # read back from the C++ storage
    sim.particles.mass[:] = 7.0
    assert all(n.value("mass", 0, i) == 7.0 for i in range(sim.count))
    x += 0.001  # in place through the view
    assert n.value("position", 0, 3) == pytest.approx(0.126)
    assert isinstance(x, swirl.FieldArray)


def test_written_state_is_stepped(swirl, tiny_scene):
    sim = swirl.Simulation(tiny_scene)
    sim.particles.velocity.x[:] = 1.0
    x0 = sim.particles.position.x.copy()
    sim.step(10)
    np.testing.assert_allclose(sim.particles.position.x, x0 + 10 * 0.001, atol=1e-6)


def test_ids_are_read_only_and_fields_named(swirl, nbody_scene):
    sim = swirl.Simulation(nbody_scene)
    ids = sim.particles.id
    assert ids.dtype == np.uint64
    with pytest.raises(ValueError):
        ids[0] = 5
    assert "potential" in sim.particles.names or len(sim.particles.names) >= 8
    with pytest.raises(KeyError, match="no particle field 'nosuch'"):
        sim.particles["nosuch"]
    with pytest.raises(AttributeError):
        sim.particles.nosuch
    with pytest.raises(AttributeError):
        sim.particles.mass = 3


def test_numpy_on_views(swirl, tiny_scene):
    sim = swirl.Simulation(tiny_scene)
    v = sim.particles.position.z
    assert np.mean(v) == pytest.approx(v.copy().mean())
    assert isinstance(v * 2, np.ndarray) and not np.shares_memory(v * 2, v)
    assert len(v) == sim.count and v.shape == (sim.count,)
    p = sim.particles.position.to_numpy()
    assert p.shape == (sim.count, 3) and not np.shares_memory(p, sim.particles.position.x)
    np.testing.assert_array_equal(p[:, 2], v)


def stale_after_reorder(swirl, sim):
    view = sim.particles.position.x
    mass = sim.particles.mass
    epoch = sim.epoch
    for _ in range(200):
        sim.step()
        if sim.epoch != epoch:
            break
    assert sim.epoch != epoch, "the particles were never reordered"
    assert not view.valid
    for use in (lambda: view[0], lambda: np.asarray(view), lambda: view + 1, lambda: np.sum(view), lambda: view.array,
                lambda: view.__setitem__(0, 1.0), lambda: mass.copy(), lambda: len(view.copy())):
        with pytest.raises(swirl.StaleViewError, match="reordered"):
            use()
    fresh = sim.particles.position.x
    assert fresh.valid and fresh.epoch == sim.epoch
    fresh[0]


def test_stale_after_reorder_sph(swirl, sph_scene):
    stale_after_reorder(swirl, swirl.Simulation(sph_scene))


def test_stale_after_reorder_gravity(swirl, nbody_scene):
    stale_after_reorder(swirl, swirl.Simulation(nbody_scene))


def test_sorted_by_id_follows_particles(swirl, nbody_scene):
    sim = swirl.Simulation(nbody_scene)
    m0 = sim.particles.sorted_by_id("mass")
    ids0 = np.sort(sim.particles.id.copy())
    sim.step(20)
    assert sim.particles.sorted_by_id("mass").tolist() == m0.tolist()
    np.testing.assert_array_equal(np.sort(sim.particles.id.copy()), ids0)
    everything = sim.particles.sorted_by_id()
    assert everything["position"].shape == (sim.count, 3)
    np.testing.assert_array_equal(everything["id"], ids0)
