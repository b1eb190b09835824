"""The working frame of curve synthesis: a similarity fixed by the curve itself
(centroid, RMS radius, principal axes, sense), so a similar target gives the same search."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechsyn.synthesis.curves.candidates import CurveCandidate
from mechsyn.synthesis.curves.descriptors import resample
from mechsyn.synthesis.curves.fitting import Bounds
from mechsyn.synthesis.curves.target import TargetCurve

__all__ = ["Frame"]


@dataclass(frozen=True)
class Frame:
    """The working frame, a similarity ``w = R((z - c) / r)`` of the target's plane: ``c``
    and ``r`` the centroid and RMS radius of the target (equally spaced in arc length),
    ``R`` the rotation to its principal axes (the long axis along x, its third moment
    positive) followed, when the curve then runs clockwise (closed by its chord if open;
    without enclosed area, when its y skew is negative), by the mirror in the x axis.
    Each part is computed from the curve itself, so a translated, scaled, rotated or
    mirrored target has the same working coordinates (rounded to ``1e-9``: the same
    numbers, not merely close ones) and the search the same course. A linkage mapped by a
    similarity traces the curve so mapped, on the same assembly branch; a mirrored one
    with its input reversed. With a ground region (an axis-parallel box) rotation and
    mirror are left out."""

    centre: complex
    scale: float
    turn: complex          # e^{i phi}: working x axis in target coordinates
    mirror: bool

    @classmethod
    def of(cls, target: TargetCurve, rotate: bool = True) -> Frame:
        w = resample(target.points, 256, closed=target.closed)
        c = complex(w.mean())
        r = float(np.sqrt(np.mean(np.abs(w - c) ** 2)))
        turn, mirror = 1.0 + 0j, False
        if rotate:
            u = (w - c) / r
            m2 = np.sum(u ** 2)
            turn = complex(np.exp(0.5j * np.angle(m2))) if abs(m2) > 1e-6 * len(u) else 1.0 + 0j
            if np.sum(((u / turn).real) ** 3) < 0:
                turn = -turn
            v = (resample(target.points, 256, closed=True) - c) / (r * turn)   # an open curve: closed by its chord
            area = 0.5 * np.sum(v.real * np.roll(v.imag, -1) - np.roll(v.real, -1) * v.imag)
            # clockwise: mirror; no area to speak of (a figure eight): the side the y skew points to
            mirror = bool(area < 0) if abs(area) > 1e-3 else bool(np.sum(v.imag ** 3) < 0)
        return cls(c, r, turn, mirror)

    def inward_points(self, P: np.ndarray) -> np.ndarray:
        w = (P[..., 0] + 1j * P[..., 1] - self.centre) / (self.scale * self.turn)
        w = np.conj(w) if self.mirror else w
        return np.round(np.stack([w.real, w.imag], axis=-1), 9)

    def outward_points(self, W: np.ndarray) -> np.ndarray:
        w = W[..., 0] + 1j * W[..., 1]
        z = self.centre + self.scale * self.turn * (np.conj(w) if self.mirror else w)
        return np.stack([z.real, z.imag], axis=-1)

    def inward(self, target: TargetCurve) -> TargetCurve:
        return TargetCurve(self.inward_points(target.points), target.closed, target.source)

    def bounds(self, user: TargetCurve, max_size, max_link_ratio, min_transmission, region) -> Bounds:
        """The design bounds in working coordinates: the size bound a disc about the
        target's centroid (the working origin), radius ``max_size`` target diagonals; both
        the centre and the diagonal (:attr:`TargetCurve.diagonal`, along the principal
        axes) are the curve's own, so a turned drawing has the turned bounds."""
        unit = user.diagonal / self.scale
        box = None
        if region is not None:
            lo, hi = self.inward_points(np.array(region[:2])), self.inward_points(np.array(region[2:]))
            box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
        return Bounds((0.0, 0.0), unit, None if max_size is None else max_size * unit,
                      max_link_ratio, float(min_transmission), box)

    def circumradius(self, user: TargetCurve) -> float:
        """The largest distance of a target point from its centroid, in target diagonals
        (the least size bound that holds the target itself)."""
        z = user.points[:, 0] + 1j * user.points[:, 1]
        return float(np.abs(z - self.centre).max() / user.diagonal)

    def outward(self, c: CurveCandidate) -> CurveCandidate:
        """The candidate in the target's coordinates (errors and ratios unchanged; a
        mirrored design runs its input the other way)."""
        import dataclasses

        x = self.outward_points(c.params.reshape(-1, 2)).reshape(-1)
        path = self.outward_points(c.path)
        start, stop = c.start, c.stop
        if self.mirror:
            start, stop = -stop, -start
            n = len(path)
            path = path[(-np.arange(n)) % n] if c.full_turn else path[::-1]
        ref = float(c.topology.plan.reference_inputs(x)[0])
        return dataclasses.replace(c, params=x, path=path, start=start, stop=stop, size=c.size * self.scale,
                                   reference_input=ref)
