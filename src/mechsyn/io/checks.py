"""Geometry a mechanism file cannot mean: checked once, when the file is read.

A silent wrong answer is worse than an error, so :func:`check_geometry` refuses

* coordinates so large that squared distances overflow (beyond the limit ``coordinate``
  of :mod:`mechsyn.limits`, 1e100):
  every length, angle and Jacobian computed from them would be ``inf`` or ``nan``;
* a zero-length link: a moving link with two or more revolute joints, all at one point
  (a crank whose both pivots coincide "assembles" everywhere and never moves; all the
  joints of a file at one point make every link zero-length);
* a gear pair of ratio 0 (the second link could never turn).

Each error names the file, the joints or links and the fix.

Examples
--------
>>> from mechsyn.io import mechanism_from_dict
>>> data = {"name": "m", "ground": "frame", "links": ["frame", "crank", "coupler", "rocker"],
...         "joints": [{"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0]},
...                    {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": [0, 0]},
...                    {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": [4, 3]},
...                    {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": [5, 0]}]}
>>> mechanism_from_dict(data, "m.yaml")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mechsyn.errors.MechsynInputError: m.yaml: joints: link 'crank' has zero length: its joints A, B are at one point ...
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.limits import limit, limit_hint

__all__ = ["check_geometry", "check_counts", "COINCIDENT_REL", "numbers", "link_components"]

#: Joints closer than this times the file's extent are at one point.
COINCIDENT_REL = 1e-12


def _vectors(mech: Any) -> list[tuple[str, np.ndarray]]:
    out = []
    for j in mech.joints:
        for name in ("point", "axis", "normal"):
            v = getattr(j, name, None)
            if v is not None:
                out.append((f"joint {j.id} {name}", np.asarray(v, float)))
        for key, v in (j.attrs or {}).items():
            if key in ("anchor", "axis2") and v is not None:
                out.append((f"joint {j.id} {key}", np.asarray(v, float)))
    for name, p in mech.points.items():
        out.append((f"point {name}", np.asarray(p.at, float)))
    return out


def check_counts(data: Any, source: str | None = None) -> None:
    """Refuse file data with more links or joints than the limits, before validating it."""
    if not isinstance(data, dict):
        return
    for what in ("links", "joints"):
        items = data.get(what)
        if isinstance(items, list) and len(items) > limit(what):
            raise MechsynInputError(
                f"{len(items):,} {what} are more than the limit of {limit(what):,} (the analyses would run "
                "for hours or longer)", source=source, field=what, hint=limit_hint(what))


def _xyz(p: Any) -> np.ndarray:
    v = np.asarray(p, float).ravel()
    return np.pad(v, (0, 3 - v.size))


def check_geometry(mech: Any, source: str | None = None) -> Any:
    """Raise :class:`MechsynInputError` for geometry no mechanism can have; return ``mech``."""
    big = limit("coordinate")
    for what, v in _vectors(mech):
        if v.size and np.max(np.abs(v)) > big:
            raise MechsynInputError(
                f"{what} {v.tolist()} is beyond ±{big:g}: distances would overflow",
                source=source, field="joints" if what.startswith("joint") else "points",
                hint="give the coordinates in a unit that keeps them below 1e100 (e.g. km instead of mm)")
    for j in mech.joints:
        if j.type == "gear" and j.ratio is not None and j.ratio == 0:
            raise MechsynInputError(
                f"gear {j.id}: ratio 0 would hold link {j.links[1]!r} still", source=source,
                field="joints", hint="give the nonzero angular velocity ratio of the second link to the first")
    P = np.array([_xyz(j.point) for j in mech.joints if j.point is not None and 1 <= np.size(j.point) <= 3])
    if len(P) < 2:
        return mech
    scale = float(np.max(np.ptp(P, axis=0)))
    tol = COINCIDENT_REL * scale
    bad = []
    for link in mech.link_names:
        if link == mech.ground:
            continue
        revolute = [j for j in mech.joints if link in j.links and j.type == "R" and j.point is not None
                    and 1 <= np.size(j.point) <= 3]
        if len(revolute) < 2:
            continue
        pts = np.array([_xyz(j.point) for j in revolute])
        if np.max(np.ptp(pts, axis=0)) <= tol:
            bad.append((link, [j.id for j in revolute]))
    if bad:
        if scale == 0:
            what = "all joints are at one point, so every link has zero length"
        else:
            what = "; ".join(f"link {link!r} has zero length: its joints {', '.join(ids)} are at one point"
                             for link, ids in bad)
        raise MechsynInputError(
            what, source=source, field="joints",
            hint="give the joints of each link their own points in the assembled configuration")
    return mech


def has_bool(value: Any) -> bool:
    """Whether ``value`` (a number or nested lists of them) holds a boolean."""
    if isinstance(value, (bool, np.bool_)):
        return True
    if isinstance(value, (list, tuple)):
        return any(has_bool(v) for v in value)
    return False


def numbers(value: Any, source: str | None, field: str) -> np.ndarray:
    """``value`` as a float array: finite, within ±limit ``coordinate``, no booleans.

    Examples
    --------
    >>> numbers([1, 2.5], "case.json", "targets[0]").tolist()
    [1.0, 2.5]
    >>> numbers([True, False], "case.json", "point")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: case.json: point: true/false is not a number ...
    """
    if has_bool(value):
        raise MechsynInputError("true/false is not a number", source=source, field=field,
                                hint="write numbers, e.g. [1.0, 0.0]")
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise MechsynInputError("must be numbers", source=source, field=field) from None
    if not np.all(np.isfinite(a)):
        raise MechsynInputError("must be finite numbers", source=source, field=field)
    if a.size and np.max(np.abs(a)) > limit("coordinate"):
        raise MechsynInputError(f"values beyond ±{limit('coordinate'):g} would overflow", source=source,
                                field=field, hint="use a unit that keeps the values below 1e100")
    return a


def link_components(names: list[str], pairs: list[tuple[str, str]]) -> list[list[str]]:
    """The connected parts of the link graph (links joined by joints), smallest first.

    Each part is its links sorted by name; parts of one size come in the order of their
    first link in ``names`` (links named only by ``pairs`` count after ``names``). A
    union-find over the joints: linear, and reading a file needs no graph library.

    Examples
    --------
    >>> link_components(["frame", "crank", "stray", "rocker"], [("frame", "crank"), ("crank", "rocker")])
    [['stray'], ['crank', 'frame', 'rocker']]
    >>> link_components(["a", "b"], [("a", "b")])
    [['a', 'b']]
    """
    parent: dict[str, str] = {}

    def root(x: str) -> str:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for name in [*names, *(x for pair in pairs for x in pair)]:
        parent.setdefault(name, name)
    for a, b in pairs:
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[rb] = ra
    parts: dict[str, list[str]] = {}
    for name in parent:  # insertion order: names first
        parts.setdefault(root(name), []).append(name)
    return sorted((sorted(p) for p in parts.values()), key=len)
