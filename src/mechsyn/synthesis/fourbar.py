"""Closed-form position analysis of the planar four-bar and slider-crank, vectorised.

Every function broadcasts over its arguments, so a whole population of designs (shape
``(P, 1)``) is evaluated at all targets (shape ``(P, n)`` or ``(n,)``) in one call.

Conventions (Cabrera, Simon & Prado 2002, *Mech. Mach. Theory* 37:1165, as used by the
public synthesis cases): local frame with the crank pivot ``O2 = (0, 0)`` and the rocker
pivot ``O4 = (r1, 0)``; ``theta2`` is the crank angle from the line ``O2 -> O4``;
``A = r2 (cos theta2, sin theta2)`` is the crank pin, ``B`` the coupler-rocker joint,
``theta3`` the coupler angle (direction ``A -> B``).

Assembly branch: ``branch = -1`` puts ``B`` on the LEFT of the directed line ``A -> O4``,
``branch = +1`` on its right. Cabrera's formula

    theta3 = 2 atan((-E + branch * sqrt(E^2 - 4 D F)) / (2 D)),
    D = cos t2 - K1 + K4 cos t2 + K5,  E = -2 sin t2,  F = K1 + (K4 - 1) cos t2 + K5,
    K1 = r1/r2,  K4 = r1/r3,  K5 = (r4^2 - r1^2 - r2^2 - r3^2) / (2 r2 r3)

gives the same configurations (tested); the geometric form used here has no singularity
at ``D = 0``. A configuration that cannot be assembled (``|A O4|`` outside
``[|r3 - r4|, r3 + r4]``) is reported in the ``assembled`` mask with NaN angles: no real
part of a complex angle is ever taken.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechsyn.kinematics.groups import circle_circle

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class FourBarPose:
    """Positions of a four-bar at a set of crank angles (arrays broadcast together).

    ``A``/``B``/``C``: crank pin, coupler-rocker joint and coupler point, shape ``(..., 2)``
    in the global frame; ``theta3``/``theta4``: coupler and rocker angles in the local frame
    (from ``O2 -> O4``); ``assembled``: bool mask; ``mu``: transmission angle (between
    coupler and rocker, in ``[0, pi]``).
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    theta3: np.ndarray
    theta4: np.ndarray
    mu: np.ndarray
    assembled: np.ndarray


