"""Velocity capability at one point: what ``mechsyn capability ARM --point`` reports.

:func:`capability_at` samples the arm's self-motion at the point (paper 004's q1 sweep),
evaluates every measure of :mod:`mechsyn.capability.measures` in each allowed
configuration, names why the others are rejected, and refines the best configuration by
a continuous search over the self-motion.

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn._result import Result
from mechsyn.capability.arm import SerialArm
from mechsyn.capability.maps import continuous_best, is_closed_form, refine_over_self_motion, self_motion
from mechsyn.capability.measures import MEASURES, all_measures, velocity_ellipse, velocity_polytope
from mechsyn.errors import MechsynInputError

__all__ = ["MEASURE_HELP", "PointCapability", "capability_at"]

#: What each measure is (shown by the CLI, included in the JSON).
MEASURE_HELP = {
    "exact": "largest speed of pure motion along d (joint rates free within their limits)",
    "component": "largest velocity component along d, perpendicular part free",
    "min_norm": "limit of the minimum-norm joint rates J+ v (paper 004's Q_dot_N)",
    "stepped_min_norm": "paper 004's 5-step raise with minimum-norm rates",
    "stepped": "paper 004's 5-step raise with the null space used to full effect",
}
_UNITS = ("speeds in the arm's length unit per second (mm/s for mm); q_deg in degrees (R joints) or "
          "lengths (P joints)")


def measures_at(arm: SerialArm, q: np.ndarray, d: np.ndarray, step: float) -> dict:
    """Every measure at configurations ``q`` (K, n) along unit direction ``d``."""
    return all_measures(arm.jacobian(q), arm.qd_max, d, arm.weights, step)


def rejection_reason(arm: SerialArm, q: np.ndarray) -> str:
    """Why configuration ``q`` is not allowed: out of reach, or the joint beyond its limit."""
    if not np.all(np.isfinite(q)):
        return "point out of reach"
    qu = arm.to_user(q)
    lo, hi = arm.to_user(arm.lower), arm.to_user(arm.upper)
    for i, name in enumerate(arm.joint_names):
        if qu[i] < lo[i] - 1e-7:
            return f"{name} = {qu[i]:.2f} below its lower limit {lo[i]:g}"
        if qu[i] > hi[i] + 1e-7:
            return f"{name} = {qu[i]:.2f} above its upper limit {hi[i]:g}"
    return "outside the joint limits"


def config_entry(arm: SerialArm, q: np.ndarray, meas: dict, k: int) -> dict:
    """``{"q_deg": ..., measure: value, ...}`` of the ``k``-th configuration."""
    entry = {"q_deg": np.round(arm.to_user(q), 10)}
    entry.update({m: float(meas[m][k]) for m in MEASURES})
    return entry


@dataclass(repr=False)
class PointCapability(Result):
    """The capability of ``arm`` at ``point`` along ``direction``; ``to_dict()`` is
    ``mechsyn capability ARM --point ... --json``.

    ``configurations`` are the allowed configurations of the sampled self-motion, each with
    every measure; ``best`` the one with the largest ``measure``; ``continuous_best`` the
    result of the continuous search (None when no allowed configuration reaches).

    Examples
    --------
    >>> import mechsyn as ms
    >>> r = ms.capability_at(ms.examples.load("paper004_3r"), [1000, 1000], [0, 1])
    >>> r.best == r.configurations[r.best_index]
    True
    """

    arm: str
    point: np.ndarray
    direction: np.ndarray
    measure: str
    configurations: list = field(default_factory=list)
    rejected: list = field(default_factory=list)
    best: dict | None = None
    continuous_best: dict | None = None
    polytope: dict | None = None
    ellipse: dict | None = None

    @property
    def best_index(self) -> int:
        """Index of ``best`` in ``configurations`` (-1 when there is none)."""
        if not self.configurations:
            return -1
        return int(np.argmax([c[self.measure] for c in self.configurations]))

    def _summary(self) -> list[tuple[str, str]]:
        rows = [("arm", self.arm), ("point", str(np.round(self.point, 6).tolist())),
                ("direction", str(np.round(self.direction, 4).tolist())), ("measure", self.measure),
                ("configurations", f"{len(self.configurations)} allowed, {len(self.rejected)} rejected")]
        if self.best is not None:
            rows.append(("best", f"{self.best[self.measure]:.6g}"))
        if self.continuous_best is not None:
            rows.append(("continuous best", f"{self.continuous_best[self.measure]:.6g}"))
        return rows

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "arm": self.arm, "point": self.point, "direction": self.direction, "measure": self.measure,
            "units": _UNITS, "measures": MEASURE_HELP, "configurations": self.configurations,
            "rejected": self.rejected, "best": self.best,
        }
        if self.polytope is not None:
            out["best_velocity_polytope"] = self.polytope
            out["best_velocity_ellipse"] = self.ellipse
        out["continuous_best"] = self.continuous_best
        return out


def capability_at(arm: SerialArm, point: Any, direction: Any, *, measure: str = "exact",
                  q1: np.ndarray | None = None, branch: str = "negative", respect_limits: bool = True,
                  step: float = 5.0, polytope: bool = False) -> PointCapability:
    """Largest tool speed along ``direction`` at ``point`` over the arm's self-motion.

    Parameters
    ----------
    arm : SerialArm
        From :func:`mechsyn.load_arm`.
    point, direction : array_like
        The tool point (task coordinates) and the direction of motion (any length).
    measure : str
        Which measure picks the best configuration: ``exact``, ``component``, ``min_norm``,
        ``stepped_min_norm`` or ``stepped`` (see :data:`MEASURE_HELP`).
    q1 : ndarray, optional
        Samples of the self-motion parameter (radians); default 20 deg steps over q1's
        limits (paper 004's choice).
    branch : str
        Elbow branch of the closed-form inverse kinematics: ``negative``, ``positive`` or
        ``both``.
    respect_limits : bool
        Reject configurations outside the joint limits (they are listed with the reason).
    step : float
        Speed step of the paper's stepping method.
    polytope : bool
        Add the best configuration's velocity polytope and ellipse.

    Returns
    -------
    PointCapability

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.capability.point import capability_at
    >>> arm = ms.examples.load("paper004_3r")
    >>> r = capability_at(arm, [1000, 1000], [1, 0])
    >>> len(r.configurations) > 0, r.best["exact"] >= r.best["min_norm"]
    (True, True)
    """
    point = np.asarray(point, float)
    d = np.asarray(direction, float)
    if measure not in MEASURES:
        raise MechsynInputError(f"unknown measure {measure!r}", field="measure", hint="one of " + ", ".join(MEASURES))
    if not np.all(np.isfinite(point)):
        raise MechsynInputError("values must be finite", field="point", hint="give finite coordinates, e.g. [1300, 900]")
    if not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0:
        raise MechsynInputError("the direction must be a finite, non-zero vector", field="direction",
                                hint="e.g. [1, 0] for +x")
    dn = d / np.linalg.norm(d)
    q, valid = self_motion(arm, point, q1, branch, respect_limits=respect_limits)
    qv = q[valid]
    meas = measures_at(arm, qv, dn, step) if len(qv) else {k: np.zeros(0) for k in MEASURES}
    configs = [config_entry(arm, qv[k], meas, k) for k in range(len(qv))]
    # without limits self_motion marks only reachability; list the rejected ones with why
    rejected = [{"q_deg": np.round(arm.to_user(qq), 10), "reason": rejection_reason(arm, qq)}
                for qq in q[~valid]] if is_closed_form(arm) else []
    res = PointCapability(arm.name, point, dn, measure, configs, rejected)
    if configs:
        k = int(np.argmax(meas[measure]))
        res.best = dict(configs[k])
        if polytope:
            J = arm.jacobian(qv[k])[0]
            poly, ell = velocity_polytope(J, arm.qd_max), velocity_ellipse(J, arm.qd_max)
            res.polytope = {"vertices": poly.vertices, "facet_normals": poly.normals,
                            "facet_offsets": poly.offsets, "equalities": poly.equalities,
                            "limit_along_d": poly.directional_limit(dn)}
            res.ellipse = {"semi_axes": ell.semi_axes, "axes": ell.axes.T, "radius_along_d": ell.radius(dn)}
    if is_closed_form(arm):
        qc, vc = continuous_best(arm, point[None], dn, measure, branch, respect_limits)
    elif configs:
        top = np.argsort(-meas[measure], kind="stable")[:8]
        qc, vc = refine_over_self_motion(arm, point, qv[top], dn, measure, respect_limits)
        k = int(np.argmax(vc))
        qc, vc = qc[k:k + 1], vc[k:k + 1]
    else:
        qc, vc = None, np.array([-np.inf])
    if np.isfinite(vc[0]):
        res.continuous_best = config_entry(arm, qc[0], measures_at(arm, qc, dn, step), 0)
    return res
