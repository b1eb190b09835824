"""Closed-form kinematics of paper 001's manipulator with a flexible element.

Paper 001 [1]_ (Bulgarian; spec ``flexible-manipulator.md``): lever 1 pivots
on the frame at A0; link 2 (the "hand", carrying the gripper point H) pivots on lever 1
at A and carries a pulley of radius r centred on A; a belt (toothed belt, chain, band or
rope) is pinned to the frame at B0 and wraps the pulley counter-clockwise.

Frame: origin at A0, y along the axis of the technological machine. In the design
position lever 1 lies on +y, A = (0, a), the belt runs straight up from
B0 = (r, a - b0) to the tangent point B = (r, a), C = (-c, a) and H = (-c, a + h).

Angles: Δφ is the rotation of lever 1 from the design position (counter-clockwise
positive), Δψ the rotation of link 2 relative to lever 1, θ = Δφ + Δψ the absolute angle
of link 2. Derivatives ``1`` and ``2`` are first and second derivatives with respect to
Δφ in radians.

The equations are the spec's corrected set (the paper's printed (4), (9), (13), (14) and
(19) carry sign slips or are wrong; see the function docstrings). Every function takes
NumPy arrays of Δφ and is vectorised; no loops over positions.

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012); authors, journal and year are not in the project's copy ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline
from scipy.spatial import ConvexHull

from mechsyn.errors import MechsynInputError

Array = NDArray[np.float64]

__all__ = [
    "BeltDesign",
    "BeltState",
    "FourBarState",
    "MotionLaw",
    "ConstantSpeedLaw",
    "TrapezoidalLaw",
    "TableLaw",
    "PointMotion",
    "MotionResult",
    "InverseResult",
    "PathQuality",
    "design_constants",
    "analyze",
    "point_motion",
    "motion",
    "inverse_input",
    "tangent_deviation",
    "best_line_deviation",
    "translation_range",
    "path_quality",
    "equivalent_four_bar",
    "compare_with_four_bar",
    "four_bar_mechanism_dict",
    "belt_mechanism_dict",
    "BeltCase",
    "load_belt_case",
]


# ----------------------------------------------------------------------------- design
def design_constants(a: float, c: float, r: float) -> tuple[float, float, float]:
    """Initial free belt length b0, frame length l0 and frame angle α0 (radians).

    Paper 001, equations (1)-(3)::

        b0 = a c / (c + r)          (1)  (exactly the condition y''_C(0) = 0)
        l0 = sqrt((a - b0)^2 + r^2) (2)
        α0 = arccos(r / l0)         (3)
    """
    b0 = a * c / (c + r)
    l0 = math.hypot(a - b0, r)
    alpha0 = math.acos(r / l0)
    return b0, l0, alpha0


@dataclass(frozen=True)
class BeltDesign:
    """Dimensions of the manipulator: lever a = |A0 A|, hand offsets c, h, pulley radius r.

    C = A + (-c, 0) and H = C + (0, h) in the design position (paper 001, fig. 1).

    Examples
    --------
    >>> import mechsyn as ms
    >>> d = ms.BeltDesign(a=500, c=350, h=100, r=75)      # paper 001's example
    >>> round(d.b0, 3), round(d.l0, 3)                    # the paper's values
    (411.765, 115.804)
    """

    a: float
    c: float
    h: float
    r: float

    def __post_init__(self) -> None:
        for name in ("a", "c", "h", "r"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise MechsynInputError(f"{name} must be a finite number, got {value!r}",
                                        field=name)
        if self.a <= 0:
            raise MechsynInputError(f"lever length a must be positive, got {self.a:g}",
                                    field="a", hint="A must lie on +y above A0")
        if self.r <= 0:
            raise MechsynInputError(f"pulley radius r must be positive, got {self.r:g}",
                                    field="r")
        if self.c <= 0:
            raise MechsynInputError(
                f"c must be positive (C to the left of A), got {self.c:g}", field="c",
                hint="with c <= 0 the free belt length b0 = a c/(c + r) is not positive",
            )

    @property
    def b0(self) -> float:
        return design_constants(self.a, self.c, self.r)[0]

    @property
    def l0(self) -> float:
        return design_constants(self.a, self.c, self.r)[1]

    @property
    def alpha0(self) -> float:
        """Angle of the frame line A0 B0 to x, radians."""
        return design_constants(self.a, self.c, self.r)[2]

    @property
    def B0(self) -> Array:
        """Belt anchor on the frame: l0 (cos α0, sin α0) = (r, a - b0)."""
        return np.array([self.r, self.a - self.b0])

    def to_dict(self) -> dict[str, float]:
        return {"a": self.a, "c": self.c, "h": self.h, "r": self.r,
                "b0": self.b0, "l0": self.l0, "alpha0_deg": math.degrees(self.alpha0)}


# --------------------------------------------------------------------------- analysis
@dataclass
class BeltState:
    """Positions and derivatives over an array of Δφ (radians); points are (n, 2) arrays.

    ``valid`` is False where the belt cannot stay taut and straight (d <= r); the values
    there are NaN.
    """

    design: BeltDesign
    dphi: Array
    d: Array
    b: Array
    beta: Array
    beta1: Array
    dpsi: Array
    psi1: Array
    psi2: Array
    yG: Array
    theta: Array
    A: Array
    B: Array
    C: Array
    C1: Array
    C2: Array
    H: Array
    H1: Array
    H2: Array
    valid: NDArray[np.bool_]

    def rows(self) -> list[dict[str, object]]:
        """One JSON-ready record per position (keys of the ``belt analyze`` contract)."""
        deg = np.degrees
        out = []
        for i in range(self.dphi.size):
            out.append({
                "dphi_deg": float(deg(self.dphi[i])),
                "dpsi_deg": float(deg(self.dpsi[i])),
                "beta_deg": float(deg(self.beta[i])),
                "theta_deg": float(deg(self.theta[i])),
                "b": float(self.b[i]),
                "d": float(self.d[i]),
                "psi1": float(self.psi1[i]),
                "psi2": float(self.psi2[i]),
                "C": self.C[i].tolist(), "H": self.H[i].tolist(),
                "C1": self.C1[i].tolist(), "C2": self.C2[i].tolist(),
                "H1": self.H1[i].tolist(), "H2": self.H2[i].tolist(),
                "valid": bool(self.valid[i]),
            })
        return out


def _rot(angle: Array, p: Array) -> Array:
    """Rotate (n, 2) points ``p`` by ``angle`` (n,) about the origin."""
    cs, sn = np.cos(angle), np.sin(angle)
    return np.stack([cs * p[:, 0] - sn * p[:, 1], sn * p[:, 0] + cs * p[:, 1]], axis=-1)


def analyze(design: BeltDesign, dphi: ArrayLike) -> BeltState:
    """Position function, transfer functions and paths of C and H over ``dphi`` (rad).

    Paper 001, corrected per the spec::

        (6)  d^2 = l0^2 + a^2 - 2 a l0 sin(α0 - Δφ)
        (5)  b = sqrt(d^2 - r^2)
        (7)  β = arctan(b/r) + arcsin(l0 cos(α0 - Δφ)/d)
        (4)  Δψ = (β - β0) - (b - b0)/r                 (β0 = 90°)
        (8)  x_B0 = l0 cos(α0 - Δφ), y_B0 = l0 sin(α0 - Δφ), y_G = y_B0 + x_B0 cot β
        (11) β' = -y_G / (y_G - a)      (derivative w.r.t. Δφ; the paper's (11) is w.r.t.
                                          the control mechanism's input -Δφ)
        (9)  ψ' = (a/r) cos β - 1       (the paper prints 1 - (a/r) cos β: that is the
                                          derivative w.r.t. -Δφ; it gives 1 + ψ' = 2, not 0,
                                          at the design position)
        (10) ψ'' = -(a/r) β' sin β
        (12)-(17) C, H and their derivatives with θ = Δφ + Δψ (signs as in the spec).

    (7) is evaluated in the equivalent, branch-safe form β = atan2(a - y_B0, -x_B0)
    - arctan(r/b) (the direction of B0→A less the tangent offset); both agree wherever
    y_B0 < a, which holds for every practical design.
    """
    des = design
    dphi = np.atleast_1d(np.asarray(dphi, dtype=float))
    a, c, h, r = des.a, des.c, des.h, des.r
    b0, l0, alpha0 = design_constants(a, c, r)

    xB0 = l0 * np.cos(alpha0 - dphi)          # B0 seen from lever 1 (kinematic inversion)
    yB0 = l0 * np.sin(alpha0 - dphi)
    d2 = l0**2 + a**2 - 2.0 * a * l0 * np.sin(alpha0 - dphi)
    d = np.sqrt(d2)
    valid = d > r * (1.0 + 1e-12)
    with np.errstate(invalid="ignore", divide="ignore"):
        b = np.where(valid, np.sqrt(np.where(valid, d2 - r**2, np.nan)), np.nan)
        beta = np.arctan2(a - yB0, -xB0) - np.arctan2(r, b)
        dpsi = (beta - np.pi / 2) - (b - b0) / r
        yG = yB0 + xB0 * np.cos(beta) / np.sin(beta)
        beta1 = -yG / (yG - a)
        psi1 = (a / r) * np.cos(beta) - 1.0
        psi2 = -(a / r) * beta1 * np.sin(beta)

    theta = dphi + dpsi
    s, co = np.sin(dphi), np.cos(dphi)
    st, ct = np.sin(theta), np.cos(theta)
    w = 1.0 + psi1

    xC = -a * s - c * ct
    yC = a * co - c * st
    xC1 = -a * co + c * w * st
    yC1 = -a * s - c * w * ct
    xC2 = a * s + c * (w**2 * ct + psi2 * st)
    yC2 = -a * co + c * (w**2 * st - psi2 * ct)
    xH = xC - h * st
    yH = yC + h * ct
    xH1 = xC1 - h * w * ct
    yH1 = yC1 - h * w * st
    xH2 = xC2 + h * (w**2 * st - psi2 * ct)
    yH2 = yC2 - h * (w**2 * ct + psi2 * st)

    A = np.stack([-a * s, a * co], axis=-1)
    B_lever = np.stack([r * np.sin(beta), a - r * np.cos(beta)], axis=-1)  # tangent point
    B = _rot(dphi, B_lever)
    pair = lambda x, y: np.stack([x, y], axis=-1)  # noqa: E731
    return BeltState(
        design=des, dphi=dphi, d=d, b=b, beta=beta, beta1=beta1, dpsi=dpsi, psi1=psi1,
        psi2=psi2, yG=yG, theta=theta, A=A, B=B,
        C=pair(xC, yC), C1=pair(xC1, yC1), C2=pair(xC2, yC2),
        H=pair(xH, yH), H1=pair(xH1, yH1), H2=pair(xH2, yH2), valid=valid,
    )


# ------------------------------------------------------------------------ input laws
@dataclass(frozen=True)
class MotionLaw:
    """Input law φ(t) of lever 1 (Δφ in radians, t in seconds)."""

    def duration(self) -> float:  # pragma: no cover - abstract
        raise NotImplementedError

    def evaluate(self, t: ArrayLike) -> tuple[Array, Array, Array]:  # pragma: no cover
        """Return Δφ(t), φ_dot(t), φ_ddot(t)."""
        raise NotImplementedError


@dataclass(frozen=True)
class ConstantSpeedLaw(MotionLaw):
    """Δφ = start + ω t from ``start`` to ``stop`` (ω > 0; direction from the signs)."""

    start: float
    stop: float
    omega: float

    def __post_init__(self) -> None:
        if not self.omega > 0:
            raise MechsynInputError(f"input speed must be positive, got {self.omega!r}",
                                    field="omega")
        if self.start == self.stop:
            raise MechsynInputError("the motion's start and stop coincide", field="range")

    def duration(self) -> float:
        return abs(self.stop - self.start) / self.omega

    def evaluate(self, t: ArrayLike) -> tuple[Array, Array, Array]:
        t = np.asarray(t, dtype=float)
        sign = math.copysign(1.0, self.stop - self.start)
        return (self.start + sign * self.omega * t, np.full_like(t, sign * self.omega),
                np.zeros_like(t))


@dataclass(frozen=True)
class TrapezoidalLaw(MotionLaw):
    """Trapezoidal speed profile from ``start`` to ``stop``: accelerate at ``accel`` up to
    ``omega_max``, cruise, decelerate at ``accel`` to rest (triangular when the stroke is
    too short to reach ``omega_max``)."""

    start: float
    stop: float
    omega_max: float
    accel: float

    def __post_init__(self) -> None:
        if not (self.omega_max > 0 and self.accel > 0):
            raise MechsynInputError("trapezoidal law needs positive omega_max and accel",
                                    field="omega_max/accel")
        if self.start == self.stop:
            raise MechsynInputError("the motion's start and stop coincide", field="range")

    def _profile(self) -> tuple[float, float, float]:
        stroke = abs(self.stop - self.start)
        t_acc = self.omega_max / self.accel
        if self.accel * t_acc**2 >= stroke:          # triangular
            t_acc = math.sqrt(stroke / self.accel)
            return t_acc, 0.0, self.accel * t_acc
        t_cruise = (stroke - self.accel * t_acc**2) / self.omega_max
        return t_acc, t_cruise, self.omega_max

    def duration(self) -> float:
        t_acc, t_cruise, _ = self._profile()
        return 2 * t_acc + t_cruise

    def evaluate(self, t: ArrayLike) -> tuple[Array, Array, Array]:
        t = np.clip(np.asarray(t, dtype=float), 0.0, self.duration())
        t_acc, t_cruise, w = self._profile()
        e = self.accel
        t2 = t_acc + t_cruise
        T = 2 * t_acc + t_cruise
        s = np.where(t < t_acc, 0.5 * e * t**2,
                     np.where(t < t2, 0.5 * e * t_acc**2 + w * (t - t_acc),
                              0.5 * e * t_acc**2 + w * t_cruise
                              + w * (t - t2) - 0.5 * e * (t - t2) ** 2))
        v = np.where(t < t_acc, e * t, np.where(t < t2, w, e * (T - t)))
        acc = np.where(t < t_acc, e, np.where(t < t2, 0.0, -e))
        sign = math.copysign(1.0, self.stop - self.start)
        return self.start + sign * s, sign * v, sign * acc


@dataclass(frozen=True)
class TableLaw(MotionLaw):
    """Tabulated Δφ(t) interpolated by a C2 cubic spline (scipy ``CubicSpline``)."""

    t: tuple[float, ...]
    phi: tuple[float, ...]
    _spline: CubicSpline = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        t = np.asarray(self.t, dtype=float)
        phi = np.asarray(self.phi, dtype=float)
        if t.ndim != 1 or t.size != phi.size or t.size < 3:
            raise MechsynInputError("a motion table needs at least 3 rows of (t, phi)",
                                    field="table")
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(phi))):
            raise MechsynInputError("the motion table holds a non-finite number",
                                    field="table")
        if np.any(np.diff(t) <= 0):
            raise MechsynInputError("times in the motion table must strictly increase",
                                    field="table.t")
        object.__setattr__(self, "_spline", CubicSpline(t, phi))

    def duration(self) -> float:
        return float(self.t[-1] - self.t[0])

    def evaluate(self, t: ArrayLike) -> tuple[Array, Array, Array]:
        tt = np.asarray(t, dtype=float) + self.t[0]
        sp = self._spline
        return sp(tt), sp(tt, 1), sp(tt, 2)


# ---------------------------------------------------------------- speeds and accels
@dataclass
class PointMotion:
    """Speed and acceleration of one point for an input law (arrays over time).

    velocity = X' φ_dot, speed S_dot = S' |φ_dot| (18), acceleration vector
    X'' φ_dot^2 + X' φ_ddot, its magnitude ``accel`` and tangential part
    ``accel_tangential`` = (X'·X'')/S' φ_dot^2 + S' φ_ddot (signed along the motion);
    ``accel_paper`` is the paper's (19)-(20) S'' φ_dot^2 + S' φ_ddot with S'' = |X''|,
    which is the acceleration's magnitude only when φ_ddot = 0 (labelled, for
    comparison with the paper).
    """

    velocity: Array
    speed: Array
    acceleration: Array
    accel: Array
    accel_tangential: Array
    accel_paper: Array


def point_motion(X1: Array, X2: Array, phid: ArrayLike, phidd: ArrayLike) -> PointMotion:
    """Velocity and acceleration of a point with derivatives X1, X2 (n, 2) w.r.t. Δφ."""
    phid = np.asarray(phid, dtype=float)
    phidd = np.asarray(phidd, dtype=float)
    S1 = np.hypot(X1[:, 0], X1[:, 1])
    S2 = np.hypot(X2[:, 0], X2[:, 1])
    vel = X1 * phid[:, None]
    acc = X2 * (phid**2)[:, None] + X1 * phidd[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        dS1 = np.einsum("ij,ij->i", X1, X2) / S1          # dS'/dΔφ
    sgn = np.where(phid < 0, -1.0, 1.0)
    return PointMotion(
        velocity=vel, speed=S1 * np.abs(phid), acceleration=acc,
        accel=np.hypot(acc[:, 0], acc[:, 1]),
        accel_tangential=sgn * (dS1 * phid**2 + S1 * phidd),
        accel_paper=S2 * phid**2 + S1 * phidd,
    )


@dataclass
class MotionResult:
    """Time history of the mechanism under an input law."""

    t: Array
    dphi: Array
    phid: Array
    phidd: Array
    state: BeltState
    C: PointMotion
    H: PointMotion

    def to_dict(self) -> dict[str, object]:
        def pm(p: PointMotion) -> dict[str, object]:
            return {"speed": p.speed, "accel": p.accel,
                    "accel_tangential": p.accel_tangential,
                    "accel_paper_formula_19": p.accel_paper,
                    "velocity": p.velocity, "acceleration": p.acceleration}
        return {"t": self.t, "dphi_deg": np.degrees(self.dphi),
                "phid_deg_s": np.degrees(self.phid), "phidd_deg_s2": np.degrees(self.phidd),
                "C": pm(self.C), "H": pm(self.H),
                "max": {"C_speed": float(np.nanmax(self.C.speed)),
                        "H_speed": float(np.nanmax(self.H.speed)),
                        "C_accel": float(np.nanmax(self.C.accel)),
                        "H_accel": float(np.nanmax(self.H.accel))}}


def motion(design: BeltDesign, law: MotionLaw, samples: int = 201) -> MotionResult:
    """Evaluate the mechanism along ``law`` at ``samples`` equally spaced instants."""
    if samples < 2:
        raise MechsynInputError("need at least 2 time samples", field="samples")
    t = np.linspace(0.0, law.duration(), samples)
    dphi, phid, phidd = law.evaluate(t)
    st = analyze(design, dphi)
    return MotionResult(t=t, dphi=dphi, phid=phid, phidd=phidd, state=st,
                        C=point_motion(st.C1, st.C2, phid, phidd),
                        H=point_motion(st.H1, st.H2, phid, phidd))


# ------------------------------------------------------------------- inverse problem
@dataclass
class InverseResult:
    """Servo input over the motion for a required speed of H along its path.

    φ_dot = σ v / S',  φ_ddot = (σ a_t - (X'·X''/S') φ_dot^2) / S'  (from (18) and the
    tangential acceleration; σ = ±1 the direction of travel in Δφ), and the time
    t(Δφ) = ∫ dΔφ / φ_dot (zero at the first position).
    """

    dphi: Array
    speed: Array
    accel_tangential: Array
    phid: Array
    phidd: Array
    t: Array

    def to_dict(self) -> dict[str, object]:
        return {"dphi_deg": np.degrees(self.dphi), "speed": self.speed,
                "accel_tangential": self.accel_tangential,
                "phid_deg_s": np.degrees(self.phid), "phidd_deg_s2": np.degrees(self.phidd),
                "t": self.t, "duration": float(self.t[-1]) if self.t.size else 0.0,
                "max_phid_deg_s": float(np.nanmax(np.abs(np.degrees(self.phid)))),
                "max_phidd_deg_s2": float(np.nanmax(np.abs(np.degrees(self.phidd))))}


def inverse_input(
    state: BeltState,
    speed: ArrayLike,
    accel_tangential: ArrayLike = 0.0,
    point: Literal["H", "C"] = "H",
    direction: int | None = None,
) -> InverseResult:
    """Servo input speed and acceleration giving ``point`` the required path speed.

    ``speed`` (> 0) and ``accel_tangential`` (rate of change of the speed) are scalars or
    arrays over ``state.dphi``; ``direction`` is +1 when Δφ increases during the motion,
    -1 when it decreases (default: the order of ``state.dphi``).
    """
    from scipy.integrate import cumulative_trapezoid

    X1 = state.H1 if point == "H" else state.C1
    X2 = state.H2 if point == "H" else state.C2
    n = state.dphi.size
    v = np.broadcast_to(np.asarray(speed, dtype=float), (n,)).astype(float)
    at = np.broadcast_to(np.asarray(accel_tangential, dtype=float), (n,)).astype(float)
    if np.any(~np.isfinite(v)) or np.any(v <= 0):
        raise MechsynInputError("the required speed must be positive and finite",
                                field="speed")
    if direction is None:
        direction = 1 if n < 2 or state.dphi[-1] >= state.dphi[0] else -1
    sigma = float(np.sign(direction)) or 1.0
    S1 = np.hypot(X1[:, 0], X1[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        dS1 = np.einsum("ij,ij->i", X1, X2) / S1
        phid = sigma * v / S1
        phidd = (sigma * at - dS1 * phid**2) / S1
        t = (cumulative_trapezoid(1.0 / phid, state.dphi, initial=0.0)
             if n >= 2 else np.zeros(n))
    return InverseResult(dphi=state.dphi, speed=v, accel_tangential=at, phid=phid,
                         phidd=phidd, t=t)


# ----------------------------------------------------------------- path straightness
def tangent_deviation(P: Array, P0: Array, T0: Array) -> Array:
    """Signed distance of points P (n, 2) from the line through P0 along T0.

    Positive on the side of +y (the normal is T0 turned by ±90° to have a non-negative
    y component; for a vertical tangent, the side of -x).
    """
    t = np.asarray(T0, dtype=float) / np.hypot(*T0)
    nrm = np.array([-t[1], t[0]])
    if nrm[1] < 0 or (nrm[1] == 0 and nrm[0] > 0):
        nrm = -nrm
    return (P - np.asarray(P0)) @ nrm


def best_line_deviation(P: Array) -> tuple[float, Array, Array]:
    """Minimax (Chebyshev) best line of points P (n, 2): the midline of the narrowest strip
    holding them. Returns (largest deviation = half the strip width, a point on the line,
    unit direction). Exact: the narrowest strip has a side on a convex-hull edge (rotating
    calipers), so every hull edge direction is tried.
    """
    P = np.asarray(P, dtype=float)
    P = P[np.all(np.isfinite(P), axis=1)]
    if P.shape[0] < 2:
        raise MechsynInputError("need at least 2 finite path points for a best line")
    centre = P.mean(axis=0)
    _, sv, vt = np.linalg.svd(P - centre, full_matrices=False)
    scale = max(sv[0], 1e-300)
    if sv.size < 2 or sv[1] <= 1e-12 * scale:
        return 0.0, centre, vt[0]
    hull = ConvexHull(P)
    V = P[hull.vertices]
    E = np.roll(V, -1, axis=0) - V
    E /= np.hypot(E[:, 0], E[:, 1])[:, None]
    N = np.stack([-E[:, 1], E[:, 0]], axis=-1)
    proj = V @ N.T                      # (vertices, edges)
    width = proj.max(axis=0) - proj.min(axis=0)
    k = int(np.argmin(width))
    mid = 0.5 * (proj[:, k].max() + proj[:, k].min())
    point = N[k] * mid + E[k] * float(centre @ E[k])
    return float(width[k] / 2), point, E[k]


def _theta_at(design: BeltDesign, dphi: float) -> float:
    return float(analyze(design, [dphi]).theta[0])


def translation_range(design: BeltDesign, lo: float, hi: float, tol: float,
                      samples: int = 4001) -> tuple[float, float]:
    """Δφ interval around the design position (within [lo, hi], rad) over which link 2
    stays within ±``tol`` (rad) of its design attitude (|θ| <= tol); the ends are found
    by Brent's method (scipy ``brentq``) between dense samples."""
    from scipy.optimize import brentq

    lo_c, hi_c = min(lo, 0.0), max(hi, 0.0)
    grid = np.union1d(np.linspace(lo_c, hi_c, samples), [0.0])
    th = analyze(design, grid).theta
    ok = np.abs(th) <= tol
    i0 = int(np.argmin(np.abs(grid)))
    bad_before = np.nonzero(~ok[:i0])[0]
    bad_after = np.nonzero(~ok[i0:])[0]

    def edge(i_in: int, i_out: int) -> float:
        target = math.copysign(tol, th[i_out]) if np.isfinite(th[i_out]) else tol
        f = lambda x: _theta_at(design, x) - target  # noqa: E731
        try:
            return float(brentq(f, grid[i_in], grid[i_out], xtol=1e-12))
        except ValueError:  # NaN (slack belt) at the outer sample
            return float(grid[i_in])

    left = edge(int(bad_before[-1] + 1), int(bad_before[-1])) if bad_before.size else lo_c
    if bad_after.size:
        j = int(i0 + bad_after[0])
        right = edge(j - 1, j)
    else:
        right = hi_c
    return max(left, lo), min(right, hi)


