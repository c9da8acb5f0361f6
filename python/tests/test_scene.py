"""Scenes from files, TOML text and dicts: round trips, overrides, the loader's messages."""

import pytest

from conftest import EXAMPLES, TINY_TOML


def test_from_file_matches_from_toml(swirl):
    path = EXAMPLES / "dam_break.toml"
    a = swirl.Scene.from_file(path)
    b = swirl.Scene.from_toml(path.read_text())
    assert a == b and a.hash == b.hash
    assert a.file == str(path) and b.file == "<toml>"
    assert a.precision == "float" and a.units == "si" and a.has_box
    assert a.dt == pytest.approx(4e-4) and a.end_time == pytest.approx(1.0)
    assert a.total_steps == 2500
    assert a.particle_count > 20000


def test_dict_round_trip(swirl):
    for name in ["dam_break.toml", "plummer.toml", "galaxy_collision.toml", "self_gravitating_drop.toml"]:
        s = swirl.Scene.from_file(EXAMPLES / name)
        d = s.to_dict()
        assert swirl.Scene.from_dict(d) == s, name
        assert swirl.Scene.from_dict(d).to_dict() == d


def test_dict_with_numpy_values(swirl):
    import numpy as np

    d = swirl.Scene.from_toml(TINY_TOML).to_dict()
    d["box"]["max"] = np.array([1.0, 1.0, 1.0])
    d["simulation"]["dt"] = np.float64(0.001)
    assert swirl.Scene.from_dict(d) == swirl.Scene.from_toml(TINY_TOML)


def test_overrides_as_set(swirl):
    s = swirl.Scene.from_file(EXAMPLES / "plummer.toml", overrides=["nbody.opening=0.7", "particles.0.count=100"])
    assert s.to_dict()["nbody"]["opening"] == 0.7
    assert s.particle_count == 100
    d = swirl.Scene.from_file(EXAMPLES / "plummer.toml").to_dict()
    assert swirl.Scene.from_dict(d, overrides=["particles.0.count=100"]).particle_count == 100
    with pytest.raises(TypeError, match="list of"):
        swirl.Scene.from_file(EXAMPLES / "plummer.toml", overrides="nbody.opening=0.7")


def test_errors_name_file_key_and_reason(swirl):
    d = swirl.Scene.from_toml(TINY_TOML).to_dict()
    d["box"]["restitutoin"] = 0.9
    with pytest.raises(swirl.SceneError, match=r"^<dict>: box\.restitutoin: unknown key \(did you mean 'restitution'\?\)"):
        swirl.Scene.from_dict(d)
    with pytest.raises(ValueError):  # SceneError is a ValueError
        swirl.Scene.from_toml(TINY_TOML.replace("dt = 0.001", "dt = -1"))
    with pytest.raises(swirl.SceneError, match=r"simulation\.dt"):
        swirl.Scene.from_toml(TINY_TOML.replace("dt = 0.001", "dt = -1"), name="mine.toml")
    with pytest.raises(swirl.SceneError, match=r"^mine\.toml: "):
        swirl.Scene.from_toml(TINY_TOML.replace("dt = 0.001", "dt = -1"), name="mine.toml")
    with pytest.raises(swirl.SceneError, match=r"nbody\.openin"):
        swirl.Scene.from_file(EXAMPLES / "plummer.toml", overrides=["nbody.openin=0.7"])
    with pytest.raises(swirl.SceneError, match=r"nosuch\.toml"):
        swirl.Scene.from_file(EXAMPLES / "nosuch.toml")
    with pytest.raises(TypeError, match=r"box\.max"):
        swirl.Scene.from_dict({"box": {"max": object()}})
