"""Shared scenes and paths for the swirl Python tests (run by `make python-test`)."""

import os
import pathlib

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"

# A small dam break: ~840 SPH particles (the particle order re-sorts as they move).
SPH_OVERRIDES = ["particles.0.spacing=0.04", "output.interval=0.004"]
# A small Plummer sphere (Barnes-Hut; the Morton order re-sorts).
NBODY_OVERRIDES = ["particles.0.count=512", "output.interval=0.0625"]

TINY_TOML = """
[simulation]
dt = 0.001
steps = 10
[box]
min = [0.0, 0.0, 0.0]
max = [1.0, 1.0, 1.0]
restitution = 0.5
[forces]
gravity = [0.0, 0.0, -9.81]
[[particles]]
kind = "lattice"
min = [0.2, 0.2, 0.2]
max = [0.8, 0.8, 0.8]
spacing = 0.2
mass = 1.0
"""


@pytest.fixture
def swirl():
    import swirl as module

    return module


@pytest.fixture
def sph_scene(swirl):
    return swirl.Scene.from_file(EXAMPLES / "dam_break.toml", overrides=SPH_OVERRIDES)


@pytest.fixture
def nbody_scene(swirl):
    return swirl.Scene.from_file(EXAMPLES / "plummer.toml", overrides=NBODY_OVERRIDES)


@pytest.fixture
def tiny_scene(swirl):
    return swirl.Scene.from_toml(TINY_TOML)


def cli_path():
    """The swirl CLI to compare with: $SWIRL_CLI (make python-test sets it), else build/swirl."""
    path = os.environ.get("SWIRL_CLI") or str(REPO / "build" / "swirl")
    return path if os.access(path, os.X_OK) else None