@dataclass
class PathQuality:
    """Straight-line quality of one point's path (lengths in the design's unit).

    extent_x, extent_y: sizes of the path's bounding box over the whole range.
    segment_deg: the Δφ segment judged; segment_span: its length along the design
    tangent; max_positive_deviation / max_negative_deviation: largest distance on the
    +y / -y side of the path's tangent at the design position (paper 001's measure);
    best_line_deviation: half-width of the narrowest strip holding the segment
    (Chebyshev best line), best_line_angle_deg: that line's angle to x;
    translation_*: run around the design position where link 2 stays within
    ±translation_tol_deg of its design attitude, and this point's travel along x over it.
    """

    point: str
    extent_x: float
    extent_y: float
    segment_deg: tuple[float, float]
    segment_span: float
    max_positive_deviation: float
    max_negative_deviation: float
    best_line_deviation: float
    best_line_angle_deg: float
    translation_tol_deg: float
    translation_length: float
    translation_dphi_deg: tuple[float, float]


def path_quality(
    design: BeltDesign,
    dphi_range: tuple[float, float],
    point: Literal["H", "C"] = "H",
    segment: tuple[float, float] | None = None,
    translation_tol: float = math.radians(3.0),
    samples: int = 8001,
) -> PathQuality:
    """Straight-line quality of C's or H's path for Δφ in ``dphi_range`` (rad).

    Evaluated on its own dense grid of ``samples`` positions (results do not depend on
    the step of a table). ``segment`` (rad) defaults to the part from the range's start
    to the design position (Δφ <= 0): the part paper 001 judges (C: ≈800 mm long,
    deviation ≈45 mm; H: ≈20 mm). See :class:`PathQuality`.
    """
    lo, hi = float(min(dphi_range)), float(max(dphi_range))
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi <= lo:
        raise MechsynInputError("the range of Δφ must have two distinct finite ends",
                                field="phi")
    if samples < 3:
        raise MechsynInputError("need at least 3 samples", field="samples")
    grid = np.linspace(lo, hi, samples)
    state = analyze(design, grid)
    P = state.H if point == "H" else state.C
    fin = np.all(np.isfinite(P), axis=1)
    if not np.any(fin):
        raise MechsynInputError("the belt is slack or crossed over the whole range (d <= r)",
                                field="phi")
    if segment is None:
        segment = (lo, 0.0) if lo < 0 < hi else (lo, hi)
    s_lo, s_hi = min(segment), max(segment)
    if s_hi <= s_lo:
        raise MechsynInputError("the segment must have two distinct ends", field="segment")
    tiny = 1e-9 * max(1.0, abs(lo), abs(hi))
    if s_lo < lo - tiny or s_hi > hi + tiny:
        raise MechsynInputError(
            f"segment {math.degrees(s_lo):g}:{math.degrees(s_hi):g} deg lies outside the range "
            f"{math.degrees(lo):g}:{math.degrees(hi):g} deg", field="segment")
    seg_state = analyze(design, np.linspace(s_lo, s_hi, samples))
    seg = seg_state.H if point == "H" else seg_state.C
    seg = seg[np.all(np.isfinite(seg), axis=1)]
    if seg.shape[0] < 2:
        raise MechsynInputError(
            f"segment {math.degrees(s_lo):g}:{math.degrees(s_hi):g} deg: the belt is slack "
            "there", field="segment")
    zero = analyze(design, [0.0])
    P0 = (zero.H if point == "H" else zero.C)[0]
    T0 = (zero.H1 if point == "H" else zero.C1)[0]
    dev = tangent_deviation(seg, P0, T0)
    along = seg @ (T0 / np.hypot(*T0))
    bl_dev, _, bl_dir = best_line_deviation(seg)
    ang = math.degrees(math.atan2(bl_dir[1], bl_dir[0]))
    ang = (ang + 90.0) % 180.0 - 90.0
    t_lo, t_hi = translation_range(design, lo, hi, translation_tol)
    run = analyze(design, np.linspace(t_lo, t_hi, samples))
    xr = (run.H if point == "H" else run.C)[:, 0]
    return PathQuality(
        point=point,
        extent_x=float(np.ptp(P[fin, 0])), extent_y=float(np.ptp(P[fin, 1])),
        segment_deg=(math.degrees(s_lo), math.degrees(s_hi)),
        segment_span=float(np.ptp(along)),
        max_positive_deviation=float(max(dev.max(), 0.0)) + 0.0,
        max_negative_deviation=float(max(-dev.min(), 0.0)) + 0.0,
        best_line_deviation=bl_dev, best_line_angle_deg=ang,
        translation_tol_deg=math.degrees(translation_tol),
        translation_length=float(np.nanmax(xr) - np.nanmin(xr)),
        translation_dphi_deg=(math.degrees(t_lo), math.degrees(t_hi)),
    )


