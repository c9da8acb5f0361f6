"""A scene dict as TOML text, for the one scene loader (swirl.Scene.from_dict).

The dict has the keys of a scene file; nested dicts are tables and lists of
dicts are arrays of tables (``particles``). Everything is written as inline
TOML, which the loader reads as the same tables, so a dict is checked by the
loader's own rules and messages (no second validator here). Only what TOML
cannot hold is refused here: a key that is not a string, a value that is not a
bool, int, float, str, list or dict.
"""

import math
import numbers
import re

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(key, path):
    if not isinstance(key, str):
        raise TypeError(f"scene dict: {path or 'the root'}: key {key!r} is not a string")
    return key if _BARE_KEY.match(key) else _string(key)


def _string(text):
    out = ['"']
    for ch in text:
        code = ord(ch)
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif code < 0x20 or code == 0x7F:
            out.append(f"\\u{code:04x}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _value(value, path):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        x = float(value)
        if math.isnan(x):
            return "nan"
        if math.isinf(x):
            return "inf" if x > 0 else "-inf"
        text = repr(x)
        return text if any(c in text for c in ".eE") else text + ".0"
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, dict):
        items = (f"{_key(k, path)} = {_value(v, f'{path}.{k}' if path else str(k))}" for k, v in value.items())
        return "{" + ", ".join(items) + "}"
    if isinstance(value, (list, tuple)) or (hasattr(value, "tolist") and hasattr(value, "ndim")):
        seq = value.tolist() if hasattr(value, "tolist") else value
        if not isinstance(seq, list):  # a numpy scalar
            return _value(seq, path)
        return "[" + ", ".join(_value(v, f"{path}.{i}") for i, v in enumerate(seq)) + "]"
    raise TypeError(f"scene dict: {path}: a {type(value).__name__} is not a TOML value "
                    "(give a bool, number, string, list or dict)")


def dict_to_toml(scene):
    """The TOML text of a scene dict: one ``key = value`` line per root key."""
    if not isinstance(scene, dict):
        raise TypeError(f"a scene dict must be a dict, not a {type(scene).__name__}")
    return "".join(f"{_key(k, '')} = {_value(v, str(k))}\n" for k, v in scene.items())
