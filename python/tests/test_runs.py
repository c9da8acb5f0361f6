"""Run folders as the CLI makes them: byte-identical frames, resume, Ctrl-C with a checkpoint."""

import filecmp
import os
import shutil
import signal
import subprocess
import threading

import pytest

from conftest import EXAMPLES, SPH_OVERRIDES, cli_path

STEPS = 20  # frames at steps 0, 10, 20 (output.interval = 0.004 s, dt = 4e-4 s)


def cli_run(tmp_path, *args):
    cli = cli_path()
    if cli is None:
        pytest.skip("no swirl CLI to compare with (make python-test sets SWIRL_CLI)")
    out = tmp_path / "cli"
    sets = [a for o in SPH_OVERRIDES for a in ("--set", o)]
    subprocess.run([cli, "run", str(EXAMPLES / "dam_break.toml"), *sets, "--out", str(out), *args],
                   check=True, capture_output=True)
    return out


def test_frames_byte_identical_to_the_cli(swirl, tmp_path):
    cli = cli_run(tmp_path, "--steps", str(STEPS))
    scene = swirl.Scene.from_file(EXAMPLES / "dam_break.toml", overrides=SPH_OVERRIDES)

    # The run loop, from Python.
    out = tmp_path / "py"
    summary = swirl.run(scene, out, steps=STEPS)
    assert summary["error"] == "" and summary["steps"] == STEPS and summary["frames"] == 3
    names = sorted(p.name for p in cli.iterdir() if p.name.startswith("particles") or p.name == "diagnostics.csv")
    assert "particles_000002.vtp" in names and "particles.pvd" in names
    for name in names + ["scene.toml"]:
        assert filecmp.cmp(cli / name, out / name, shallow=False), name

    # A Simulation stepped from Python, its frame written by the same writer.
    sim = swirl.Simulation(scene)
    sim.write_frame(tmp_path / "step0.vtp")
    sim.run(steps=STEPS)
    sim.write_frame(tmp_path / "step20.vtp")
    assert filecmp.cmp(cli / "particles_000000.vtp", tmp_path / "step0.vtp", shallow=False)
    assert filecmp.cmp(cli / "particles_000002.vtp", tmp_path / "step20.vtp", shallow=False)


def test_write_frame_splits_boundary_particles_as_the_run_does(swirl, tmp_path):
    # Walls of boundary particles: a run writes them to their own series (boundary_000000.vtp, once: they do
    # not move); write_frame likewise writes them beside the frame, byte-identical to the CLI's files.
    walls = 'box.walls="particles"'
    cli = cli_run(tmp_path, "--steps", str(STEPS), "--set", walls)
    scene = swirl.Scene.from_file(EXAMPLES / "dam_break.toml", overrides=SPH_OVERRIDES + [walls])
    sim = swirl.Simulation(scene)
    boundary = int((sim.particles.kind.copy() != 0).sum())
    assert 0 < boundary < sim.count
    written = sim.write_frame(tmp_path / "particles_000000.vtp")
    assert [p.name for p in written] == ["particles_000000.vtp", "boundary_000000.vtp"]
    assert filecmp.cmp(cli / "particles_000000.vtp", written[0], shallow=False)
    assert filecmp.cmp(cli / "boundary_000000.vtp", written[1], shallow=False)
    sim.run(steps=STEPS)
    written = sim.write_frame(tmp_path / "end.csv")
    assert [p.name for p in written] == ["end.csv", "end_boundary.csv"]
    rows = [sum(1 for line in open(p) if line[:1].isdigit()) for p in written]
    assert rows == [sim.count - boundary, boundary]
    sim.write_frame(tmp_path / "end.vtp")
    assert filecmp.cmp(cli / "particles_000002.vtp", tmp_path / "end.vtp", shallow=False)


