#!/usr/bin/env python3
"""Compile the same files in two build trees side by side and print both times.

Usage: compare_compile_times.py OLD_BUILD NEW_BUILD FILE...

OLD_BUILD and NEW_BUILD are CMake build trees (with compile_commands.json, as
the presets write) of two checkouts; FILE is a path suffix of a source, e.g.
tests/sim/guard_test.cpp. For each FILE the two compile commands run at the
same time, one per core, so both see the same load (this machine is shared and
noisy: compare the two columns of one row, not rows of different days). The
objects go to a temporary folder; the trees are not touched. ccache is skipped.
"""
import json
import pathlib
import re
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor


def command_for(tree, suffix, out):
    """(directory, shell command) compiling SUFFIX in TREE into OUT, without ccache."""
    for entry in json.loads((pathlib.Path(tree) / "compile_commands.json").read_text()):
        if entry["file"].endswith(suffix):
            command = re.sub(r"^\S*ccache\s+", "", entry["command"])
            return entry["directory"], re.sub(r" -o \S+", f" -o {out}", command, count=1)
    sys.exit(f"compare_compile_times: {suffix} is not in {tree}/compile_commands.json")


def timed(directory_and_command):
    directory, command = directory_and_command
    start = time.monotonic()
    subprocess.run(command, shell=True, cwd=directory, check=True)
    return time.monotonic() - start


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    old, new, files = sys.argv[1], sys.argv[2], sys.argv[3:]
    with tempfile.TemporaryDirectory() as tmp, ThreadPoolExecutor(2) as pool:
        print(f"{'file':45} {'old (s)':>8} {'new (s)':>8}")
        for suffix in files:
            jobs = [command_for(old, suffix, f"{tmp}/old.o"), command_for(new, suffix, f"{tmp}/new.o")]
            t_old, t_new = pool.map(timed, jobs)
            print(f"{suffix:45} {t_old:8.1f} {t_new:8.1f}", flush=True)


if __name__ == "__main__":
    main()
