"""`pip install .` from the repository root in a fresh venv, then import swirl, step a scene and run an example (slow: one test)."""

import os
import shutil
import subprocess
import sys

from conftest import REPO, TINY_TOML


def test_pip_install_in_a_fresh_venv(tmp_path):
    venv = tmp_path / "venv"
    # Debian's Python (the project's; this test runs in a venv made from it), its numpy through the system site.
    base = getattr(sys, "_base_executable", sys.executable)
    subprocess.run([base, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    python = str(venv / "bin" / "python")
    env = dict(os.environ)
    env.setdefault("CMAKE_BUILD_PARALLEL_LEVEL", "2")
    cmd = [python, "-m", "pip", "install", "-q", str(REPO),
           # The CMake tree of `make python`, with its flags: the engine's objects are reused, and only
           # nanobind and the module (whose nanobind is now the isolated build environment's) are compiled.
           f"--config-settings=build-dir={REPO / 'build-python' / 'build'}",
           "--config-settings=cmake.define.SWIRL_NATIVE=ON"]
    if shutil.which("ccache"):
        cmd.append("--config-settings=cmake.define.CMAKE_CXX_COMPILER_LAUNCHER=ccache")
    subprocess.run(cmd, check=True, env=env, cwd=tmp_path, timeout=1800)
    script = (
        "import swirl\n"
        f"scene = swirl.Scene.from_toml({TINY_TOML!r})\n"
        "sim = swirl.Simulation(scene)\n"
        "sim.step(3)\n"
        "assert sim.steps == 3\n"
        "print(swirl.__file__)\n"
    )
    result = subprocess.run([python, "-c", script], check=True, capture_output=True, text=True, cwd=tmp_path)
    assert str(venv) in result.stdout
    # And an example a newcomer runs first, small.
    example = REPO / "examples" / "python" / "rotating_frame.py"
    result = subprocess.run([python, str(example), "--count", "128", "--until", "0.5", "--out", str(tmp_path / "example")],
                            check=True, capture_output=True, text=True, cwd=tmp_path)
    assert "RMS distance" in result.stdout and (tmp_path / "example" / "difference.png").exists()
    # The `swirl` command the package installs: the same tool as the executable.
    result = subprocess.run([str(venv / "bin" / "swirl"), "--version"], check=True, capture_output=True, text=True)
    assert result.stdout.startswith("swirl ")