def test_diagnostics_are_the_logs_row(swirl, tmp_path):
    # sim.diagnostics() is a row of diagnostics.csv: the same columns (the solvers' and the stepper's own: DFSPH's
    # iteration counts) and the same numbers as the CLI's log at the same step, to the log's 9 digits.
    dfsph = 'sph.method="dfsph"'
    cli = cli_run(tmp_path, "--steps", str(STEPS), "--set", dfsph)
    header, *rows = (cli / "diagnostics.csv").read_text().splitlines()
    names, last = header.split(","), rows[-1].split(",")
    sim = swirl.Simulation(swirl.Scene.from_file(EXAMPLES / "dam_break.toml", overrides=SPH_OVERRIDES + [dfsph]))
    sim.run(steps=STEPS)
    d = sim.diagnostics()
    assert "dfsph_density_iterations" in names
    for name, text in zip(names, last):
        if name in ("dt_min", "dt_max", "dt_next", "limited_by"):  # the log's step history since its last row
            continue
        assert name in d, name
        assert d[name] == pytest.approx(float(text), rel=2e-8, abs=1e-12), name


def test_summary_and_diagnostics(swirl, sph_scene, tmp_path):
    out = tmp_path / "run"
    summary = swirl.run(sph_scene, out, steps=10, threads=1)
    assert summary["threads"] == 1 and summary["particles"] == sph_scene.particle_count
    assert summary["phases"]["forces"] > 0 and "mean_neighbours" in summary["metrics"]
    d = swirl.read_diagnostics(out)
    assert d["time"].tolist()[0] == 0.0 and len(d["time"]) == 2
    assert "kinetic_energy" in d
    with pytest.raises(swirl.IoError, match="another run|holds"):
        swirl.run(sph_scene, out, steps=10)
    assert swirl.run(sph_scene, out, steps=10, overwrite=True)["steps"] == 10


def test_resume_is_bit_identical(swirl, sph_scene, tmp_path):
    whole = tmp_path / "whole"
    swirl.run(sph_scene, whole, steps=20)
    part = tmp_path / "part"
    first = swirl.run(sph_scene, part, steps=10, checkpoint_every_steps=5)
    assert first["last_checkpoint"].endswith("checkpoint_000000000010.swc")
    second = swirl.resume(part, steps=10)
    assert second["first_step"] == 10 and second["steps"] == 10
    assert filecmp.cmp(whole / "particles_000002.vtp", part / "particles_000002.vtp", shallow=False)


def test_a_run_on_mpi_ranks_resumes_in_python(swirl, sph_scene, tmp_path):
    # The module runs in one process; a run folder made by the CLI on 2 MPI ranks (its checkpoints are the
    # one-rank bytes) resumes from Python to the frames of an uninterrupted Python run.
    cli = cli_path()
    mpiexec = shutil.which("mpiexec")
    if cli is None or mpiexec is None:
        pytest.skip("no swirl CLI or no mpiexec (make python-test sets SWIRL_CLI; make mpi installs OpenMPI)")
    info = subprocess.run([cli, "info"], capture_output=True, text=True, check=True).stdout
    mpi_line = next((line for line in info.splitlines() if line.strip().startswith("MPI ")), "")
    if not mpi_line or "not built" in mpi_line:  # `swirl info` of a build with SWIRL_MPI=OFF: "MPI  not built (...)"
        pytest.skip("the swirl CLI was built without MPI")
    whole = tmp_path / "whole"
    swirl.run(sph_scene, whole, steps=20)
    part = tmp_path / "part"
    sets = [a for o in SPH_OVERRIDES for a in ("--set", o)]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1")
    subprocess.run([mpiexec, "-n", "2", "--oversubscribe", cli, "run", str(EXAMPLES / "dam_break.toml"), *sets,
                    "--steps", "10", "--checkpoint-every-steps", "5", "--out", str(part)],
                   check=True, capture_output=True, env=env, timeout=300)
    assert (part / "checkpoints" / "checkpoint_000000000010.swc").exists()
    second = swirl.resume(part, steps=10)
    assert second["first_step"] == 10 and second["steps"] == 10
    for name in ("particles_000001.vtp", "particles_000002.vtp", "diagnostics.csv"):
        assert filecmp.cmp(whole / name, part / name, shallow=False), name