# ------------------------------------------------------------- equivalent four-bar
@dataclass
class FourBarState:
    """Hinged four-bar A0-A-B-B0 equivalent (up to second derivatives) to the belt
    mechanism in its design position: crank A0A = a, coupler AB = r (link 2, carrying C
    and H), rocker BB0 = b0, frame A0B0 = l0, right angle at B in the design position.
    NaN where it cannot be assembled."""

    dphi: Array
    A: Array
    B: Array
    theta: Array
    C: Array
    H: Array
    valid: NDArray[np.bool_]


def equivalent_four_bar(design: BeltDesign, dphi: ArrayLike) -> FourBarState:
    """Positions of the equivalent four-bar over ``dphi`` (rad), assembly branch of the
    design position (B to the right of the line A B0 ... i.e. as in paper 001's fig. 1).

    B is the intersection of the circles (A, r) and (B0, b0); θ = angle of AB to x.
    """
    dphi = np.atleast_1d(np.asarray(dphi, dtype=float))
    a, c, h, r = design.a, design.c, design.h, design.r
    b0 = design.b0
    B0 = design.B0
    A = np.stack([-a * np.sin(dphi), a * np.cos(dphi)], axis=-1)
    D = B0[None, :] - A
    dist = np.hypot(D[:, 0], D[:, 1])
    u = D / dist[:, None]
    along = (dist**2 + r**2 - b0**2) / (2 * dist)
    with np.errstate(invalid="ignore"):
        perp = np.sqrt(r**2 - along**2)
    # design position: A=(0,a), B0=(r, a-b0); B=(r, a) lies on the left-hand normal side?
    nrm = np.stack([-u[:, 1], u[:, 0]], axis=-1)
    # choose the branch sign from the design position
    D0 = B0 - np.array([0.0, a])
    d0 = math.hypot(*D0)
    u0 = D0 / d0
    n0 = np.array([-u0[1], u0[0]])
    al0 = (d0**2 + r**2 - b0**2) / (2 * d0)
    Bdesign = np.array([0.0, a]) + al0 * u0
    sign = 1.0 if (np.array([r, a]) - Bdesign) @ n0 > 0 else -1.0
    B = A + along[:, None] * u + sign * perp[:, None] * nrm
    AB = B - A
    theta = np.arctan2(AB[:, 1], AB[:, 0])
    st, ct = np.sin(theta), np.cos(theta)
    C = A + c * np.stack([-ct, -st], axis=-1)
    H = C + h * np.stack([-st, ct], axis=-1)
    return FourBarState(dphi=dphi, A=A, B=B, theta=theta, C=C, H=H,
                        valid=np.isfinite(perp))


