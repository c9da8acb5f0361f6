"""Forces written in Python (with their cost) and pictures of run folders (as `swirl render`)."""

import filecmp
import gc
import subprocess
import weakref

import numpy as np
import pytest

from conftest import cli_path


def test_python_force_matches_the_built_in_field(swirl, tiny_scene):
    # Gravity off in the scene, the same uniform field from Python: the same trajectory.
    no_g = swirl.Scene.from_toml(tiny_scene.toml, overrides=["forces.gravity=[0.0, 0.0, 0.0]"])
    calls = []

    def gravity(sim, t):
        calls.append(t)
        sim.particles.acceleration.z -= 9.81

    with_python = swirl.Simulation(no_g, forces={"gravity": gravity})
    built_in = swirl.Simulation(tiny_scene)
    with_python.step(10)
    built_in.step(10)
    np.testing.assert_array_equal(with_python.particles.sorted_by_id("position"),
                                  built_in.particles.sorted_by_id("position"))
    assert len(calls) == 11 and calls[0] == 0.0  # the initial state, then once per step
    assert with_python.phases()["forces.python.gravity"] > 0
    assert "relative_energy_error" not in with_python.diagnostics()


def test_python_force_sees_fresh_views_after_reorders(swirl, nbody_scene):
    epochs = []

    def drag(sim, t):
        v = sim.particles.velocity
        a = sim.particles.acceleration
        for c in range(3):
            a[c] -= 0.1 * v[c]
        epochs.append(sim.epoch)

    sim = swirl.Simulation(nbody_scene, forces=[drag])
    sim.step(20)
    assert len(set(epochs)) > 1  # the particles were re-sorted between calls, and each call's views were fresh
    assert sim.phases()["forces.python.drag"] > 0


def test_python_force_errors(swirl, tiny_scene):
    def bad(sim, t):
        if t > 0.0025:
            raise ZeroDivisionError("from the force")

    sim = swirl.Simulation(tiny_scene, forces={"bad": bad})
    with pytest.raises(ZeroDivisionError):
        sim.step(10)
    assert sim.steps == 2
    with pytest.raises(RuntimeError, match="cannot go on"):
        sim.step()
    with pytest.raises(ValueError, match="identifier"):
        swirl.Simulation(tiny_scene, forces={"a b": bad})
    with pytest.raises(TypeError, match="callable"):
        swirl.Simulation(tiny_scene, forces={"x": 3})


def test_simulation_with_force_is_freed(swirl, tiny_scene):
    sim = swirl.Simulation(tiny_scene, forces=[lambda s, t: None])
    ref = weakref.ref(sim)
    del sim
    gc.collect()
    assert ref() is None


def test_render_matches_the_cli(swirl, sph_scene, tmp_path):
    out = tmp_path / "run"
    swirl.run(sph_scene, out, steps=10)
    image = swirl.render(out, 1, size=(320, 200), png=tmp_path / "py.png")
    assert image.shape == (200, 320, 3) and image.dtype == np.uint8
    assert image.std() > 5  # a picture, not a blank
    cli = cli_path()
    if cli is None:
        pytest.skip("no swirl CLI to compare with")
    subprocess.run([cli, "render", str(out), "--frame", "1", "--size", "320x200", "--out", str(tmp_path / "cli")],
                   check=True, capture_output=True)
    assert filecmp.cmp(tmp_path / "cli" / "particles_000001.png", tmp_path / "py.png", shallow=False)
    with pytest.raises(IndexError, match="no frame 7"):
        swirl.render(out, 7)
    with pytest.raises(ValueError):
        swirl.render(out, view="sideways")


def test_render_a_simulation_state_as_the_run_folder_frame(swirl, sph_scene, tmp_path):
    """sim.render() draws the current state with the renderer swirl render uses: camera and colours fixed at the
    first call, as from a run's first frame, so the same state gives the same picture as the run folder's frame."""
    out = tmp_path / "dam_break"  # the caption names the run folder, or the scene file's stem: the same here
    swirl.run(sph_scene, out, steps=20)
    reference = swirl.render(out, 2, size=(320, 200))
    sim = swirl.Simulation(sph_scene)
    first = sim.render(size=(320, 200), png=tmp_path / "first.png")
    np.testing.assert_array_equal(first, swirl.render(out, 0, size=(320, 200)))
    assert (tmp_path / "first.png").stat().st_size > 1000
    sim.step(20)
    np.testing.assert_array_equal(sim.render(size=(320, 200)), reference)
    # Other arguments fix the camera and colours anew; bad ones are refused.
    assert sim.render(view="top", size=(128, 96)).shape == (96, 128, 3)
    with pytest.raises(ValueError):
        sim.render(view="sideways")
    with pytest.raises(ValueError, match="between 64 and 16384"):
        sim.render(size=(32, 32))
    with pytest.raises(ValueError, match="between 64 and 16384"):
        swirl.render(out, 0, size=(100000, 100))
