"""Cams of planar kinematics: the curve a roller centre (or a knife edge) follows on
the cam, built from the joint's profile (see :mod:`mechsyn.kinematics.system`, where the
cam pair's constraint ``P_b - r_a - A_a O(t) = 0`` uses it).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError

__all__ = ["CamCurve", "cam_curve"]


@dataclass(frozen=True)
class CamCurve:
    """The curve the roller centre follows on the cam (profile offset by the roller radius).

    ``kind`` is ``"circle"`` (an eccentric disc: exact) or ``"spline"`` (a periodic cubic
    spline through the offset of the profile points), in the cam's local frame.
    """

    kind: str
    center: np.ndarray | None = None
    radius: float = 0.0
    spline: Any = None
    period: float = 2 * np.pi

    def eval(self, t: np.ndarray, der: int = 0) -> np.ndarray:
        if self.kind == "circle":
            ang = t + der * np.pi / 2
            out = self.radius * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
            return out + (self.center if der == 0 else 0.0)
        return self.spline(np.mod(t, self.period), der)

    def closest(self, p: np.ndarray) -> float:
        """Parameter of the curve point nearest ``p`` (local coordinates)."""
        if self.kind == "circle":
            d = p - self.center
            return float(np.arctan2(d[1], d[0]))
        ts = np.linspace(0, self.period, 4001)
        pts = self.eval(ts)
        return float(ts[np.argmin(np.sum((pts - p) ** 2, axis=1))])


def cam_curve(profile: Any, center_local: np.ndarray, rho: float, contact_local: np.ndarray,
               to_local: Any, source: str, jid: str) -> CamCurve:
    """Build the offset curve followed by the roller centre from the joint's profile."""
    from scipy.interpolate import make_interp_spline

    if isinstance(profile, dict) and "points" in profile:  # a polar function, sampled
        profile = profile["points"]
    if isinstance(profile, dict):
        c = to_local(np.asarray(profile["center"], float))
        r = float(profile["radius"])
        d = float(np.linalg.norm(center_local - c))
        # roller outside (r + rho) or inside (r - rho) the disc: whichever matches
        r_off = r + rho if abs(d - (r + rho)) <= abs(d - abs(r - rho)) else abs(r - rho)
        return CamCurve("circle", center=c, radius=r_off)
    pts = np.array([to_local(np.asarray(p, float)) for p in profile])
    if np.allclose(pts[0], pts[-1]):
        pts = pts[:-1]
    closed = np.vstack([pts, pts[:1]])
    t = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    if np.any(np.diff(t) <= 0):
        raise MechsynInputError(f"cam profile of joint {jid} repeats a point", source=source,
                                field=f"joints.{jid}.profile", hint="list distinct points round the cam")
    spl = make_interp_spline(t, closed, k=3, bc_type="periodic")
    if rho == 0:
        return CamCurve("spline", spline=spl, period=float(t[-1]))
    ts = np.linspace(0, t[-1], 16 * len(pts) + 400, endpoint=False)
    p, d1 = spl(ts), spl(ts, 1)
    nrm = np.stack([d1[:, 1], -d1[:, 0]], axis=1) / np.linalg.norm(d1, axis=1)[:, None]
    # offset to the side where the roller centre is
    k = int(np.argmin(np.sum((p - contact_local) ** 2, axis=1)))
    sign = 1.0 if float(nrm[k] @ (center_local - p[k])) >= 0 else -1.0
    off = p + sign * rho * nrm
    off_closed = np.vstack([off, off[:1]])
    to = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(off_closed, axis=0), axis=1))])
    spl2 = make_interp_spline(to, off_closed, k=3, bc_type="periodic")
    return CamCurve("spline", spline=spl2, period=float(to[-1]))