def _run_length(dphi: Array, theta: Array, x: Array, tol: float) -> tuple[float, float, float]:
    """Contiguous run around Δφ = 0 with |θ| <= tol on a grid: (x travel, Δφ ends)."""
    ok = np.abs(theta) <= tol
    i0 = int(np.argmin(np.abs(dphi)))
    if not ok[i0]:
        return 0.0, float(dphi[i0]), float(dphi[i0])
    before = np.nonzero(~ok[:i0])[0]
    after = np.nonzero(~ok[i0:])[0]
    lo = int(before[-1] + 1) if before.size else 0
    hi = int(i0 + after[0] - 1) if after.size else dphi.size - 1
    return float(np.ptp(x[lo:hi + 1])), float(dphi[lo]), float(dphi[hi])


def compare_with_four_bar(
    design: BeltDesign,
    dphi_range: tuple[float, float],
    translation_tol: float = math.radians(3.0),
    samples: int = 4001,
) -> dict[str, object]:
    """Belt mechanism against its equivalent hinged four-bar A0-A-B-B0 (paper 001's claim
    that the belt version is better), over the same lever rotations Δφ in ``dphi_range``.

    For each mechanism and for C and H: the Δφ interval where it can be assembled
    (the belt: d > r; the four-bar: the circles (A, r), (B0, b0) meet), the horizontal
    extent of the path, the largest distances above and below the design tangent line
    on the machine side (Δφ <= 0) and on the other side (Δφ >= 0), and the travel of the
    point while link 2 stays within ±``translation_tol`` of its design attitude. Lengths
    as the design's; angles in degrees.
    """
    lo, hi = float(min(dphi_range)), float(max(dphi_range))
    grid = np.union1d(np.linspace(lo, hi, samples), [0.0] if lo < 0 < hi else [])
    belt = analyze(design, grid)
    fb = equivalent_four_bar(design, grid)
    zero = analyze(design, [0.0])
    out: dict[str, object] = {}
    for name, valid, theta, pts in (
        ("belt", belt.valid, belt.theta, {"C": belt.C, "H": belt.H}),
        ("four_bar", fb.valid, fb.theta, {"C": fb.C, "H": fb.H}),
    ):
        entry: dict[str, object] = {}
        if np.any(valid):
            entry["assembled_dphi_deg"] = [float(np.degrees(grid[valid].min())),
                                           float(np.degrees(grid[valid].max()))]
        else:
            entry["assembled_dphi_deg"] = None
        for p in ("C", "H"):
            P = pts[p]
            P0 = (zero.C if p == "C" else zero.H)[0]
            T0 = (zero.C1 if p == "C" else zero.H1)[0]
            dev = tangent_deviation(P, P0, T0)
            neg, pos = (grid <= 0) & valid, (grid >= 0) & valid
            rec: dict[str, object] = {
                "extent_x": float(np.ptp(P[valid, 0])) if np.any(valid) else None}
            for side, sel in (("machine_side", neg), ("other_side", pos)):
                rec[side] = ({"max_positive_deviation": float(max(dev[sel].max(), 0.0)) + 0.0,
                              "max_negative_deviation": float(max(-dev[sel].min(), 0.0)) + 0.0}
                             if np.any(sel) else None)
            th = np.where(valid, theta, np.inf)
            length, tlo, thi = _run_length(grid, th, np.where(valid, P[:, 0], np.nan),
                                           translation_tol)
            rec["translation_length"] = length
            rec["translation_dphi_deg"] = [math.degrees(tlo), math.degrees(thi)]
            entry[p] = rec
        out[name] = entry
    out["translation_tol_deg"] = math.degrees(translation_tol)
    return out