def rotate(x: np.ndarray, y: np.ndarray, angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotate the vector ``(x, y)`` by ``angle`` (counter-clockwise)."""
    c, s = np.cos(angle), np.sin(angle)
    return c * x - s * y, s * x + c * y


def fourbar_position(
    r1, r2, r3, r4, theta2, *, branch: int = -1, rcx=0.0, rcy=0.0, x0=0.0, y0=0.0, theta0=0.0,
) -> FourBarPose:
    """Closed-form position of a four-bar linkage (all arguments broadcast).

    ``B = A + r3 u`` is the intersection of the circles (``A``, ``r3``) and (``O4``, ``r4``)
    (:func:`coupler_direction`, the RRR kernel); ``theta3`` the direction of ``u``: with
    ``d = |O4 - A|`` and ``gamma`` the direction of ``A -> O4``, ``theta3 = gamma - branch *
    alpha``, ``cos(alpha) = (r3^2 + d^2 - r4^2) / (2 r3 d)``.
    The coupler point is ``C = R(theta0) [A + rcx u + rcy n] + (x0, y0)`` with
    ``u = (cos theta3, sin theta3)``, ``n = (-sin theta3, cos theta3)``.
    """
    r1, r2, r3, r4, theta2 = np.broadcast_arrays(*(np.asarray(v, float) for v in (r1, r2, r3, r4, theta2)))
    ax, ay = r2 * np.cos(theta2), r2 * np.sin(theta2)
    with np.errstate(divide="ignore", invalid="ignore"):
        ux, uy, assembled = coupler_direction(ax, ay, r1, r3, r4, branch)
        assembled &= (r3 > 0) & (r4 > 0)
        ux, uy = np.where(assembled, ux, np.nan), np.where(assembled, uy, np.nan)
        theta3 = np.arctan2(uy, ux)
        bx, by = ax + r3 * ux, ay + r3 * uy
        theta4 = np.arctan2(by, bx - r1)
        d2 = (r1 - ax) ** 2 + ay * ay
        cos_mu = (r3 * r3 + r4 * r4 - d2) / (2.0 * r3 * r4)
        mu = np.where(assembled, np.arccos(np.clip(cos_mu, -1.0, 1.0)), np.nan)
    ux, uy = np.cos(theta3), np.sin(theta3)
    cx = ax + rcx * ux - rcy * uy
    cy = ay + rcx * uy + rcy * ux

    def to_global(x, y):
        gx, gy = rotate(x, y, theta0)
        return np.stack(np.broadcast_arrays(gx + x0, gy + y0), axis=-1)

    return FourBarPose(
        A=to_global(ax, ay), B=to_global(bx, by), C=to_global(cx, cy),
        theta3=theta3, theta4=theta4, mu=mu, assembled=assembled,
    )


def coupler_direction(ax, ay, r1, r3, r4, branch: int = -1, folded: bool = False):
    """The coupler's unit direction ``(ux, uy)`` from the crank pin ``A = (ax, ay)`` and
    whether the four-bar assembles, by the RRR kernel
    :func:`mechsyn.kinematics.groups.circle_circle` (the circles (``A``, ``r3``) and
    (``O4``, ``r4``)): with ``d = O4 - A``, ``u = (f d - branch g R90 d) / r3`` (``f d``
    and ``g |d|`` are the coupler's components along and across ``d``).

    Where it does not assemble, ``u`` is NaN, or with ``folded`` the folded direction
    ``sign(f) d / |d|`` (the coupler laid along ``d``: the pose nearest to assembling,
    which keeps a least-squares residual finite).
    """
    dx, dy = r1 - ax, -ay
    f, g2, _ = circle_circle(np.asarray(dx, float), np.asarray(dy, float), r3 * r3, r4 * r4)
    assembled = g2 >= 0
    if folded:
        g2 = np.maximum(g2, 0.0)
    g = np.sqrt(g2)
    ux = (f * dx + branch * g * dy) / r3
    uy = (f * dy - branch * g * dx) / r3
    if folded and not assembled.all():
        n = np.hypot(ux, uy)  # 1 where assembled (to round-off); |f d| / r3 where folded
        ux, uy = np.where(assembled, ux, ux / n), np.where(assembled, uy, uy / n)
    return ux, uy, assembled


def coupler_point(r1, r2, r3, r4, theta2, branch: int = -1, rcx=0.0, rcy=0.0, x0=0.0, y0=0.0, theta0=0.0,
                  folded: bool = False):
    """Coupler point only, ``(Cx, Cy, assembled)``: the lean form of :func:`fourbar_position`
    (:func:`coupler_direction`: NaN where the linkage cannot be assembled, or with
    ``folded`` the folded pose there).
    """
    ax, ay = r2 * np.cos(theta2), r2 * np.sin(theta2)
    with np.errstate(divide="ignore", invalid="ignore"):
        ux, uy, assembled = coupler_direction(ax, ay, r1, r3, r4, branch, folded)
        cx = ax + rcx * ux - rcy * uy
        cy = ay + rcx * uy + rcy * ux
    c0, s0 = np.cos(theta0), np.sin(theta0)
    return c0 * cx - s0 * cy + x0, s0 * cx + c0 * cy + y0, assembled


def cabrera_theta3(r1, r2, r3, r4, theta2, branch: int = -1) -> np.ndarray:
    """Coupler angle by Cabrera et al. (2002)'s half-angle formula (reference form).

    ``theta3 = 2 atan((-E + branch sqrt(E^2 - 4DF)) / (2D))`` with ``D, E, F`` as in the
    module docstring; NaN where ``E^2 - 4DF < 0`` (cannot assemble). Kept as the
    independent reference of :func:`fourbar_position` (it is singular at ``D = 0``).
    """
    r1, r2, r3, r4, t2 = (np.asarray(v, float) for v in (r1, r2, r3, r4, theta2))
    k1, k4 = r1 / r2, r1 / r3
    k5 = (r4**2 - r1**2 - r2**2 - r3**2) / (2 * r2 * r3)
    D = np.cos(t2) - k1 + k4 * np.cos(t2) + k5
    E = -2 * np.sin(t2)
    F = k1 + (k4 - 1) * np.cos(t2) + k5
    disc = E * E - 4 * D * F
    with np.errstate(invalid="ignore"):
        return np.where(disc >= 0, 2 * np.arctan((-E + branch * np.sqrt(disc)) / (2 * D)), np.nan)


def crank_cos_range(r1, r2, r3, r4) -> tuple[np.ndarray, np.ndarray]:
    """Interval ``[c_lo, c_hi]`` of ``cos(theta2)`` at which the four-bar assembles.

    From ``|A - O4|^2 = r1^2 + r2^2 - 2 r1 r2 cos(theta2)`` in ``[(r3 - r4)^2, (r3 + r4)^2]``:
    ``c_lo = (r1^2 + r2^2 - (r3 + r4)^2) / (2 r1 r2)``,
    ``c_hi = (r1^2 + r2^2 - (r3 - r4)^2) / (2 r1 r2)``. Empty when ``c_lo > c_hi`` or the
    interval misses ``[-1, 1]``.
    """
    r1, r2, r3, r4 = (np.asarray(v, float) for v in (r1, r2, r3, r4))
    with np.errstate(divide="ignore", invalid="ignore"):
        den = 2.0 * r1 * r2
        c_lo = (r1 * r1 + r2 * r2 - (r3 + r4) ** 2) / den
        c_hi = (r1 * r1 + r2 * r2 - (r3 - r4) ** 2) / den
    return c_lo, c_hi


def arc_cos_extremes(theta_start, sweep) -> tuple[np.ndarray, np.ndarray]:
    """Minimum and maximum of ``cos(theta)`` over the arc from ``theta_start`` by ``sweep``.

    ``sweep`` is signed (positive = counter-clockwise). The maximum is 1 when the arc
    contains an angle ``2 k pi``, the minimum -1 when it contains ``(2k + 1) pi``;
    otherwise they are the end values. Used to check that the linkage stays assembled
    (and the transmission angle in bounds) along the whole motion between two targets.
    """
    a = np.asarray(theta_start, float)
    s = np.asarray(sweep, float)
    lo = np.minimum(a, a + s)
    hi = np.maximum(a, a + s)
    c_end = np.minimum(np.cos(lo), np.cos(hi)), np.maximum(np.cos(lo), np.cos(hi))
    contains_zero = TWO_PI * np.floor(hi / TWO_PI) >= lo
    contains_pi = TWO_PI * np.floor((hi - np.pi) / TWO_PI) + np.pi >= lo
    cmax = np.where(contains_zero, 1.0, c_end[1])
    cmin = np.where(contains_pi, -1.0, c_end[0])
    return cmin, cmax


def grashof_excess(r1, r2, r3, r4) -> np.ndarray:
    """Grashof's ``s + l - p - q`` (shortest + longest minus the other two); ``<= 0``: Grashof."""
    r = np.stack(np.broadcast_arrays(*(np.asarray(v, float) for v in (r1, r2, r3, r4))), axis=-1)
    r = np.sort(r, axis=-1)
    return r[..., 0] + r[..., 3] - r[..., 1] - r[..., 2]


@dataclass(frozen=True)
class SliderCrankPose:
    """Positions of an offset slider-crank (see :func:`slider_crank_position`)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    theta3: np.ndarray
    slider: np.ndarray
    assembled: np.ndarray


def slider_crank_position(
    r2, r3, e, theta2, *, branch: int = -1, rcx=0.0, rcy=0.0, x0=0.0, y0=0.0, theta0=0.0,
) -> SliderCrankPose:
    """Closed-form offset slider-crank: crank ``r2`` about ``O2``, coupler ``r3``, slider
    pin ``B`` on the line ``y = e`` of the local frame (slide direction ``theta0``).

    ``B = (A_x - branch sqrt(r3^2 - (e - A_y)^2), e)``: ``branch = -1`` puts the slider
    ahead of the crank pin (+x side). Assembles when ``|e - A_y| <= r3``. The coupler point
    is ``A + rcx u + rcy n`` in the coupler frame (``u`` along ``A -> B``).
    """
    r2, r3, e, theta2 = np.broadcast_arrays(*(np.asarray(v, float) for v in (r2, r3, e, theta2)))
    ax, ay = r2 * np.cos(theta2), r2 * np.sin(theta2)
    h2 = r3 * r3 - (e - ay) ** 2
    assembled = (h2 >= 0) & (r3 > 0)
    with np.errstate(invalid="ignore"):
        bx = np.where(assembled, ax - branch * np.sqrt(np.where(assembled, h2, 0.0)), np.nan)
    by = np.where(assembled, e, np.nan)
    theta3 = np.arctan2(by - ay, bx - ax)
    ux, uy = np.cos(theta3), np.sin(theta3)
    cx = ax + rcx * ux - rcy * uy
    cy = ay + rcx * uy + rcy * ux

    def to_global(x, y):
        gx, gy = rotate(x, y, theta0)
        return np.stack(np.broadcast_arrays(gx + x0, gy + y0), axis=-1)

    return SliderCrankPose(
        A=to_global(ax, ay), B=to_global(bx, by), C=to_global(cx, cy),
        theta3=theta3, slider=bx, assembled=assembled,
    )
