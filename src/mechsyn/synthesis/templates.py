"""Mechanism dicts of one parsed structure: the fast path of a loop over designs that
produces a mechanism dict per design (:mod:`mechsyn.synthesis.finger`).

A design loop changes only numbers: joint points and P axes, named points (and the loads
applied at them), link masses, centres of mass and inertias. :class:`DictTemplate` parses one dict of the loop; a later
dict whose structure (everything but those numbers, :func:`structure_key`) is the same is
not parsed again: its numbers are filled into the parsed mechanism as the reader stores
them (floats, unit axes), the reader's geometry checks
(:func:`mechsyn.io.checks.check_geometry`) run on them, and its plan is the template's
compiled plan refilled (:meth:`mechsyn.kinematics.analysis.KinematicPlan.refilled`, see
docs/kinematics.md, "The fresh-geometry fast path"). Any number the reader would refuse
or read otherwise (not a finite float, a zero axis, a field given or left out where the
template has none) returns None: the caller parses that dict, so its message is the
reader's.

Examples
--------
>>> import mechsyn as ms
>>> from mechsyn.io import mechanism_to_dict
>>> d = mechanism_to_dict(ms.examples.load("crank_rocker"))
>>> tpl = DictTemplate(d, "<example>")
>>> d["joints"][2]["point"] = [3.1, 2.9]
>>> tpl.mechanism(d).joint(d["joints"][2]["id"]).point.tolist()
[3.1, 2.9]
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from typing import Any

import numpy as np

from mechsyn.io import mechanism_from_dict
from mechsyn.io.checks import check_geometry
from mechsyn.kinematics.analysis import KinematicPlan, compile_plan
from mechsyn.model.mechanism import Mechanism

__all__ = ["DictTemplate", "structure_key"]

_JOINT_NUMBERS = ("point", "axis")
_LINK_NUMBERS = ("mass", "com", "inertia")


def structure_key(d: dict) -> str | None:
    """The mechanism dict ``d`` without its joint points and axes, named points'
    coordinates and link masses, centres of mass and inertias, as text (None when ``d``
    is not a dict of that shape)."""
    try:
        bare = {**d,
                "joints": [{k: v for k, v in j.items() if k not in _JOINT_NUMBERS} for j in d["joints"]],
                "links": [e if isinstance(e, str) else {k: v for k, v in e.items() if k not in _LINK_NUMBERS}
                          for e in d["links"]],
                "points": {n: {k: v for k, v in p.items() if k != "at"} for n, p in (d.get("points") or {}).items()}}
        return json.dumps(bare, sort_keys=True, allow_nan=False)
    except (TypeError, ValueError, KeyError, AttributeError):
        return None


def _vector(v: Any, n: int) -> np.ndarray | None:
    """``n`` finite numbers (no booleans) as the reader stores them, else None."""
    if type(v) is not list or len(v) != n or not all(type(x) in (int, float) and math.isfinite(x) for x in v):
        return None
    return np.asarray(v, float)


def _scalar(v: Any) -> float | None:
    """A finite number at least 0 (a mass, an inertia), else None."""
    return float(v) if type(v) in (int, float) and math.isfinite(v) and v >= 0 else None


class DictTemplate:
    """A mechanism dict parsed once, and its compiled plan; :meth:`mechanism` and
    :meth:`plan` give those of another dict of the same :func:`structure_key`."""

    def __init__(self, d: dict, source: str) -> None:
        self.source = source
        self.key = structure_key(d)
        self.mech = mechanism_from_dict(d, source=source)
        self.compiled: KinematicPlan | None = None
        # contours and states are built from the joints they name: parsed anew
        self.usable = self.key is not None and not d.get("contours") and not d.get("states")
        self.usable = self.usable and self._same_numbers(d)

    def _same_numbers(self, d: dict) -> bool:
        """Whether the fill of the template's own dict gives the reader's numbers."""
        m = self.mechanism(d)
        if m is None:
            return False

        def eq(a: Any, b: Any) -> bool:
            return (a is None and b is None) or (a is not None and b is not None and np.array_equal(a, b))
        return all(eq(a.point, b.point) and eq(a.axis, b.axis) for a, b in zip(self.mech.joints, m.joints)) and \
            all(eq(p.at, m.points[n].at) for n, p in self.mech.points.items()) and \
            all(a.attrs == b.attrs for a, b in zip(self.mech.links, m.links)) and self.mech.attrs == m.attrs

    def mechanism(self, d: dict, key: str | None = None) -> Mechanism | None:
        """The mechanism of ``d`` (same structure; ``key``: its :func:`structure_key` when
        known) with its numbers, geometry-checked; None where ``d`` must be parsed (another
        structure, a number the reader refuses)."""
        if not self.usable or (structure_key(d) if key is None else key) != self.key:
            return None
        m, dim = self.mech, self.mech.dim
        joints = list(m.joints)
        for k, (e, j) in enumerate(zip(d["joints"], m.joints)):
            p = _vector(e.get("point"), dim) if "point" in e else None
            if (p is None) != (j.point is None) or ("axis" in e) != (j.axis is not None):
                return None
            axis = None
            if j.axis is not None:
                axis = _vector(e["axis"], dim)
                norm = 0.0 if axis is None else float(np.linalg.norm(axis))
                if not norm >= 1e-12:
                    return None
                axis = axis / norm
            joints[k] = replace(j, point=p, axis=axis)
        links = list(m.links)
        for k, (e, link) in enumerate(zip(d["links"], m.links)):
            if isinstance(e, dict):
                links[k] = _link(e, link)
                if links[k] is None:
                    return None
        points = dict(m.points)
        for n, q in (d.get("points") or {}).items():
            at = _vector(q.get("at"), dim)
            if at is None:
                return None
            points[n] = replace(m.points[n], at=at)
        attrs = m.attrs
        if attrs.get("loads"):  # a load at a named point is applied where the point is drawn
            attrs = {**attrs, "loads": [{**ld, "at": [float(x) for x in points[ld["point"]].at]} if "point" in ld
                                        else ld for ld in attrs["loads"]]}
        return check_geometry(replace(m, joints=tuple(joints), links=tuple(links), points=points, attrs=attrs),
                              self.source)

    def plan(self, mech: Mechanism) -> KinematicPlan:
        """The compiled plan of ``mech`` (from :meth:`mechanism`): the template's refilled."""
        if self.compiled is None:
            self.compiled = compile_plan(self.mech)
        return self.compiled.refilled(mech)


def _link(e: dict, link: Any) -> Any:
    """``link`` with the mass, centre of mass and inertia of its entry ``e``, as the
    reader stores them; None where the reader would refuse one."""
    attrs = {k: v for k, v in link.attrs.items() if k not in _LINK_NUMBERS}
    for k in _LINK_NUMBERS:
        v = e.get(k)
        if v is None:
            continue
        if k == "com":
            if type(v) is not list or not all(type(x) in (int, float) and math.isfinite(x) for x in v):
                return None
            attrs[k] = [float(x) for x in v]
        else:
            attrs[k] = _scalar(v)
            if attrs[k] is None:
                return None
    return replace(link, attrs=attrs)