# ------------------------------------------------------------------ example files
# Schema of a belt-manipulator case file (YAML or JSON), e.g. examples/belt/paper001.yaml:
#
#   name: Paper 001 example
#   design: {a: 500, c: 350, h: 100, r: 75}          # or synthesis: {...} below
#   phi_deg: {start: -73, stop: 85, step: 1}
#   motion: {law: constant, omega_deg_s: 60}         # trapezoidal: omega_max_deg_s, accel_deg_s2
#   paths: {segment_deg: [-73, 0], translation_tol_deg: 3}
#
#   synthesis: {h0: [-350, 600], hf: [324.6, 597.5], phi_of_deg: -60, r: 75, a0: [0, 0]}

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator  # noqa: E402


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class DesignSpec(_Strict):
    """Dimensions of the mechanism (lengths in any one unit, mm in paper 001)."""

    a: float = Field(gt=0, description="lever 1 length |A0 A|")
    c: float = Field(gt=0, description="x offset of C to the left of A")
    h: float = Field(description="height of H above C")
    r: float = Field(gt=0, description="pulley radius")


class SynthesisSpec(_Strict):
    """Working scene for the synthesis (machine frame, y along the machine's axis)."""

    h0: tuple[float, float] = Field(description="design position of H")
    hf: tuple[float, float] = Field(description="final position of H")
    phi_of_deg: float = Field(description="rotation of lever 1 from H0 to Hf, degrees")
    r: float = Field(gt=0, description="pulley radius")
    a0: tuple[float, float] = Field((0.0, 0.0), description="base point A0")


