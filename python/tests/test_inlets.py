"""A scene with an inlet and an outlet: swirl.Simulation sees the count change
(sim.count, the views taken after a step), and a view taken before is stale."""

import numpy as np
import pytest

INLET_TOML = """
[simulation]
precision = "double"
dt = 0.001
steps = 100

[box]
min = [0.0, 0.0, 0.0]
max = [0.2, 0.2, 0.3]

[sph]
method = "dfsph"
smoothing_length = 0.04

[[particles]]
kind = "fluid_block"
min = [0.0, 0.0, 0.0]
max = [0.2, 0.2, 0.04]
spacing = 0.02

[[inlets]]
center = [0.1, 0.1, 0.25]
direction = [0, 0, -1]
radius = 0.05
speed = 1.0
spacing = 0.02

[[outlets]]
min = [0.0, 0.0, -0.1]
max = [0.05, 0.2, 0.1]
"""


def test_the_count_changes_and_views_follow(swirl):
    sim = swirl.Simulation(swirl.Scene.from_toml(INLET_TOML))
    assert sim.count == 200
    old = sim.particles.mass  # a view of the 200 particles
    sim.step(30)
    # Layers of 21 at t = 0, 0.02 (by t = 0.03), the outlet's column of the water gone.
    assert sim.count != 200
    with pytest.raises(swirl.StaleViewError):
        old[0]
    ids = sim.particles.copy("id")
    assert len(ids) == sim.count
    assert len(np.unique(ids)) == sim.count
    assert ids.max() >= 200 + 2 * 21 - 1  # the entering particles' fresh ids
    x = sim.particles.copy("position")
    assert x.shape == (sim.count, 3)
    fluid_in_outlet = (x[:, 0] < 0.05) & (x[:, 2] < 0.1)
    assert not fluid_in_outlet.any()
