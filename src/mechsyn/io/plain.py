"""A plain mechanism file read without building pydantic's validators (a start-up path).

Building the validators of :mod:`mechsyn.io.schema` costs about as much as the rest of
reading and analysing a four-bar. Most files are *plain*: every value already has its
schema type exactly (text is ``str``, a number an ``int`` or ``float`` that is finite, a
flag a ``bool``, a list a ``list``), no field is unknown, no constraint is near. For those
:func:`plain_spec` builds the same models directly (``model_construct``), converting as
the validators do (numbers to ``float``, integer joint ids and contour entries to text).
Anything else -- a wrong type, an unknown field, a constraint broken, states or cam
profiles -- returns ``None``, and the file goes through pydantic's
validation, with its error messages: the fast path accepts a subset of what validation
accepts, never more, and builds equal models (tested on every example file).

Examples
--------
>>> spec = plain_spec({"name": "m", "ground": "frame", "links": ["frame", "crank"],
...                    "joints": [{"id": 1, "type": "R", "links": ["frame", "crank"], "point": [0, 0]}]})
>>> spec.joints[0].id, spec.joints[0].point, spec.kind
('1', [0.0, 0.0], 'planar')
>>> plain_spec({"name": "m", "ground": "frame", "links": ["frame"], "joints": [], "colour": "red"}) is None
True
"""

from __future__ import annotations

import math
from typing import Any

from mechsyn.io.schema import JointEntry, LinkEntry, LoadEntry, MechanismFile, PointEntry

__all__ = ["plain_spec"]


class _NotPlain(Exception):
    """The value needs pydantic's validation (coercion, an error message, or a rare field)."""



def _construct(cls: Any, **values: Any) -> Any:
    """``cls.model_construct(**values)`` with the fields in the model's order, as validation
    gives them (pydantic before 2.6 puts the given fields first, the defaults after)."""
    m = cls.model_construct(**values)
    d = m.__dict__
    ordered = {k: d[k] for k in cls.model_fields if k in d}
    if list(ordered) != list(d):
        object.__setattr__(m, "__dict__", {**ordered, **{k: v for k, v in d.items() if k not in ordered}})
    return m

def _text(v: Any) -> str:
    if type(v) is not str:
        raise _NotPlain
    return v


def _number(v: Any) -> float:
    if type(v) not in (int, float) or not abs(v) < 2.0 ** 53:  # exact as float; nan, inf refused
        raise _NotPlain
    return float(v)


def _numbers(v: Any) -> list[float]:
    if type(v) is not list:
        raise _NotPlain
    return [_number(x) for x in v]


def _whole(v: Any) -> int:
    if type(v) is not int:
        raise _NotPlain
    return v


def _ref(v: Any) -> str | int:
    if type(v) not in (str, int):
        raise _NotPlain
    return v


def _flag(v: Any) -> bool:
    if type(v) is not bool:
        raise _NotPlain
    return v


def _one_of(*values: str):
    def check(v: Any) -> str:
        if type(v) is not str or v not in values:
            raise _NotPlain
        return v
    return check


def _at_least(lower: float, strict: bool):
    def check(v: Any) -> float:
        x = _number(v)
        if x < lower or (strict and x == lower):
            raise _NotPlain
        return x
    return check


def _fields(data: Any, kinds: dict[str, Any], required: tuple[str, ...] = ()) -> dict[str, Any]:
    """``data``'s fields converted by ``kinds`` (``None`` kept as ``None``); unknown or
    missing required fields are not plain."""
    if type(data) is not dict or any(type(k) is not str or k not in kinds for k in data) \
            or any(k not in data for k in required):
        raise _NotPlain
    return {k: None if v is None and k not in required else kinds[k](v) for k, v in data.items()}


_LINK = {"name": _text, "id": _whole, "mass": _at_least(0, False), "com": _numbers,
         "inertia": _at_least(0, False), "description": _text}
_JOINT = {"id": lambda v: str(v) if type(v) is int else _text(v), "type": _text,
          "links": lambda v: [_ref(x) for x in _list(v)], "class": _whole, "point": _numbers,
          "axis": _numbers, "axis2": _numbers, "normal": _numbers, "pitch": _number, "ratio": _number,
          "actuated": _flag, "vll": _one_of("active", "passive", "locked"), "limits": _numbers,
          "anchor": _numbers, "radius": _at_least(0, True), "wrap": _one_of("ccw", "cw"),
          "description": _text}


def _list(v: Any) -> list:
    if type(v) is not list:
        raise _NotPlain
    return v


def _link(v: Any) -> str | LinkEntry:
    if type(v) is str:
        return v
    if type(v) is not dict or any(type(k) is not str for k in v):
        raise _NotPlain
    known = _fields({k: x for k, x in v.items() if k in _LINK}, _LINK)
    return _construct(LinkEntry, **known, **{k: x for k, x in v.items() if k not in _LINK})


def _joint(v: Any) -> JointEntry:
    fields = _fields(v, _JOINT, ("id", "type", "links"))
    if "actuated" in fields and fields["actuated"] is None:
        raise _NotPlain  # a bool field: null is an error
    if "class" in fields:
        fields["pair_class"] = fields.pop("class")
    return _construct(JointEntry, **fields)


def _contours(v: Any) -> list[list[str]]:
    return [[_text(str(x) if isinstance(x, int) else x) for x in _list(c)] for c in _list(v)]


_POINT = {"link": _ref, "at": _numbers}
_LOAD = {"link": _ref, "force": _numbers, "at": _numbers, "point": _text, "moment": _number,
         "description": _text}


def _points(v: Any) -> dict[str, PointEntry]:
    if type(v) is not dict:
        raise _NotPlain
    return {_text(k): _construct(PointEntry, **_fields(p, _POINT, ("link", "at"))) for k, p in v.items()}


def _loads(v: Any) -> list[LoadEntry]:
    return [_construct(LoadEntry, **_fields(x, _LOAD, ("link",))) for x in _list(v)]


_FILE = {"name": _text, "kind": _one_of("planar", "spatial"), "ground": _ref,
         "links": lambda v: [_link(x) for x in _list(v)], "joints": lambda v: [_joint(x) for x in _list(v)],
         "contours": _contours, "points": _points, "loads": _loads, "mobility": _whole, "description": _text, "source": _text, "units": _text}


def plain_spec(data: Any) -> MechanismFile | None:
    """The validated models of a plain file (see the module docstring), or ``None``."""
    try:
        fields = _fields(data, _FILE, ("name", "ground", "links", "joints"))
        if not fields["links"] or any(fields.get(k, "") is None for k in ("kind", "points", "loads")):
            raise _NotPlain
        return _construct(MechanismFile, **fields)
    except _NotPlain:
        return None