class RangeSpec(_Strict):
    start: float
    stop: float
    step: float = 1.0


class MotionSpec(_Strict):
    law: Literal["constant", "trapezoidal", "table"] = "constant"
    omega_deg_s: float | None = Field(None, gt=0, description="constant input speed")
    omega_max_deg_s: float | None = Field(None, gt=0, description="trapezoidal: top speed")
    accel_deg_s2: float | None = Field(None, gt=0, description="trapezoidal: acceleration")
    t: list[float] | None = Field(None, description="table: times, s")
    phi_deg: list[float] | None = Field(None, description="table: Δφ at those times, deg")

    @model_validator(mode="after")
    def _complete(self) -> "MotionSpec":
        if self.law == "trapezoidal" and (self.omega_max_deg_s is None
                                          or self.accel_deg_s2 is None):
            raise ValueError("a trapezoidal law needs omega_max_deg_s and accel_deg_s2")
        if self.law == "table" and (self.t is None or self.phi_deg is None):
            raise ValueError("a table law needs t and phi_deg lists")
        return self


class PathsSpec(_Strict):
    segment_deg: tuple[float, float] | None = None
    translation_tol_deg: float = Field(3.0, gt=0)


class BeltCase(_Strict):
    """A belt-manipulator case: the design (or its synthesis data) and what to analyse."""

    name: str = "belt manipulator"
    design: DesignSpec | None = None
    synthesis: SynthesisSpec | None = None
    phi_deg: RangeSpec | None = None
    motion: MotionSpec | None = None
    paths: PathsSpec = PathsSpec()

    @model_validator(mode="after")
    def _one_design(self) -> "BeltCase":
        if (self.design is None) == (self.synthesis is None):
            raise ValueError("give exactly one of 'design' and 'synthesis'")
        return self


