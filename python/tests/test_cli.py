"""swirl.cli and swirl.bench: the command-line tool in-process, the same bytes as the executable."""

import filecmp
import signal

import pytest

from conftest import EXAMPLES, SPH_OVERRIDES, cli_path
from test_runs import STEPS, cli_run


def test_cli_run_is_the_executable(swirl, tmp_path):
    """swirl.cli(["run", ...]) writes the run folder the swirl executable writes, byte for byte."""
    reference = cli_run(tmp_path, "--steps", str(STEPS))
    out = tmp_path / "in-process"
    sets = [a for o in SPH_OVERRIDES for a in ("--set", o)]
    assert swirl.cli(["run", EXAMPLES / "dam_break.toml", *sets, "--out", out, "--steps", str(STEPS)]) == 0
    names = sorted(p.name for p in reference.iterdir() if p.suffix in (".vtp", ".pvd", ".csv", ".toml"))
    assert "particles_000002.vtp" in names
    for name in names:
        assert filecmp.cmp(reference / name, out / name, shallow=False), name
    # Python's handlers and the thread count are back after the tool's run.
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_cli_statuses_and_errors(swirl, tmp_path, capfd):
    assert swirl.cli(["--version"]) == 0
    assert "swirl " in capfd.readouterr().out
    assert swirl.cli(["run", str(tmp_path / "missing.toml")]) == 2
    assert "missing.toml" in capfd.readouterr().err
    assert swirl.cli(["no-such-command"]) == 2
    # An existing run folder is not overwritten by surprise, from Python either.
    out = tmp_path / "run"
    assert swirl.cli(["run", EXAMPLES / "dam_break.toml", "--set", SPH_OVERRIDES[0], "--out", out, "--steps", "1"]) == 0
    assert swirl.cli(["run", EXAMPLES / "dam_break.toml", "--set", SPH_OVERRIDES[0], "--out", out, "--steps", "1"]) == 2
    assert "--overwrite" in capfd.readouterr().err
    with pytest.raises(TypeError, match="list of strings"):
        swirl.cli("run scene.toml")
    with pytest.raises(TypeError, match="every argument"):
        swirl.cli(["run", 3])


def test_bench_returns_the_suites_tables(swirl, tmp_path):
    before = swirl.threads()
    result = swirl.bench("hash-stats", out=tmp_path / "hs", threads=[1], quick=True)
    assert swirl.threads() == before  # the suite's --threads is not left behind
    assert result["suite"] == "hash-stats" and result["quick"] is True and result["threads"] == [1]
    rows = {r["statistic"]: r for r in result.table()}
    assert rows["particles"]["thesis"] == 15000 and rows["mean_neighbours"]["swirl"] > 10
    assert (result.path / "hash-stats.csv").exists() and (result.path / "hash-stats.md").exists()
    with pytest.raises(KeyError, match="no table 'nope'"):
        result.table("nope")
    with pytest.raises(ValueError, match="refused"):
        swirl.bench("hash-stats", out=tmp_path / "x", quick=True, no_such_option=3)
    with pytest.raises(ValueError, match="refused"):
        swirl.bench("no-such-suite", out=tmp_path / "y")


def test_bench_default_folder(swirl, tmp_path, monkeypatch):
    """Without out=, the CLI's folders relative to the working directory (out/bench-quick/<suite> with quick)."""
    import pathlib

    monkeypatch.chdir(tmp_path)
    result = swirl.bench("hash-stats", threads=[1], quick=True)
    assert result.path == pathlib.Path("out/bench-quick/hash-stats")
    assert (tmp_path / "out" / "bench-quick" / "hash-stats" / "hash-stats.json").exists()


def test_bench_option_words(swirl, tmp_path):
    """Keywords become the CLI's flags: lists joined by commas, True a bare flag, None and False left out."""
    from swirl._cli import _flag_words

    assert _flag_words("sizes", [1024, 8192]) == ["--sizes", "1024,8192"]
    assert _flag_words("check_placement", "after") == ["--check-placement", "after"]
    assert _flag_words("quick", True) == ["--quick"] and _flag_words("quick", False) == []
    assert _flag_words("threads", None) == []


@pytest.mark.skipif(cli_path() is None, reason="no swirl executable to compare with")
def test_bench_json_has_the_executables_shape(swirl, tmp_path):
    import json
    import subprocess

    subprocess.run([cli_path(), "bench", "hash-stats", "--quick", "--threads", "1", "--out", str(tmp_path / "exe")],
                   check=True, capture_output=True)
    exe = json.loads((tmp_path / "exe" / "hash-stats.json").read_text())
    mine = swirl.bench("hash-stats", out=tmp_path / "py", threads=[1], quick=True)
    assert set(exe) == set(mine) and set(exe["tables"]) == set(mine["tables"])
    # The statistics of the settled state are deterministic: the same in both.
    assert exe["tables"]["main"]["rows"] == mine["tables"]["main"]["rows"]


def test_cli_ctrl_c_checkpoints_and_raises(swirl, tmp_path):
    """Ctrl-C during swirl.cli(["run", ...]): the tool's own handler stops after the step and writes a checkpoint,
    KeyboardInterrupt is raised here, and Python's handler is back."""
    import os
    import threading

    out = tmp_path / "run"
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt, match="exit status 130"):
            swirl.cli(["run", EXAMPLES / "dam_break.toml", "--set", SPH_OVERRIDES[0], "--out", out,
                       "--steps", str(10**6)])
    finally:
        timer.cancel()
    assert list((out / "checkpoints").glob("*.swc"))
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    assert swirl.cli(["run", "--resume", out, "--steps", "2"]) == 0


def test_cli_capture_for_notebooks(swirl, tmp_path):
    """capture=True: the tool's C stdio output comes back as strings, and the process's descriptors are restored."""
    import os

    before = [(os.fstat(fd).st_dev, os.fstat(fd).st_ino) for fd in (1, 2)]
    result = swirl.cli(["--version"], capture=True)
    assert result.returncode == 0 and result.stdout.startswith("swirl ") and result.stderr == ""
    result = swirl.cli(["run", str(tmp_path / "missing.toml")], capture=True)
    assert result.returncode == 2 and "missing.toml" in result.stderr and result.stdout == ""
    assert [(os.fstat(fd).st_dev, os.fstat(fd).st_ino) for fd in (1, 2)] == before
