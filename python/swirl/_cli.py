"""The swirl command-line tool, in this process: ``cli``, ``bench`` and the ``swirl`` command.

The tool is the C++ ``run_cli`` that the ``swirl`` executable runs (apps/swirl/run_cli.hpp);
nothing here re-implements a command.
"""

import json
import os
import pathlib
import subprocess
import sys
import tempfile

from . import _swirl


def cli(args, capture=False):
    """Runs the swirl command-line tool in this process, as ``swirl ARGS...`` in a shell.

    ``args`` is a list of strings without the program name: ``swirl.cli(["run", "scene.toml",
    "--out", "out/a"])``. Returns the tool's exit status (int): 0 done, 1 the run failed
    (blow-up, write error), 2 bad input; the tool prints its messages to this process's
    stdout and stderr (C stdio: in a notebook they go to the terminal that started it).
    With ``capture=True`` they are captured instead and a ``subprocess.CompletedProcess``
    is returned (``returncode``, ``stdout``, ``stderr`` as str): for notebooks. Capturing
    redirects the process's file descriptors 1 and 2 for the call, so output of other
    threads meanwhile is captured too.

    Ctrl-C during ``swirl run`` stops the run after its current step and writes a checkpoint,
    as in a shell; then KeyboardInterrupt is raised here. Python's own signal handlers and
    swirl's thread count are as before once the call returns. The GIL is released meanwhile.
    """
    if isinstance(args, (str, bytes)):
        raise TypeError("swirl.cli: args is a list of strings (the words after 'swirl'), not one string")
    words = [str(a) if isinstance(a, pathlib.PurePath) else a for a in args]
    for w in words:
        if not isinstance(w, str):
            raise TypeError(f"swirl.cli: every argument is a str or a path, got {type(w).__name__}: {w!r}")
    sys.stdout.flush()
    sys.stderr.flush()
    if capture:
        with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
            saved = os.dup(1), os.dup(2)
            try:
                os.dup2(out.fileno(), 1)
                os.dup2(err.fileno(), 2)
                status = _swirl.cli(words)
            finally:
                os.dup2(saved[0], 1)
                os.dup2(saved[1], 2)
                os.close(saved[0])
                os.close(saved[1])
            out.seek(0)
            err.seek(0)
            captured = subprocess.CompletedProcess(["swirl", *words], status,
                                                   out.read().decode(errors="replace"),
                                                   err.read().decode(errors="replace"))
    else:
        status = _swirl.cli(words)
    if status in (130, 143):
        raise KeyboardInterrupt(f"swirl {' '.join(words[:1])}: stopped by a signal (exit status {status}); "
                                "a run folder can be continued with swirl.resume()")
    return captured if capture else status


def _flag_words(name, value):
    flag = "--" + name.replace("_", "-")
    if value is None or value is False:
        return []
    if value is True:
        return [flag]
    if isinstance(value, (list, tuple)):
        return [flag, ",".join(str(v) for v in value)]
    return [flag, str(value)]


class BenchResult(dict):
    """A bench suite's results: the ``<suite>.json`` the suite wrote, as a dict.

    Keys as in that file: ``suite``, ``title``, ``command``, ``date``, ``machine``, ``build``,
    ``threads``, ``quick``, ``parameters``, ``tables`` (name -> {"file", "rows": [row dicts]}),
    ``plots``. ``path`` is the output folder (CSV, markdown, PNG plots beside the JSON);
    ``table(name)`` gives a table's rows as a list of dicts.
    """

    def __init__(self, data, path):
        super().__init__(data)
        self.path = pathlib.Path(path)

    def table(self, name="main"):
        """The rows of table ``name`` ("main" is the suite's first table): a list of dicts, column -> value."""
        tables = self.get("tables", {})
        if name not in tables:
            raise KeyError(f"bench {self.get('suite')}: no table {name!r} (tables: {', '.join(tables)})")
        return tables[name]["rows"]


def bench(suite, out=None, threads=None, quick=False, **options):
    """Runs a ``swirl bench`` suite in this process and returns its results (a BenchResult).

    ``suite``: sph-table, hash-stats, bh-table, bh-lambda, bh-phases, bh-opt, bh-scale
    (``swirl bench --help`` lists them; docs/performance/bench-suites.md says what each measures).
    ``out``: the output folder (default: the CLI's, bench/results/<suite> or, with quick,
    out/bench-quick/<suite>, relative to the working directory). ``threads``: thread counts,
    e.g. ``[1, 2]`` (default 1 .. all cores). ``quick``: tiny sizes, to check the pipeline, not
    the speed. Any other option of the suite as a keyword, underscores for dashes, lists
    joined by commas: ``swirl.bench("bh-table", sizes=[1024, 8192], quick=True)`` is
    ``swirl bench bh-table --sizes 1024,8192 --quick``.

    Raises ValueError for options the suite refuses (status 2) and RuntimeError if it fails.
    """
    # The folder is always passed, so that the results are read back from where they were written.
    folder = pathlib.Path(out) if out is not None else pathlib.Path(
        "out/bench-quick" if quick else "bench/results") / str(suite)
    words = ["bench", str(suite), "--out", str(folder)]
    words += _flag_words("threads", list(threads) if threads is not None else None)
    words += _flag_words("quick", bool(quick))
    for name, value in options.items():
        words += _flag_words(name, value)
    status = cli(words)
    if status == 2:
        raise ValueError(f"swirl bench {suite}: refused its arguments {words[4:]} (the message is on stderr)")
    if status != 0:
        raise RuntimeError(f"swirl bench {suite}: failed with exit status {status} (the message is on stderr)")
    report = folder / f"{suite}.json"
    with open(report, encoding="utf-8") as f:
        return BenchResult(json.load(f), folder)


def main():
    """The ``swirl`` command that ``pip install`` adds: the same tool as the C++ executable."""
    try:
        return cli(sys.argv[1:])
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
