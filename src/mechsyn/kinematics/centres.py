"""Instant centres of velocity of every pair of links of a planar mechanism at one pose.

The instant centre ``P_ab`` of links ``a`` and ``b`` is the point that has the same velocity
on both (Kennedy's theorem: the three centres of any three links lie on one line). Here it
is computed from the velocity analysis of the same engines (one row of
:func:`mechsyn.kinematics.analysis.simulate`, the drives turning at 1 rad/s or moving at 1
length unit/s): with ``v_a(Q)`` the velocity of a point ``Q`` of link ``a`` and ``ω_a`` its
angular velocity, ``v_a(P) = v_a(Q_a) + ω_a k × (P - Q_a)``; equating the two links gives
``(ω_a - ω_b) k × P = v_b(Q_b) - v_a(Q_a) + ω_a k × Q_a - ω_b k × Q_b``. Where
``ω_a = ω_b`` the relative motion is a translation and the centre lies at infinity,
perpendicular to it (a P pair's centre). Each centre gives the velocity ratio
``ω_b / ω_a``; a pair joined by an R joint has that joint as its (primary) centre.

Examples
--------
>>> import mechsyn as ms
>>> from mechsyn.kinematics.centres import instant_centres
>>> cs = instant_centres(ms.examples.load("crank_rocker"))
>>> len(cs), [c.links for c in cs if c.joint == "B"]
(6, [('crank', 'coupler')])
>>> c13 = next(c for c in cs if c.links == ("frame", "coupler"))
>>> c13.kind, c13.point is not None
('Kennedy', True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import drawn_inputs, simulate
from mechsyn.kinematics.plane import perp  # k × v: v turned by +90 degrees
from mechsyn.model.mechanism import Mechanism

__all__ = ["InstantCentre", "instant_centres"]


@dataclass(frozen=True)
class InstantCentre:
    """The instant centre of links ``links`` (file order): ``point`` (None at infinity, then
    ``direction`` is the direction in which it lies), ``joint`` the R joint that is it (a
    primary centre), ``ratio`` = ω_b / ω_a (absolute angular velocities; None where ω_a = 0)."""

    links: tuple[str, str]
    point: np.ndarray | None
    direction: np.ndarray | None
    joint: str | None
    ratio: float | None

    @property
    def kind(self) -> str:
        if self.joint:
            return "primary"
        if self.point is None:
            return "at infinity" if self.direction is not None else "indeterminate (no relative motion)"
        return "Kennedy"

    def to_dict(self) -> dict[str, Any]:
        return {"links": list(self.links), "point": None if self.point is None else self.point.tolist(),
                "direction": None if self.direction is None else self.direction.tolist(), "joint": self.joint,
                "ratio": self.ratio, "kind": self.kind}


def _rates(mech: Mechanism, inputs: dict[str, float] | None) -> tuple[dict, dict, float]:
    """``ω`` and a reference point with its velocity of every link (the frame: 0), by one
    simulated row at ``inputs`` (the drawn pose when None), and the mechanism's length
    scale (its system's)."""

    u = drawn_inputs(mech)
    if not u:
        raise MechsynInputError("instant centres need a drive to give the velocities", field="joints",
                                hint="mark the input joint with Drive")
    u.update(inputs or {})
    rs = [j.id for j in mech.joints if j.type == "R" and j.point is not None]
    sim = simulate(mech, {k: [float(v)] for k, v in u.items()}, points=rs)
    if not bool(sim.assembled[0]):
        raise MechsynInputError("not assembled at this input: no velocities", field="inputs")
    omega = {mech.ground: 0.0}
    ref: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for name in mech.moving_links:
        omega[name] = float(sim.links[name].angular_velocity[0]) if name in sim.links else math.nan
    for j in mech.joints:
        if j.id in rs and j.id in sim.points:
            pm = sim.points[j.id]
            for link in j.links:
                ref.setdefault(link, (np.asarray(pm.position[0], float), np.asarray(pm.velocity[0], float)))
    return omega, ref, sim.system.scale


def instant_centres(mech: Mechanism, inputs: dict[str, float] | None = None) -> list[InstantCentre]:
    """Every pair of links' instant centre at the pose of ``inputs`` (drive values in the
    engine's convention, degrees for an R drive; the drawn pose when None), links in file
    order. A link without an R joint (its velocity field unknown here) has no centre listed."""
    if mech.kind != "planar":
        raise MechsynInputError("instant centres are for planar mechanisms", field="kind")
    omega, ref, scale = _rates(mech, inputs)
    rjoint = {}
    for j in mech.joints:
        if j.type == "R":
            rjoint.setdefault(tuple(sorted(j.links)), j.id)
    out = []
    names = [n for n in mech.link_names if n in ref or n == mech.ground]
    for a, b in combinations(names, 2):
        wa, wb = omega[a], omega[b]
        qa, va = ref.get(a, (np.zeros(2), np.zeros(2)))
        qb, vb = ref.get(b, (np.zeros(2), np.zeros(2)))
        if not (math.isfinite(wa) and math.isfinite(wb)):
            continue
        c = vb - va + wa * perp(qa) - wb * perp(qb)
        dw = wa - wb
        ratio = wb / wa if abs(wa) > 1e-12 * (abs(wa) + abs(wb) + 1e-300) and wa != 0 else None
        speed = float(np.linalg.norm(c)) + (abs(wa) + abs(wb)) * scale
        joint = rjoint.get(tuple(sorted((a, b))))
        if abs(dw) * scale <= 1e-9 * speed:  # a relative translation: the centre at infinity
            # (no relative motion at all, a dead centre of the pair: no direction either;
            # speeds are those of the drives at 1 rad/s, 1 unit/s: ``scale`` is their size)
            t = c / np.linalg.norm(c) if np.linalg.norm(c) > 1e-9 * scale else None
            out.append(InstantCentre((a, b), None, None if t is None else perp(t), joint, ratio))
        else:
            out.append(InstantCentre((a, b), np.array([c[1], -c[0]]) / dw, None, joint, ratio))  # k × P = c / dw
    return out