def load_belt_case(path: str) -> BeltCase:
    """Read and validate a belt case file (YAML or JSON); MechsynInputError on bad input
    (naming the file, the line of a syntax error, or the offending field)."""
    from mechsyn.io.files import read_data

    data, _ = read_data(path, "belt case file")
    if not isinstance(data, dict):
        raise MechsynInputError("expected a mapping (name, design, phi_deg, ...) at the top",
                                source=str(path))
    try:
        return BeltCase.model_validate(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        loc = ".".join(str(x) for x in first["loc"]) or None
        raise MechsynInputError(first["msg"], source=str(path), field=loc,
                                hint="see docs/belt.md for the file's keys") from None


def four_bar_mechanism_dict(design: BeltDesign, name: str | None = None) -> dict[str, object]:
    """The equivalent four-bar A0-A-B-B0 of the design position as a mechanism-file dict
    (issue 2's YAML/JSON format, for the general planar solver): frame, lever (A0 A),
    hand (A B, carrying C and H: link 2 with its pulley) and rocker (B B0, the belt's free
    run frozen at b0). The belt mechanism itself differs from it beyond second order."""
    a, c, h, r = design.a, design.c, design.h, design.r
    b0 = design.b0
    return {
        "name": name or f"equivalent four-bar of the belt manipulator a={a:g} c={c:g} "
                        f"h={h:g} r={r:g}",
        "kind": "planar",
        "ground": "frame",
        "links": ["frame", "lever", "hand", "rocker"],
        "joints": [
            {"id": "A0", "type": "R", "links": ["frame", "lever"], "point": [0.0, 0.0],
             "actuated": True},
            {"id": "A", "type": "R", "links": ["lever", "hand"], "point": [0.0, a]},
            {"id": "B", "type": "R", "links": ["hand", "rocker"], "point": [r, a]},
            {"id": "B0", "type": "R", "links": ["rocker", "frame"], "point": [r, a - b0]},
        ],
        "points": {"C": {"link": "hand", "at": [-c, a]},
                   "H": {"link": "hand", "at": [-c, a + h]}},
    }


def belt_mechanism_dict(design: BeltDesign, name: str | None = None) -> dict[str, object]:
    """The belt manipulator itself as a mechanism-file dict for the general planar solver,
    in the design position: frame, lever (A0 A, driven at A0), hand (link 2 with its
    pulley, C and H) and a ``belt`` pair from the frame (anchor B0 = (r, a - b0)) to the
    hand's pulley centred on A, wrapped counter-clockwise. A0's input is the lever's
    direction: 90° + Δφ (``examples/belt/paper001_mechanism.yaml`` for the paper's numbers).
    """
    a, c, h, r = design.a, design.c, design.h, design.r
    B0 = [float(x) for x in design.B0]
    return {
        "name": name or f"belt manipulator a={a:g} c={c:g} h={h:g} r={r:g}",
        "kind": "planar",
        "ground": "frame",
        "links": ["frame", "lever", "hand"],
        "joints": [
            {"id": "A0", "type": "R", "links": ["frame", "lever"], "point": [0.0, 0.0],
             "actuated": True},
            {"id": "A", "type": "R", "links": ["lever", "hand"], "point": [0.0, a]},
            {"id": "W", "type": "belt", "links": ["frame", "hand"], "point": [0.0, a],
             "anchor": B0, "radius": r, "wrap": "ccw"},
        ],
        "points": {"C": {"link": "hand", "at": [-c, a]},
                   "H": {"link": "hand", "at": [-c, a + h]},
                   "B0": {"link": "frame", "at": B0}},
    }
