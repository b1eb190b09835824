"""Geometry a mechanism file cannot mean: checked once, when the file is read.

A silent wrong answer is worse than an error, so :func:`check_geometry` refuses

* coordinates so large that squared distances overflow (beyond the limit ``coordinate``
  of :mod:`mechsyn.limits`, 1e100):
  every length, angle and Jacobian computed from them would be ``inf`` or ``nan``;
* a zero-length link: a moving link with two or more pivots (revolute, spherical,
  universal pairs), all at one point (a crank whose both pivots coincide "assembles"
  everywhere and never moves; all the joints of a file at one point make every link
  zero-length). Each pivot is a hinge of the link along its own arm (an R pair's axis,
  the U pair's arm fixed in that link): hinges at one point with crossed arms (a Hooke
  joint's cross, the shafts of a Hooke coupling written R + U at one point, a spherical
  linkage written at its centre) are allowed; slides, cylinders and contacts act along
  lines and are not pivots, and a link that has one is never refused for its pins
  (a slider block carrying two pins at one point);
* one pair written twice: two joints of one type between the same links at one point;
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
    out = np.zeros(3)  # zero-padded to 3D (np.pad cost 30 us a point, half the planar checks)
    out[:v.size] = v
    return out


#: Pairs that act about a point of the link (a pivot): two of them at one point leave a
#: link of zero length. A slide (P), a cylinder (C), a screw (H) or a contact pair acts
#: along a line or a surface: its ``point`` is any point of it, and may lie on a pivot.
PIVOT_PAIRS = ("R", "S", "U", "S_pin")


def _located(j: Any) -> bool:
    return j.point is not None and 1 <= np.size(j.point) <= 3


def check_geometry(mech: Any, source: str | None = None) -> Any:
    """Raise :class:`MechsynInputError` for geometry no mechanism can have; return ``mech``.

    Work grows linearly with the joints (a 2,000-link file is checked in milliseconds).
    """
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
    located = [j for j in mech.joints if _located(j)]
    if len(located) < 2:
        return mech
    P = np.array([_xyz(j.point) for j in located])
    scale = float(np.max(np.ptp(P, axis=0)))
    tol = COINCIDENT_REL * scale
    _check_duplicates(located, P, tol, source)
    bad = _zero_length_links(mech, located, P, tol)
    if bad:
        if scale == 0 and len(bad) == len(mech.link_names) - 1:
            what = "all joints are at one point, so every link has zero length"
        else:
            what = "; ".join(f"link {link!r} has zero length: its joints {', '.join(ids)} are at one point"
                             for link, ids in bad)
        raise MechsynInputError(
            what, source=source, field="joints",
            hint="give the joints of each link their own points in the assembled configuration")
    return mech


def _parallel(axes: list[Any]) -> bool:
    """Whether the given axes (``None``: the plane's normal) are all parallel."""
    A = np.array([[0.0, 0.0, 1.0] if a is None else _xyz(a) for a in axes])
    A /= np.maximum(np.linalg.norm(A, axis=1, keepdims=True), 1e-300)
    return bool(np.all(np.linalg.norm(np.cross(A, A[0]), axis=1) <= 1e-9))


def _arm(j: Any, link: str) -> Any:
    """The axis a pivot lets ``link`` turn about, as a hinge: an R pair's axis (``None``,
    the plane's normal, in a planar file), a U pair's arm fixed in that link (``axis`` in
    its first link, ``axis2`` in its second); ``False`` for a ball (S, S_pin), which
    lets the link turn about every axis through the point."""
    if j.type == "R":
        return j.axis
    if j.type == "U":
        return j.axis if link == j.links[0] else j.axis2
    return False


def _zero_length_links(mech: Any, located: list[Any], P: np.ndarray, tol: float) -> list[tuple[str, list[str]]]:
    """Moving links whose two or more pivots (:data:`PIVOT_PAIRS`) are all at one point.

    Each pivot is a hinge of the link along its arm (:func:`_arm`): hinges at one point
    with crossed arms are a Hooke joint's cross or a shaft of a Hooke coupling, not a
    zero-length link. A link that also has a slide, a cylinder, a screw or a contact is
    placed by it and never refused for its pins."""
    on: dict[str, list[int]] = {}
    placed: set[str] = set()
    for j in mech.joints:
        if j.type not in PIVOT_PAIRS:
            placed.update(j.links)
    for k, j in enumerate(located):
        if j.type in PIVOT_PAIRS:
            for link in dict.fromkeys(j.links):
                on.setdefault(link, []).append(k)
    bad = []
    for link in mech.link_names:
        rows = on.get(link, [])
        if link == mech.ground or link in placed or len(rows) < 2 or np.max(np.ptp(P[rows], axis=0)) > tol:
            continue
        pivots = [located[k] for k in rows]
        arms = [_arm(j, link) for j in pivots]
        if all(a is not False for a in arms) and not _parallel(arms):
            continue
        bad.append((link, [j.id for j in pivots]))
    return bad


def _check_duplicates(located: list[Any], P: np.ndarray, tol: float, source: str | None) -> None:
    """Two joints of one type between the same two links at one point: one pair written twice."""
    seen: dict[tuple, int] = {}
    for k, j in enumerate(located):
        key = (j.type, frozenset(j.links))
        if key in seen and np.max(np.abs(P[k] - P[seen[key]])) <= tol and (
                j.type != "R" or _parallel([j.axis, located[seen[key]].axis])):
            other = located[seen[key]].id
            raise MechsynInputError(
                f"joints {other} and {j.id} are the same {j.type} pair: both join links "
                f"{' and '.join(repr(x) for x in j.links)} at one point", source=source, field="joints",
                hint=f"delete one of them (a second bearing of one hinge goes at its own point on the axis)")
        seen.setdefault(key, k)


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


def flag(value: Any, source: str | None, field: str) -> bool:
    """``value`` as a yes/no setting: ``true`` or ``false`` only (the string ``"false"`` is
    not read as true, nor ``1`` as a flag).

    >>> flag("false", "case.yaml", "input.free")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: case.yaml: input.free: must be true or false, not str 'false' ...
    """
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise MechsynInputError(f"must be true or false, not {type(value).__name__} {value!r:.40}", source=source,
                            field=field, hint="write true or false without quotes")


def whole_number(value: Any, source: str | None, field: str, lowest: int = 1, highest: int = 10 ** 9) -> int:
    """``value`` as an integer in ``[lowest, highest]``: a whole number (``3`` or ``3.0``),
    not a boolean, a string or ``1e308`` (whose ``int`` has 309 digits).

    >>> whole_number(40.0, "case.yaml", "optimizer.maxiter")
    40
    >>> whole_number("40", "case.yaml", "optimizer.maxiter")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: case.yaml: optimizer.maxiter: expected a whole number, got '40' ...
    """
    ok = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))
    if not ok or not np.isfinite(value) or float(value) != int(value):
        raise MechsynInputError(f"expected a whole number, got {value!r:.40}", source=source, field=field,
                                hint=f"write a number from {lowest:,} to {highest:,} without quotes")
    if not lowest <= value <= highest:
        raise MechsynInputError(f"{value:g} is outside {lowest:,} ... {highest:,}", source=source, field=field,
                                hint=f"give a number from {lowest:,} to {highest:,}")
    return int(value)


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
