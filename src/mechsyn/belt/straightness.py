"""How straight the paths of C and H of paper 001's belt manipulator are.

Deviations from the design tangent (the paper's measure), the Chebyshev (minimax) best
line, and the run over which link 2 keeps its design attitude within a tolerance.

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
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull

from mechsyn.belt.design import BeltDesign
from mechsyn.belt.kinematics import analyze
from mechsyn.errors import MechsynInputError

Array = NDArray[np.float64]

__all__ = ["PathQuality", "best_line_deviation", "path_quality", "tangent_deviation",
           "translation_range", "translation_travel"]


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
    unit direction). Exact: the narrowest strip has a side on a convex-hull edge, so every
    hull edge is tried, each against its antipodal vertex (rotating calipers: the vertex
    where the hull's edge angles pass the edge's own plus 180°, found by a binary search),
    in O(h log h) for h hull vertices.

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.belt.straightness import best_line_deviation
    >>> x = np.linspace(0, 10, 11)
    >>> dev, point, direction = best_line_deviation(np.c_[x, 0.5 * (-1.0) ** np.arange(11)])
    >>> round(dev, 12), np.round(np.abs(direction), 12).tolist()
    (0.5, [1.0, 0.0])
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
    V = P[ConvexHull(P).vertices]      # counter-clockwise
    h = V.shape[0]
    E = np.roll(V, -1, axis=0) - V
    E /= np.hypot(E[:, 0], E[:, 1])[:, None]
    N = np.stack([-E[:, 1], E[:, 0]], axis=-1)          # inward normals
    angle = np.unwrap(np.arctan2(E[:, 1], E[:, 0]))     # increasing: exterior angles < 180°
    far = np.searchsorted(np.concatenate([angle, angle + 2 * np.pi]), angle + np.pi)
    cand = (far[None, :] + np.arange(-1, 2)[:, None]) % h   # and its neighbours, for rounding
    high = np.einsum("ckj,kj->ck", V[cand], N).max(axis=0)
    low = np.einsum("kj,kj->k", V, N)
    width = high - low
    k = int(np.argmin(width))
    point = N[k] * 0.5 * (high[k] + low[k]) + E[k] * float(centre @ E[k])
    return float(width[k] / 2), point, E[k]


def translation_range(design: BeltDesign, lo: float, hi: float, tol: float,
                      samples: int = 4001, theta_of=None) -> tuple[float, float]:
    """Δφ interval around the design position (within [lo, hi], rad) over which link 2
    stays within ±``tol`` (rad) of its design attitude (|θ| <= tol); the ends are found
    by Brent's method (scipy ``brentq``) between dense samples. ``theta_of`` (Δφ array ->
    θ array, NaN where it does not assemble) is the belt mechanism's by default; the
    equivalent four-bar's is measured the same way (:func:`~mechsyn.belt.four_bar.compare_with_four_bar`)."""
    from scipy.optimize import brentq

    theta_of = theta_of if theta_of is not None else (lambda g: analyze(design, g).theta)
    lo_c, hi_c = min(lo, 0.0), max(hi, 0.0)
    grid = np.union1d(np.linspace(lo_c, hi_c, samples), [0.0])
    th = theta_of(grid)
    ok = np.abs(th) <= tol
    i0 = int(np.argmin(np.abs(grid)))
    if not ok[i0]:
        return float(grid[i0]), float(grid[i0])
    bad_before = np.nonzero(~ok[:i0])[0]
    bad_after = np.nonzero(~ok[i0:])[0]

    def edge(i_in: int, i_out: int) -> float:
        target = math.copysign(tol, th[i_out]) if np.isfinite(th[i_out]) else tol
        f = lambda x: float(theta_of(np.array([x]))[0]) - target  # noqa: E731
        try:
            return float(brentq(f, grid[i_in], grid[i_out], xtol=1e-12))
        except ValueError:  # NaN (slack belt, no assembly) at the outer sample
            return float(grid[i_in])

    left = edge(int(bad_before[-1] + 1), int(bad_before[-1])) if bad_before.size else lo_c
    if bad_after.size:
        j = int(i0 + bad_after[0])
        right = edge(j - 1, j)
    else:
        right = hi_c
    return max(left, lo), min(right, hi)


def translation_travel(x_of, t_lo: float, t_hi: float, samples: int = 8001) -> float:
    """A point's travel along x while Δφ runs over [t_lo, t_hi] (``x_of``: Δφ array -> x
    array): the one measure of the report's "travel with |θ| ≤ tol", belt and four-bar alike."""
    xr = x_of(np.linspace(t_lo, t_hi, samples))
    return float(np.nanmax(xr) - np.nanmin(xr)) if np.any(np.isfinite(xr)) else 0.0


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
    travel = translation_travel(lambda g: (analyze(design, g).H if point == "H" else analyze(design, g).C)[:, 0],
                                t_lo, t_hi, samples)
    return PathQuality(
        point=point,
        extent_x=float(np.ptp(P[fin, 0])), extent_y=float(np.ptp(P[fin, 1])),
        segment_deg=(math.degrees(s_lo), math.degrees(s_hi)),
        segment_span=float(np.ptp(along)),
        max_positive_deviation=float(max(dev.max(), 0.0)) + 0.0,
        max_negative_deviation=float(max(-dev.min(), 0.0)) + 0.0,
        best_line_deviation=bl_dev, best_line_angle_deg=ang,
        translation_tol_deg=math.degrees(translation_tol),
        translation_length=travel,
        translation_dphi_deg=(math.degrees(t_lo), math.degrees(t_hi)),
    )


