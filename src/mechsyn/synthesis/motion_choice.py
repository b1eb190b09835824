"""Choosing among Burmester four-bars: each linkage labelled by what a designer reads
(size against the poses, Grashof type, whether it reaches the poses on one branch and in
order, the crank's working range, the smallest transmission angle along the motion), the
unbuildable ones left out, the rest ranked; for three poses, the two-parameter family
offered by sampling its moving pivots, or built from the two the designer picks.

Motion generation through 3 poses leaves every body point a circle point (its three
positions lie on a circle about a centre point): the designer chooses two moving pivots.
Through 4 poses the circle points lie on the circle-point curve and their centres on the
centre-point curve (:func:`mechsyn.synthesis.exact.center_point_curve`); through 5, at
most four Burmester points. :func:`mechsyn.synthesis.exact.dyad_fourbar` assembles and
verifies every pair.

Examples
--------
>>> import numpy as np
>>> from mechsyn.synthesis.motion_choice import motion_choices
>>> poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, np.radians(20)], [2.0, 0.6, np.radians(45)]])
>>> cs = motion_choices(poses, top=3)
>>> len(cs) >= 2, all(c.buildable for c in cs)
(True, True)
>>> cs[0].label().count(";")
4
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.synthesis.exact import (MotionSynthesisResult, _poses, _rot, center_point, dyad_fourbar,
                                     motion_synthesis)
from mechsyn.synthesis.fourbar import crank_cos_range, fourbar_position

__all__ = ["MotionChoice", "motion_quality", "rank_motion", "motion_choices", "linkage_from_pivots",
           "MAX_SIZE_RATIO"]

#: A linkage more than this many times the poses' extent is "far outside the poses' size".
MAX_SIZE_RATIO = 10.0


@dataclass(frozen=True)
class MotionChoice:
    """A Burmester four-bar with what a designer reads of it (lengths in the poses' unit,
    angles in degrees)."""

    result: MotionSynthesisResult
    size: float               # extent of every joint over the motion
    size_ratio: float         # size / extent of the poses' origins
    one_branch_in_order: bool
    crank_range_deg: float    # the crank's working range on its branch (360: turns fully)
    travel_deg: float         # the crank's turn from the first pose to the last
    min_transmission_deg: float  # along that motion (not only at the poses)
    buildable: bool
    score: float

    @property
    def grashof(self) -> str:
        return self.result.grashof

    def label(self) -> str:
        """The designer's reading on one line."""
        reach = ("reaches the poses on one branch, in order" if self.one_branch_in_order
                 else "branch defect" if self.result.branch_defect else "order defect")
        crank = ("crank turns fully" if self.crank_range_deg >= 360 - 1e-9
                 else f"crank range {self.crank_range_deg:.0f}°")
        if self.one_branch_in_order:
            crank += f" (poses within {self.travel_deg:.0f}°)"
        return f"{self.grashof}; {self.size_ratio:.1f}× the poses; {reach}; {crank}; min μ {self.min_transmission_deg:.0f}°"

    def to_dict(self) -> dict[str, Any]:
        r = self.result
        return {"label": self.label(), "grashof": self.grashof, "size": self.size, "size_ratio": self.size_ratio,
                "one_branch_in_order": self.one_branch_in_order, "crank_range_deg": self.crank_range_deg,
                "travel_deg": self.travel_deg, "min_transmission_deg": self.min_transmission_deg,
                "buildable": self.buildable, "score": self.score, "position_error": r.position_error,
                "fixed_pivots": [r.O2.tolist(), r.O4.tolist()],
                "moving_pivots": [_at_pose(r.pA, 0, self._poses).tolist(), _at_pose(r.pB, 0, self._poses).tolist()]}

    _poses: np.ndarray = None  # type: ignore[assignment]
    _crank: np.ndarray = None  # type: ignore[assignment]

    def crank_angles(self) -> np.ndarray:
        """The crank angles (radians, from the ground line) of the motion from the first pose
        to the last (181 positions)."""
        return self._crank


def _at_pose(p: np.ndarray, j: int, P: np.ndarray) -> np.ndarray:
    """Body point ``p`` (the moving body's frame) at pose ``j``."""
    return _rot(P[j, 2]) @ np.asarray(p, float) + P[j, :2]


def _crank_range(r: MotionSynthesisResult) -> float:
    """The crank's working range on one branch (degrees): the arc of ``cos θ2`` within the
    assembly interval that holds the first pose."""
    c_lo, c_hi = (float(v) for v in crank_cos_range(r.r1, r.r2, r.r3, r.r4))
    if c_lo <= -1 and c_hi >= 1:
        return 360.0
    if c_hi >= 1:
        return math.degrees(2 * math.acos(max(-1.0, c_lo)))
    if c_lo <= -1:
        return math.degrees(2 * (math.pi - math.acos(min(1.0, c_hi))))
    return math.degrees(math.acos(max(-1.0, c_lo)) - math.acos(min(1.0, c_hi)))


