"""Limits that keep careless or hostile input from hanging or exhausting the machine.

Every limit has a name, a default and a reason (see docs/reliability.md). Change one for
a process with the environment variable ``MECHSYN_LIMIT_<NAME>`` (e.g.
``MECHSYN_LIMIT_LINKS=100000 mechsyn analyze big.yaml``) or in Python with
:func:`set_limit`. Messages that hit a limit name that variable.

Examples
--------
>>> limit("sweep_points")
1000000
>>> set_limit("sweep_points", 10)
>>> limit("sweep_points")
10
>>> set_limit("sweep_points", None)  # back to the default
>>> limit("sweep_points")
1000000
"""

from __future__ import annotations

import os

from mechsyn.errors import MechsynInputError

__all__ = ["DEFAULTS", "limit", "set_limit", "limit_hint"]

#: name -> (default, what it bounds)
DEFAULTS: dict[str, tuple[float, str]] = {
    "file_bytes": (50_000_000, "size of an input file in bytes"),
    "nesting": (64, "nesting depth of lists and mappings in an input file"),
    "values": (5_000_000, "values in an input file (YAML aliases counted expanded)"),
    "coordinate": (1e100, "magnitude of a coordinate or bound (squares of 1e154 overflow)"),
    "expression_chars": (10_000, "length of a cam profile expression"),
    "sweep_points": (1_000_000, "positions of one input sweep or synthesis grid"),
    "links": (2_000, "links of a mechanism file (analysis time grows as the cube)"),
    "joints": (4_000, "joints of a mechanism file"),
    "atlas_links": (14, "links of an atlas enumeration (the count grows ~46-fold per 2 links)"),
    "arm_joints": (100, "joints of an arm file (capability maps grow with the joints squared)"),
}

_overrides: dict[str, float] = {}


def _env_name(name: str) -> str:
    return f"MECHSYN_LIMIT_{name.upper()}"


def limit(name: str) -> float:
    """The current value of limit ``name`` (override, environment, then default)."""
    if name in _overrides:
        return _overrides[name]
    default = DEFAULTS[name][0]
    text = os.environ.get(_env_name(name))
    if text:
        try:
            value = float(text)
        except ValueError:
            raise MechsynInputError(f"expected a number, got {text!r}", source=_env_name(name)) from None
        return int(value) if isinstance(default, int) and value.is_integer() else value
    return default


def set_limit(name: str, value: float | None) -> None:
    """Set limit ``name`` for this process (``None``: back to the environment/default)."""
    if name not in DEFAULTS:
        raise KeyError(f"no limit {name!r}; one of {', '.join(DEFAULTS)}")
    if value is None:
        _overrides.pop(name, None)
    else:
        _overrides[name] = value


def limit_hint(name: str) -> str:
    """How to raise limit ``name``, for a message's fix."""
    return f"if this is meant, raise the limit: {_env_name(name)}=<value> (now {limit(name):,})"
