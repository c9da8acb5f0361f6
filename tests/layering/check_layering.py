#!/usr/bin/python3
"""The module layering, checked from the #include lines.

Reads every file under include/swirl/<module>/, src/<module>/ and apps/swirl/
and fails when a module includes a header of a module that is not strictly
below it (its own headers excepted): modules of the same rank stay
independent. A module missing from the table fails the check, so a new module
must be placed in it.

The ranks are the layering that holds today (lowest first). docs name the
coarse layers core; parallel; spatial, io; dist; force, integrate, boundary, sph,
gravity; scene; sim; render; view; CLI. dist sits above spatial: the ghosts
of a rank (dist/halo.hpp) are found in the particle order's key frame and cells. Within the solver layer the includes are
finer: the steppers (integrate) apply the box (boundary) and return the
step's scan (force/step_scan.hpp); sph and gravity implement the Solver seam
(force) and gravity's benchmark steps with a stepper (integrate). So
boundary < force < integrate < sph, gravity. render reads scenes (the run's
Scene) and io (frames) but not sim; view sits above render, whose surface
mesh it sends the page.

Usage: check_layering.py SOURCE_DIR
"""
import pathlib
import re
import sys

RANK = {
    "core": 0,
    "parallel": 1,
    "spatial": 2, "io": 2,
    "dist": 3,
    "boundary": 4,
    "force": 5,
    "integrate": 6,
    "sph": 7, "gravity": 7,
    "scene": 8,
    "sim": 9,
    "render": 10,
    "view": 11,  # the live view sends the fluid's surface (render/surface_mesh.hpp)
    "apps": 12,  # apps/swirl: the CLI, above everything
}

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]swirl/([A-Za-z0-9_]+)/', re.MULTILINE)


def module_files(root):
    """(module, path) for every C++ file of every module and of the CLI."""
    for base in ("include/swirl", "src"):
        for folder in sorted((root / base).iterdir()):
            if folder.is_dir():
                for path in sorted(folder.rglob("*")):
                    if path.suffix in (".hpp", ".cpp", ".h", ".inl"):
                        yield folder.name, path
    for path in sorted((root / "apps" / "swirl").rglob("*")):
        if path.suffix in (".hpp", ".cpp"):
            yield "apps", path


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    problems = []
    checked = 0
    for module, path in module_files(root):
        checked += 1
        if module not in RANK:
            problems.append(f"{path.relative_to(root)}: module '{module}' has no rank in check_layering.py")
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        for match in INCLUDE.finditer(text):
            target = match.group(1)
            line = text.count("\n", 0, match.start()) + 1
            if target not in RANK:
                problems.append(f"{path.relative_to(root)}:{line}: includes unknown module '{target}'")
            elif target != module and RANK[target] >= RANK[module]:
                problems.append(f"{path.relative_to(root)}:{line}: {module} (rank {RANK[module]}) includes "
                                f"{target} (rank {RANK[target]}), which is not below it")
    if checked == 0:
        problems.append(f"no source files found under {root}")
    for p in problems:
        print(p)
    print(f"{checked} files checked, {len(problems)} layering problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