def motion_quality(r: MotionSynthesisResult, poses: Any, max_size_ratio: float = MAX_SIZE_RATIO) -> MotionChoice:
    """What a designer reads of Burmester four-bar ``r`` guiding ``poses``: the crank is
    followed from the first pose to the last (the direction the order check found, else
    counter-clockwise) on the linkage's branch, 181 positions."""
    P = _poses(poses)
    direction = r.direction or 1
    steps = np.mod(direction * np.diff(r.theta2), 2 * np.pi)
    travel = float(steps.sum())
    th = r.theta2[0] + direction * np.linspace(0.0, travel, 181)
    pose = fourbar_position(r.r1, r.r2, r.r3, r.r4, th, branch=r.branch, x0=r.O2[0], y0=r.O2[1], theta0=r.theta0)
    mu = np.minimum(pose.mu, np.pi - pose.mu)
    min_mu = float(np.degrees(np.nanmin(mu))) if np.isfinite(mu).any() and pose.assembled.all() else 0.0
    pts = np.concatenate([np.stack([r.O2, r.O4]), np.asarray(pose.A).reshape(-1, 2), np.asarray(pose.B).reshape(-1, 2),
                          P[:, :2]])
    pts = pts[np.isfinite(pts).all(axis=1)]
    size = float(np.ptp(pts, axis=0).max())
    spread = float(np.ptp(P[:, :2], axis=0).max()) or 1.0
    in_order = not r.branch_defect and not r.order_defect
    rng = _crank_range(r)
    buildable = bool(r.ok and in_order and size / spread <= max_size_ratio)
    # ranked: a good transmission angle, a working range with room beyond the poses, a size
    # near the poses' (each term about 0..1)
    score = min(min_mu, 90.0) / 90.0 + 0.5 * min(rng / 360.0, 1.0) - 0.5 * math.log10(max(size / spread, 1.0))
    return MotionChoice(r, size, size / spread, in_order, rng, math.degrees(travel), min_mu, buildable, score, P, th)


def rank_motion(results: list[MotionSynthesisResult], poses: Any, *, keep_unbuildable: bool = False,
                max_size_ratio: float = MAX_SIZE_RATIO) -> list[MotionChoice]:
    """``results`` labelled (:func:`motion_quality`), the unbuildable ones (a branch or order
    defect, not verified, more than ``max_size_ratio`` times the poses) left out unless
    ``keep_unbuildable``, buildable first, then by score (best first)."""
    if not keep_unbuildable:  # (a defect or a failed verification is known before the quality)
        results = [r for r in results if r.ok]
    out = [motion_quality(r, poses, max_size_ratio) for r in results]
    if not keep_unbuildable:
        out = [c for c in out if c.buildable]
    out.sort(key=lambda c: (not c.buildable, -c.score))
    return out


def linkage_from_pivots(poses: Any, moving_a: Any, moving_b: Any) -> MotionSynthesisResult:
    """The four-bar guiding three poses whose moving pivots are at ``moving_a`` and
    ``moving_b`` at the first pose (drawing coordinates): each pivot's centre is the centre
    of the circle through its three positions (:func:`mechsyn.synthesis.exact.center_point`).
    A pivot whose three positions are collinear has no centre: the error says so."""
    P = _poses(poses)
    if len(P) != 3:
        raise MechsynInputError("moving pivots are chosen for 3 poses", field="poses")
    R0 = _rot(P[0, 2])
    pa, pb = (R0.T @ (np.asarray(m, float) - P[0, :2]) for m in (moving_a, moving_b))
    if np.linalg.norm(pa - pb) < 1e-9 * (float(np.ptp(P[:, :2], axis=0).max()) or 1.0):
        raise MechsynInputError("the two moving pivots coincide", field="pivots", hint="move one of them")
    return dyad_fourbar(P, center_point(P, pa), pa, center_point(P, pb), pb)


def _three_pose_family(P: np.ndarray, side: int) -> list[MotionSynthesisResult]:
    """Four-bars of 3 poses from moving pivots on a ``side`` × ``side`` grid of body points
    around the poses (the body frame of pose 1, ±1.5 the poses' extent), every pair."""
    spread = float(np.ptp(P[:, :2], axis=0).max()) or 1.0
    g = np.linspace(-1.5 * spread, 1.5 * spread, side)
    body = np.array([[x, y] for x in g for y in g])
    centres = []
    for p in body:
        try:
            centres.append(center_point(P, p))
        except MechsynInputError:  # three collinear positions: no centre
            centres.append(None)
    out = []
    for i in range(len(body)):
        for j in range(i + 1, len(body)):
            if centres[i] is not None and centres[j] is not None:
                out.append(dyad_fourbar(P, centres[i], body[i], centres[j], body[j]))
    return out


def motion_choices(poses: Any, *, top: int = 8, keep_unbuildable: bool = False, side: int = 6,
                   max_size_ratio: float = MAX_SIZE_RATIO, max_pairs: int = 1500) -> list[MotionChoice]:
    """Ranked, labelled four-bars guiding a body through 3, 4 or 5 poses (rows x, y, angle
    in radians): for 3 poses a sample of the two-parameter family (:func:`_three_pose_family`),
    for 4 ``max_pairs`` pairs of the centre-point curve's points, for 5 the Burmester points'
    (:func:`mechsyn.synthesis.exact.motion_synthesis`); the ``top`` best."""
    P = _poses(poses)
    results = _three_pose_family(P, side) if len(P) == 3 else motion_synthesis(P, max_pairs=max_pairs)
    ranked = rank_motion(results, P, keep_unbuildable=keep_unbuildable, max_size_ratio=max_size_ratio)
    return _distinct(ranked, P)[:top]


def _distinct(choices: list[MotionChoice], P: np.ndarray) -> list[MotionChoice]:
    """The choices without near-repeats (the same pair of pivots swapped, or pivots within
    2 % of the poses' extent of a better one's)."""
    tol = 0.02 * (float(np.ptp(P[:, :2], axis=0).max()) or 1.0)
    out: list[MotionChoice] = []
    for c in choices:
        piv = np.array([c.result.O2, c.result.O4])
        if not any(min(np.abs(piv - np.array([o.result.O2, o.result.O4])).max(),
                       np.abs(piv[::-1] - np.array([o.result.O2, o.result.O4])).max()) < tol for o in out):
            out.append(c)
    return out
