"""Every script of examples/python/ runs, at its smallest sensible size, and writes what it promises."""

import subprocess
import sys

import pytest

from conftest import REPO

SCRIPTS = REPO / "examples" / "python"

# script: (its smallest arguments, besides --out; the files it promises in --out)
RUNS = {
    "dam_break.py": (["--spacing", "0.04", "--until", "0.5"], ["front.png", "front.csv"]),
    "plummer.py": (["--count", "256", "--until", "0.5"], ["plummer.png", "plummer.csv"]),
    "galaxy_collision.py": (["--count", "256", "--until", "1"],
                            ["run/particles.pvd", "run/diagnostics.csv", "png/frame_0000.png", "png/frame_0001.png"]),
    "rotating_frame.py": (["--count", "64", "--until", "0.25"], ["difference.png", "difference.csv"]),
    "paddle.py": (["--spacing", "0.02", "--until", "1.2"], ["waves.png", "waves.csv"]),
}


def test_every_example_is_run_here():
    assert sorted(p.name for p in SCRIPTS.glob("*.py")) == sorted(RUNS)


@pytest.mark.parametrize("script", sorted(RUNS))
def test_example_runs(script, tmp_path):
    args, outputs = RUNS[script]
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, str(SCRIPTS / script), *args, "--out", str(out)],
                            capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert result.returncode == 0, f"{script} failed:\n{result.stdout}\n{result.stderr}"
    missing = [name for name in outputs if not (out / name).is_file()]
    assert not missing, f"{script} did not write {missing}; it printed:\n{result.stdout}"