def test_ctrl_c_stops_the_run_with_a_checkpoint(swirl, sph_scene, tmp_path):
    out = tmp_path / "run"
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            swirl.run(sph_scene, out, steps=10**6)
    finally:
        timer.cancel()
    assert list((out / "checkpoints").glob("*.swc"))
    assert swirl.resume(out, steps=2)["steps"] == 2


def test_progress_callback_can_stop(swirl, sph_scene, tmp_path):
    seen = []

    def progress(p):
        seen.append(p["step"])
        return p["step"] < 3

    summary = swirl.run(sph_scene, tmp_path / "run", steps=50, progress=progress)
    assert summary["interrupted"] and summary["steps"] == 3 and seen[-1] == 3


def test_run_with_a_callback_steers_and_resumes_bit_identically(swirl, sph_scene, tmp_path):
    """A callback that changes the state every 5 steps, in a run that writes its folder: a run stopped at step 10
    and resumed with the same callback ends byte-identical to the uninterrupted one."""
    import numpy as np

    def kick(sim):
        assert sim.steps % 5 == 0
        sim.particles.velocity.x += 0.01  # a steady push, through fresh views
        return True

    plain = swirl.run(sph_scene, tmp_path / "plain", steps=20)
    whole = swirl.run(sph_scene, tmp_path / "whole", steps=20, callback=kick, every=5)
    assert whole["steps"] == 20 and whole["error"] == ""
    assert not filecmp.cmp(tmp_path / "plain" / "particles_000002.vtp", tmp_path / "whole" / "particles_000002.vtp",
                           shallow=False)
    first = swirl.run(sph_scene, tmp_path / "part", steps=10, checkpoint_every_steps=5, callback=kick, every=5)
    assert first["steps"] == 10 and plain["steps"] == 20
    swirl.resume(tmp_path / "part", steps=10, callback=kick, every=5)
    for name in ("particles_000002.vtp", "diagnostics.csv"):
        assert filecmp.cmp(tmp_path / "whole" / name, tmp_path / "part" / name, shallow=False), name

    # At times: every 0.002 s of simulated time (dt = 4e-4 s: steps 5, 10, ...).
    seen = []
    swirl.run(sph_scene, tmp_path / "timed", steps=20, callback=lambda s: seen.append(round(s.time, 6)), every=0.002)
    np.testing.assert_allclose(seen, [0.002, 0.004, 0.006, 0.008], rtol=1e-9)


def test_run_callback_stops_raises_and_is_cut_off(swirl, sph_scene, tmp_path):
    kept = []

    def stop_at_6(sim):
        kept.append(sim)
        with pytest.raises(Exception, match="the run steps it"):
            sim.step()
        return sim.steps < 6

    summary = swirl.run(sph_scene, tmp_path / "stop", steps=50, callback=stop_at_6, every=3)
    assert summary["interrupted"] and summary["steps"] == 6
    assert summary["last_checkpoint"].endswith("checkpoint_000000000006.swc")
    with pytest.raises(RuntimeError, match="the run has ended"):
        kept[0].particles.position.x  # noqa: B018  (the run's particles are gone)

    def broken(sim):
        if sim.steps == 4:
            raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError, match="from the callback"):
        swirl.run(sph_scene, tmp_path / "raise", steps=50, callback=broken, every=2)
    assert list((tmp_path / "raise" / "checkpoints").glob("*.swc"))
    with pytest.raises(ValueError, match="give a callback too"):
        swirl.run(sph_scene, tmp_path / "x", steps=2, every=2)
    with pytest.raises(ValueError, match="every=0"):
        swirl.run(sph_scene, tmp_path / "y", steps=2, callback=print, every=0)


def test_run_with_a_python_force(swirl, tiny_scene, tmp_path):
    """A force written in Python inside a run folder's run: timed as its own phase, and it acts."""
    def lift(sim, t):
        sim.particles.acceleration.z += 9.81  # cancels the scene's gravity

    summary = swirl.run(tiny_scene, tmp_path / "lift", steps=10, forces={"lift": lift})
    assert "forces.python.lift" in summary["phases"]
    final = swirl.read_diagnostics(tmp_path / "lift")
    assert abs(final["momentum_z"][-1]) < 1e-9  # gravity cancelled: nothing falls
