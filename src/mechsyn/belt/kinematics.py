"""Closed-form kinematics of paper 001's manipulator with a flexible element.

Lever 1 pivots on the frame at A0; link 2 (the "hand", carrying the gripper point H)
pivots on lever 1 at A and carries a pulley of radius r centred on A; a belt pinned to the
frame at B0 wraps the pulley counter-clockwise (geometry: :mod:`mechsyn.belt.design`).

Angles: Δφ is the rotation of lever 1 from the design position (counter-clockwise
positive), Δψ the rotation of link 2 relative to lever 1, θ = Δφ + Δψ the absolute angle
of link 2. Derivatives ``1`` and ``2`` are first and second derivatives with respect to
Δφ in radians. Every function takes NumPy arrays of Δφ and is vectorised.

Notes
-----
Differences from the paper: the equations are the spec's corrected set. The printed (4),
(9), (13), (14) carry sign slips (the paper's (9) is the derivative with respect to -Δφ)
and (19) is the acceleration's magnitude only when φ̈ = 0 (see :func:`analyze` and
:class:`PointMotion`).

References
----------
.. [1] Paper 001 (seed 001), the belt manipulator: the reference in :mod:`mechsyn.belt`.
.. [2] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from mechsyn.belt.design import BeltDesign, design_constants
from mechsyn.errors import MechsynInputError

Array = NDArray[np.float64]

__all__ = [
    "BeltState", "MotionLaw", "ConstantSpeedLaw", "TrapezoidalLaw", "TableLaw", "PointMotion",
    "MotionResult", "InverseResult", "analyze", "point_motion", "motion", "inverse_input",
]


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

    def describe(self) -> str:  # pragma: no cover - abstract
        """The law in words, as a report prints it (no class name)."""
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

    def describe(self) -> str:
        """The law in words.

        >>> ConstantSpeedLaw(0.0, 1.0, math.radians(60)).describe()
        'constant speed 60 °/s'
        """
        return f"constant speed {math.degrees(self.omega):.4g} °/s"

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

    def describe(self) -> str:
        """The law in words.

        >>> TrapezoidalLaw(0.0, 1.0, math.radians(90), math.radians(180)).describe()
        'trapezoidal speed: top 90 °/s, acceleration 180 °/s²'
        """
        return (f"trapezoidal speed: top {math.degrees(self.omega_max):.4g} °/s, "
                f"acceleration {math.degrees(self.accel):.4g} °/s²")

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

    def describe(self) -> str:
        """The table's size in words."""
        return f"table of {len(self.t)} times, spline-interpolated"

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
    design: BeltDesign | None = None
    point: str = "H"

    def to_dict(self) -> dict[str, object]:
        """The ``mechsyn belt inverse --json`` contract (angles in degrees)."""
        return {"design": self.design.to_dict() if self.design is not None else None,
                "point": self.point, "dphi_deg": np.degrees(self.dphi), "speed": self.speed,
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

    if point not in ("H", "C"):
        raise MechsynInputError(f"unknown point {point!r}", field="point", hint="H or C")
    if not np.all(state.valid):
        bad = np.degrees(state.dphi[~state.valid])
        raise MechsynInputError(
            f"the belt goes slack (d <= r) inside the range (Δφ = {bad.min():g}…{bad.max():g}°): "
            "no input can move the point there", field="phi", hint="narrow the range")
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
                         phidd=phidd, t=t, design=state.design, point=point)


