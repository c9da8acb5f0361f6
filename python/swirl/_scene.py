"""swirl.Scene: a validated scene, from a file, TOML text or a dict."""

import os
import tomllib

from . import _swirl


def _overrides(overrides):
    if overrides is None:
        return []
    if isinstance(overrides, str):
        raise TypeError('overrides is a list of "key=value" strings, e.g. ["nbody.opening=0.7"], not one string')
    out = []
    for o in overrides:
        if not isinstance(o, str):
            raise TypeError(f'overrides: {o!r} is not a "key=value" string')
        out.append(o)
    return out


class Scene:
    """A validated scene: what a scene file describes (docs/scenes.md lists every key).

    Make one with ``Scene.from_file(path)``, ``Scene.from_toml(text)`` or
    ``Scene.from_dict(d)``; all three go through the loader ``swirl run`` uses,
    so a mistake raises ``swirl.SceneError`` (a ``ValueError``) with the CLI's
    message: the file (``<toml>`` or ``<dict>`` when there is none), the key
    and the reason, e.g. ``scene.toml: box.restitutoin: unknown key (did you
    mean 'restitution'?)``.

    ``overrides`` (all three): a list of ``"key=value"`` strings, exactly as
    ``swirl run --set``: a dotted key and a TOML value, applied before
    validation, e.g. ``["nbody.opening=0.7", "particles.0.count=5000"]``.

    A Scene is immutable; its figures are read-only properties. Units follow
    ``simulation.units``: SI (s, m, kg) or N-body (G = 1).
    """

    __slots__ = ("_scene",)

    def __init__(self, _native):
        if not isinstance(_native, _swirl.Scene):
            raise TypeError("make a Scene with Scene.from_file(), Scene.from_toml() or Scene.from_dict()")
        self._scene = _native

    @classmethod
    def from_file(cls, path, overrides=None):
        """Reads and validates the scene file ``path`` (str or os.PathLike).

        ``overrides``: list of ``"key=value"`` (as ``--set``), default none.
        Raises ``SceneError`` naming the file, the key and the reason.
        """
        return cls(_swirl.load_scene(os.fspath(path), _overrides(overrides)))

    @classmethod
    def from_toml(cls, text, overrides=None, name="<toml>"):
        """Validates a scene given as TOML text; ``name`` stands for the file in messages (default ``"<toml>"``)."""
        if not isinstance(text, str):
            raise TypeError(f"from_toml takes the TOML text as a str, not a {type(text).__name__}")
        return cls(_swirl.parse_scene(text, name, _overrides(overrides)))

    @classmethod
    def from_dict(cls, scene, overrides=None, name="<dict>"):
        """Validates a scene given as a dict with the keys of a scene file.

        Tables are dicts (``{"simulation": {"dt": 0.001, ...}}``), the
        ``particles`` sources a list of dicts, vectors lists of three numbers
        (numpy arrays are accepted). The dict becomes TOML text for the same
        loader as a file, so the checks and messages are the file's;
        ``name`` stands for the file in messages (default ``"<dict>"``).
        """
        from ._toml import dict_to_toml

        return cls(_swirl.parse_scene(dict_to_toml(scene), name, _overrides(overrides)))

    @property
    def toml(self):
        """The scene as TOML after overrides (what a run saves as ``scene.toml``); str."""
        return self._scene.toml

    def to_dict(self):
        """The scene as a dict (the TOML text parsed by ``tomllib``): ``Scene.from_dict(s.to_dict())`` is ``s``."""
        return tomllib.loads(self._scene.toml)

    @property
    def file(self):
        """Where the scene came from (the path, ``"<toml>"`` or ``"<dict>"``), as used in messages."""
        return self._scene.file

    @property
    def hash(self):
        """The scene's stable 64-bit hash (docs/scenes.md "Scene hash"; checkpoints carry it); int."""
        return self._scene.hash

    @property
    def precision(self):
        """``"float"`` or ``"double"``: the particle fields' floating-point type (simulation.precision)."""
        return self._scene.precision

    @property
    def units(self):
        """``"si"`` (s, m, kg) or ``"nbody"`` (G = 1)."""
        return self._scene.units

    @property
    def dt(self):
        """The time step (s, or N-body time); with adaptive steps the largest step, dt_max."""
        return self._scene.dt

    @property
    def adaptive_dt(self):
        """True when ``simulation.dt = "adaptive"``."""
        return self._scene.adaptive_dt

    @property
    def end_time(self):
        """``simulation.end_time`` (s or N-body time), or None when the scene gives ``steps``."""
        return self._scene.end_time

    @property
    def total_steps(self):
        """The steps the scene asks for: ``steps``, or ceil(end_time / dt); int."""
        return self._scene.total_steps

    @property
    def output_interval(self):
        """Simulated time between frames (``output.interval``); 0: first and last frame only."""
        return self._scene.output_interval

    @property
    def particle_count(self):
        """How many particles the scene's ``[[particles]]`` sources make; int."""
        return self._scene.particle_count

    @property
    def has_box(self):
        """True when the scene has a ``[box]`` (walls); False for open space."""
        return self._scene.has_box

    def __eq__(self, other):
        """Scenes are equal when their validated contents are (the same ``hash``)."""
        return isinstance(other, Scene) and self.hash == other.hash

    def __hash__(self):
        return hash(self.hash)

    def __repr__(self):
        return f"<swirl.Scene {self.file!r}: {self.particle_count} particles, {self.precision}, dt = {self.dt:g}>"
