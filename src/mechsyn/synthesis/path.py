"""Four-bar path generation: the case's objective and its constraints.

A case (:class:`~mechsyn.synthesis.cases.PathCase`, read by :mod:`mechsyn.synthesis.cases`) follows the schema of ``spec/data/synthesis_cases_public.json``: ``targets``
(``n`` points), ``timing`` (``prescribed``: a fixed ``theta2`` list; ``prescribed_increment``:
``theta2_1`` is a variable and ``theta2_i = theta2_1 + (i - 1) step`` with ``timing.step``
or ``timing.increments``; ``free``: one variable ``theta2_i`` per target), ``fixed`` values,
``variables`` with bounds, ``kinematics.branch`` and ``constraints``.

Design vector names: ``x0, y0`` (crank pivot), ``theta0`` (ground line angle), ``r1`` ground,
``r2`` crank, ``r3`` coupler, ``r4`` rocker, ``rcx, rcy`` (coupler point in the coupler
frame), ``theta2_i`` (crank angles, radians). Objective (the cases' ``objective``):

    f = sum_i |C_i - Cd_i|^2     (sum of squared distances, no mean, no root)

Constraints (all must hold; see :meth:`PathProblem.evaluate`):

* the linkage assembles on the case's fixed branch at every target AND along the whole
  crank motion from one target to the next (so it cannot jump branch or pass a dead
  position between targets; this is the order/branch-defect check of path generation);
* Grashof ``s + l <= p + q`` when the case lists a ``Grashof`` constraint (or
  ``options.grashof`` is true; ``"crank-rocker"`` also asks the crank to be shortest),
  with a margin: at the crank angles where the four pivots can line up (``theta2 = 0``
  and ``pi``, where the crank reaches them) the transmission angle must stay at least
  ``options.fold_margin_deg`` (default 5 deg) away from 0 and 180 deg. At
  ``s + l = p + q`` the linkage folds flat there once per turn (a change point, where
  it may leave its branch); Grashof alone lets such designs through;
* a minimum transmission angle ``options.transmission_angle_min_deg`` (default 20 deg,
  0 to drop it) over the whole motion from the first target to the last (the angle
  ``mu`` between coupler and rocker must stay within ``[min, 180 - min]``);
* input angles cyclically ordered (counter-clockwise, at most one turn) for free timing;
* optional ``options.link_ratio_max`` (longest / shortest of ``r1..r4``);
* a size bound ``options.max_size`` or ``--max-size`` (0 or absent: none; the bounds a
  case states on its variables are its design space, no default overrides them, and the
  result's ``limited_by`` names any bound the design sits on): both frame pivots and the whole circles the
  crank and rocker pins move on lie within ``max_size`` diagonals of the targets'
  centroid, both the curve's own as in ``synth curve``
  (:func:`~mechsyn.synthesis.curves.target.principal_frame`: the centroid of the polyline
  through the targets and the diagonal along its principal axes, so the bound turns with
  the drawing; the linkage, pivots included, fits in a disc ``2 max_size`` diagonals
  across; the pins' circles are a safe over-estimate of the arcs they sweep);
* variable bounds.

Feasibility first: an infeasible design scores ``U + violation`` where ``U`` is an upper
bound of the objective of every design within the bounds, so no infeasible design can
ever rank better than a feasible one (Deb's rule as a penalty).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn.synthesis.cases import (  # noqa: F401  (the case format lives in cases.py)
    FOLD_MARGIN_DEG,
    LENGTHS,
    LINKAGE_NAMES,
    TIMING_TYPES,
    TRANSMISSION_ANGLE_MIN_DEG,
    PathCase,
    Variable,
    load_cases,
)
from mechsyn.synthesis.fourbar import (
    TWO_PI,
    arc_cos_extremes,
    coupler_point,
    crank_cos_range,
    fourbar_position,
    grashof_excess,
)

_TOL = 1e-9  # rad: allowed overlap of the first and last crank angle (free timing)
FEASIBILITY_TOL = 1e-12  # total violation treated as numerically zero


@dataclass(frozen=True)
class Evaluation:
    """Objective and constraint state of a batch of designs (arrays of shape ``(P,)``)."""

    error: np.ndarray
    violation: np.ndarray
    assembled_at_all_targets: np.ndarray

    @property
    def feasible(self) -> np.ndarray:
        return self.violation <= FEASIBILITY_TOL


class PathProblem:
    """The optimisation problem of a :class:`PathCase`.

    The optimiser works on an internal vector ``z``: the linkage variables in the case's
    order, then the timing variables. For free timing these are ``theta2_1`` and the
    increments ``delta_i = theta2_(i+1) - theta2_i`` in ``[0, 2 pi]`` (counter-clockwise
    order; mirrored for ``order = "cw"``), so ordering becomes the single constraint
    ``sum(delta) <= 2 pi``. :meth:`design` maps ``z`` to the case's own variables.
    """

    def __init__(self, case: PathCase):
        self.case = case
        b = case.bounds()
        self.linkage_vars = [v.name for v in case.variables if v.name in LINKAGE_NAMES]
        lo = [b[k][0] for k in self.linkage_vars]
        hi = [b[k][1] for k in self.linkage_vars]
        n = case.n
        if case.timing == "free":
            lo += [b["theta2_1"][0]] + [0.0] * (n - 1)
            hi += [b["theta2_1"][1]] + [TWO_PI] * (n - 1)
        elif case.timing == "prescribed_increment":
            lo.append(b["theta2_1"][0])
            hi.append(b["theta2_1"][1])
        self.lower = np.array(lo, float)
        self.upper = np.array(hi, float)
        self.names = self.linkage_vars + (
            ["theta2_1"] + [f"delta_{i + 1}" for i in range(n - 1)] if case.timing == "free"
            else (["theta2_1"] if case.timing == "prescribed_increment" else []))
        self.penalty_base = self._objective_upper_bound()

    @property
    def dim(self) -> int:
        return len(self.lower)

    def _objective_upper_bound(self) -> float:
        """``U``: no design within the bounds can have a larger objective.

        ``|C| <= |(x0, y0)| + r2 + |(rcx, rcy)|`` (coupler point = pivot + crank + offset),
        so ``f <= n (max|C| + max|Cd|)^2``; doubled and padded for safety.
        """
        b = self.case.bounds()

        def mag(k):
            if k in self.case.fixed:
                return abs(self.case.fixed[k])
            return max(abs(b[k][0]), abs(b[k][1]))

        reach = np.hypot(mag("x0"), mag("y0")) + mag("r2") + np.hypot(mag("rcx"), mag("rcy"))
        tmax = np.max(np.hypot(*self.case.targets.T))
        return float(2.0 * self.case.n * (reach + tmax) ** 2 + 1.0)

    # -- mapping -------------------------------------------------------------------------
    def unpack(self, z: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
        """Linkage values ``(P,)`` each, crank angles ``(P, n)`` and signed sweeps ``(P, n-1)``."""
        z = np.atleast_2d(z)
        P = z.shape[0]
        vals = {k: np.full(P, v) for k, v in self.case.fixed.items()}
        for j, k in enumerate(self.linkage_vars):
            vals[k] = z[:, j]
        m = len(self.linkage_vars)
        case = self.case
        if case.timing == "prescribed":
            th = np.broadcast_to(case.theta2, (P, case.n))
        elif case.timing == "prescribed_increment":
            th = z[:, m:m + 1] + case.theta2[None, :]
        else:
            sign = 1.0 if case.order == "ccw" else -1.0
            th = z[:, m:m + 1] + sign * np.concatenate(
                [np.zeros((P, 1)), np.cumsum(z[:, m + 1:], axis=1)], axis=1)
        sweeps = np.diff(th, axis=1)
        return vals, th, sweeps

    def design(self, z: np.ndarray) -> dict[str, Any]:
        """The case's design variables (names as in the case) for one internal vector."""
        vals, th, _ = self.unpack(np.asarray(z, float)[None, :])
        out: dict[str, Any] = {k: float(vals[k][0]) for k in self.linkage_vars}
        if self.case.timing != "prescribed":
            b = self.case.bounds()
            angles = []
            for i, t in enumerate(th[0]):
                lo, hi = b.get(f"theta2_{i + 1}", b["theta2_1"])
                if hi - lo >= TWO_PI - 1e-12:
                    t = lo + np.mod(t - lo, TWO_PI)
                angles.append(float(t))
            if self.case.timing == "free":
                out.update({f"theta2_{i + 1}": a for i, a in enumerate(angles)})
            else:
                out["theta2_1"] = angles[0]
        return out

    def internal(self, design: dict[str, Any]) -> np.ndarray:
        """Inverse of :meth:`design` (accepts ``theta2`` as a list as in published vectors)."""
        z = [float(design[k]) for k in self.linkage_vars]
        if self.case.timing == "free":
            th = np.asarray(design["theta2"] if "theta2" in design else
                            [design[f"theta2_{i + 1}"] for i in range(self.case.n)], float)
            sign = 1.0 if self.case.order == "ccw" else -1.0
            z += [th[0]] + list(np.mod(sign * np.diff(th), TWO_PI))
        elif self.case.timing == "prescribed_increment":
            z.append(float(design["theta2_1"]))
        return np.array(z)

    @property
    def reduced_dim(self) -> int:
        """Number of variables the global search sees (free timing: linkage only)."""
        return len(self.linkage_vars) if self.case.timing == "free" else self.dim

    def project_timing(self, zl: np.ndarray, samples: int = 96, refinements: int = 2) -> np.ndarray:
        """Complete linkage-only vectors ``(P, m)`` with their best crank angles (free timing).

        For each design the coupler curve is sampled at ``samples`` crank angles on the
        case's branch; each target takes the angle of its nearest curve point, refined
        ``refinements`` times by a parabola through the squared distances at the angle and
        its neighbours (spacing divided by 6 each time). The result is a full internal
        vector whose objective is evaluated as usual (so it is the objective of a real
        design, not an estimate); ordering and assembly are checked as for any design.
        """
        zl = np.atleast_2d(np.asarray(zl, float))
        P, m = zl.shape
        case = self.case
        vals = {k: np.full(P, v) for k, v in case.fixed.items()}
        for j, k in enumerate(self.linkage_vars):
            vals[k] = zl[:, j]
        tx, ty = case.targets[:, 0], case.targets[:, 1]

        def d2(theta, extra_axis):
            sh = (P, 1, 1) if extra_axis else (P, 1)
            c = {k: v.reshape(sh) for k, v in vals.items()}
            cx, cy, ok = coupler_point(c["r1"], c["r2"], c["r3"], c["r4"], theta, case.branch,
                                       c["rcx"], c["rcy"], c["x0"], c["y0"], c["theta0"])
            if extra_axis:  # theta (P, n, K): distance of target i to its own samples
                dx = cx - tx[None, :, None]
                dy = cy - ty[None, :, None]
            else:  # theta (1, M): distance of every target to every sample -> (P, M, n)
                dx = cx[:, :, None] - tx[None, None, :]
                dy = cy[:, :, None] - ty[None, None, :]
                ok = ok[:, :, None]
            return np.where(ok, dx * dx + dy * dy, np.inf)

        h = TWO_PI / samples
        grid = np.arange(samples) * h
        dd = d2(grid[None, :], False)
        k = np.argmin(dd, axis=1)  # (P, n)
        rows, cols = np.arange(P)[:, None], np.arange(case.n)[None, :]
        f = np.stack([dd[rows, (k - 1) % samples, cols], dd[rows, k, cols], dd[rows, (k + 1) % samples, cols]], -1)
        theta = grid[k]
        for level in range(refinements + 1):
            fm, f0, fp = f[..., 0], f[..., 1], f[..., 2]
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                den = fm - 2.0 * f0 + fp
                off = np.where(np.isfinite(den) & (den > 0), 0.5 * (fm - fp) / den, 0.0)
            theta = theta + np.clip(np.nan_to_num(off), -1.0, 1.0) * h
            if level == refinements:
                break
            h = h / 6.0
            f = d2(theta[..., None] + h * np.array([-1.0, 0.0, 1.0]), True)
        sign = 1.0 if case.order == "ccw" else -1.0
        lo = case.bounds()["theta2_1"][0]
        t1 = lo + np.mod(theta[:, :1] - lo, TWO_PI)
        deltas = np.mod(sign * np.diff(theta, axis=1), TWO_PI)
        return np.concatenate([zl, t1, deltas], axis=1)

    def expand(self, zr: np.ndarray) -> np.ndarray:
        """Full internal vectors from the global search's vectors (see :attr:`reduced_dim`)."""
        zr = np.atleast_2d(np.asarray(zr, float))
        return self.project_timing(zr) if self.case.timing == "free" else zr

    def reduced_fitness(self, zr: np.ndarray) -> np.ndarray:
        """:meth:`fitness` of :meth:`expand` ``(zr)``."""
        return self.fitness(self.expand(zr))

    # -- evaluation ----------------------------------------------------------------------
    def evaluate(self, z: np.ndarray) -> Evaluation:
        """Objective and total constraint violation for a population ``z`` of shape ``(P, dim)``."""
        z = np.atleast_2d(np.asarray(z, float))
        case = self.case
        vals, th, sweeps = self.unpack(z)
        r1, r2, r3, r4 = (vals[k][:, None] for k in LENGTHS)
        cx, cy, assembled = coupler_point(
            r1, r2, r3, r4, th, case.branch, vals["rcx"][:, None], vals["rcy"][:, None],
            vals["x0"][:, None], vals["y0"][:, None], vals["theta0"][:, None])
        ex, ey = cx - case.targets[None, :, 0], cy - case.targets[None, :, 1]
        error = np.sum(ex * ex + ey * ey, axis=1)
        assembled_all = np.all(assembled, axis=1)
        viol = np.zeros(len(z))
        # positive lengths
        rmat = np.stack([vals[k] for k in LENGTHS], axis=1)
        scale = np.maximum(np.max(np.abs(rmat), axis=1), 1e-12)
        viol += np.sum(np.maximum(0.0, 1e-9 * scale[:, None] - rmat), axis=1) / scale
        # assembly at every target and along each crank sweep, in cos(theta2) units
        c_lo, c_hi = crank_cos_range(r1[:, 0], r2[:, 0], r3[:, 0], r4[:, 0])
        c_lo = np.nan_to_num(c_lo, nan=2.0, posinf=2.0, neginf=-2.0)
        c_hi = np.nan_to_num(c_hi, nan=-2.0, posinf=2.0, neginf=-2.0)
        c = np.cos(th)
        if th.shape[1] > 1:
            cmin, cmax = arc_cos_extremes(th[:, :-1], sweeps)
            cmin = np.minimum(cmin, c.min(axis=1, keepdims=True))
            cmax = np.maximum(cmax, c.max(axis=1, keepdims=True))
        else:
            cmin, cmax = c, c
        viol += np.sum(np.maximum(0.0, c_lo[:, None] - cmin) + np.maximum(0.0, cmax - c_hi[:, None]), axis=1)
        viol += np.where(assembled_all, 0.0, 1e-6)  # numerical edge cases of the interval test
        if case.grashof:
            viol += np.maximum(0.0, grashof_excess(*(vals[k] for k in LENGTHS))) / scale
            if case.grashof == "crank-rocker":
                others = np.minimum(np.minimum(vals["r1"], vals["r3"]), vals["r4"])
                viol += np.maximum(0.0, vals["r2"] - others) / scale
        if case.timing == "free":
            m = len(self.linkage_vars)
            viol += np.maximum(0.0, np.sum(z[:, m + 1:], axis=1) - TWO_PI - _TOL)
        cos_mu_motion, cos_mu_fold = _cos_transmission(r1[:, 0], r2[:, 0], r3[:, 0], r4[:, 0],
                                                       cmin, cmax, c_lo, c_hi)
        if case.transmission_angle_min_deg:
            k = np.cos(np.radians(case.transmission_angle_min_deg))
            viol += np.nan_to_num(np.maximum(0.0, cos_mu_motion - k), nan=1.0)
        if case.grashof and case.fold_margin_deg:
            k = np.cos(np.radians(case.fold_margin_deg))
            viol += np.nan_to_num(np.maximum(0.0, cos_mu_fold - k), nan=1.0)
        if case.link_ratio_max is not None:
            ratio = np.max(rmat, axis=1) / np.maximum(np.min(rmat, axis=1), 1e-300)
            viol += np.maximum(0.0, ratio - case.link_ratio_max) / case.link_ratio_max
        if case.max_size:
            viol += self._size_violation(vals)
        # bounds of the case's own variables (internal bounds hold by construction except
        # reported angles whose bounds are narrower than a turn)
        viol += self._bound_violation(z, vals, th)
        error = np.where(np.isfinite(error), error, np.inf)
        return Evaluation(error=error, violation=viol, assembled_at_all_targets=assembled_all)

    @property
    def frame(self) -> tuple[np.ndarray, float]:
        """The targets' centroid ``(2,)`` and diagonal (:func:`~mechsyn.synthesis.curves.target.principal_frame`)."""
        f = self.__dict__.get("_frame")
        if f is None:
            from mechsyn.synthesis.curves.target import principal_frame

            f = self.__dict__["_frame"] = principal_frame(self.case.targets)
        return f

    def size(self, vals: dict[str, np.ndarray]) -> np.ndarray:
        """Radius ``(P,)`` about the targets' centroid (:attr:`frame`) of the disc holding
        both frame pivots and the circles of the crank and rocker pins."""
        c = self.frame[0]
        a0 = np.hypot(vals["x0"] - c[0], vals["y0"] - c[1])
        bx = vals["x0"] + vals["r1"] * np.cos(vals["theta0"])
        by = vals["y0"] + vals["r1"] * np.sin(vals["theta0"])
        b0 = np.hypot(bx - c[0], by - c[1])
        return np.maximum(a0 + np.abs(vals["r2"]), b0 + np.abs(vals["r4"]))

    def _size_violation(self, vals: dict[str, np.ndarray]) -> np.ndarray:
        limit = self.case.max_size * max(self.frame[1], 1e-300)
        return np.maximum(0.0, self.size(vals) / limit - 1.0)

    def _bound_violation(self, z, vals, th) -> np.ndarray:
        v = np.sum(np.maximum(0.0, self.lower - z) + np.maximum(0.0, z - self.upper), axis=1)
        if self.case.timing != "prescribed":
            b = self.case.bounds()
            for i in range(self.case.n):
                lo, hi = b.get(f"theta2_{i + 1}", b["theta2_1"])
                if hi - lo < TWO_PI - 1e-12:
                    v += np.maximum(0.0, lo - th[:, i]) + np.maximum(0.0, th[:, i] - hi)
        return v

    def fitness(self, z: np.ndarray) -> np.ndarray:
        """Feasibility-first scalar score: ``f`` if feasible, else ``U + violation`` (``> f``)."""
        ev = self.evaluate(z)
        return np.where(ev.feasible & np.isfinite(ev.error), ev.error, self.penalty_base + ev.violation)

    def residuals(self, z: np.ndarray) -> np.ndarray:
        """Residual vector ``C - Cd`` (length ``2n``) for local least-squares polishing.

        Where the linkage cannot assemble, the coupler is laid along the pivots' line (its
        folded pose, :func:`~mechsyn.synthesis.fourbar.coupler_direction`) and a large
        residual proportional to the violation is appended, so a polisher is pushed back to
        feasible designs (its result is accepted only if feasible).
        """
        return self.residuals_batch(np.asarray(z, float)[None, :])[0]

    def residuals_batch(self, Z: np.ndarray) -> np.ndarray:
        """:meth:`residuals` of many designs ``Z`` (P, dim) at once: shape (P, 2n + 1)."""
        Z = np.atleast_2d(np.asarray(Z, float))
        case = self.case
        vals, th, _ = self.unpack(Z)
        r1, r2, r3, r4 = (vals[k][:, None] for k in LENGTHS)
        gx, gy, _ = coupler_point(r1, r2, r3, r4, th, case.branch, *(vals[k][:, None] for k in
                                  ("rcx", "rcy", "x0", "y0", "theta0")), folded=True)
        viol = self.evaluate(Z).violation
        return np.concatenate([gx - case.targets[:, 0], gy - case.targets[:, 1],
                               1e3 * np.sqrt(self.penalty_base) * viol[:, None]], axis=1)

    def residual_jacobian(self, z: np.ndarray) -> np.ndarray:
        """Forward-difference Jacobian of :meth:`residuals` at ``z``, (2n + 1, dim): all
        ``dim + 1`` designs in one :meth:`residuals_batch` call. Steps as SciPy's
        ``2-point`` scheme (``sqrt(eps) max(1, |z_j|)``), taken backwards at an upper
        bound."""
        z = np.asarray(z, float)
        h = np.sqrt(np.finfo(float).eps) * np.maximum(1.0, np.abs(z))
        h = np.where(z + h > self.upper, -h, h)
        Z = np.vstack([z, z + np.diag(h)])
        R = self.residuals_batch(Z)
        return ((R[1:] - R[0]) / h[:, None]).T


def _cos_transmission(r1, r2, r3, r4, cmin, cmax, c_lo, c_hi) -> tuple[np.ndarray, np.ndarray]:
    """Largest ``|cos mu|`` over the motion and at the crank's fold positions, ``(P,)`` each.

    ``cos mu = (r3^2 + r4^2 - r1^2 - r2^2 + 2 r1 r2 cos theta2) / (2 r3 r4)`` is monotone
    in ``cos theta2``, so over the motion (``cos theta2`` in ``[cmin, cmax]``, arrays
    ``(P, k)`` of the arcs) its extremes are at the interval's ends. The fold positions
    are ``theta2 = 0`` and ``pi`` (all four pivots on one line), where the crank reaches
    them (``cos theta2`` within the assembly range ``[c_lo, c_hi]``); 0 when neither.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        def cos_mu(ct):
            return (r3 ** 2 + r4 ** 2 - r1 ** 2 - r2 ** 2 + 2 * r1 * r2 * ct) / (2 * r3 * r4)

        lo = np.min(cmin, axis=1) if np.ndim(cmin) > 1 else cmin
        hi = np.max(cmax, axis=1) if np.ndim(cmax) > 1 else cmax
        motion = np.maximum(np.abs(cos_mu(lo)), np.abs(cos_mu(hi)))
        fold = np.zeros_like(motion)
        for ct in (1.0, -1.0):
            reach = (c_lo <= ct + 1e-12) & (ct - 1e-12 <= c_hi)
            fold = np.where(reach, np.maximum(fold, np.abs(cos_mu(ct))), fold)
    return motion, fold


def transmission_angles(case: PathCase, design: dict[str, Any]) -> dict[str, float | None]:
    """Worst transmission angle of a design, in degrees (``min(mu, 180 - mu)``).

    ``worst_transmission_angle_deg``: over the motion from the first target to the last;
    ``fold_distance_deg``: at the crank angles 0 and pi where the linkage would fold flat
    (0 at ``s + l = p + q``; ``None`` when the crank reaches neither).

    Examples
    --------
    A change-point four-bar (1 + 3 = 2 + 2) folds flat at theta2 = 0:

    >>> case = PathCase.from_dict({"targets": [[0, 1], [0, 2]], "timing": {"type":
    ...     "prescribed", "theta2": [1.0, 2.0]}, "variables": [{"name": k, "lower": 0,
    ...     "upper": 5} for k in ("r1", "r2", "r3", "r4", "rcx", "rcy")]})
    >>> out = transmission_angles(case, {"r1": 3, "r2": 1, "r3": 2, "r4": 2, "rcx": 0, "rcy": 0})
    >>> round(out["fold_distance_deg"], 9), out["worst_transmission_angle_deg"] > 20
    (0.0, True)
    """
    prob = PathProblem(case)
    z = prob.internal(design)[None, :]
    vals, th, sweeps = prob.unpack(z)
    r1, r2, r3, r4 = (vals[k] for k in LENGTHS)
    c = np.cos(th)
    if th.shape[1] > 1:
        cmin, cmax = arc_cos_extremes(th[:, :-1], sweeps)
        cmin, cmax = np.minimum(cmin, c.min(axis=1, keepdims=True)), np.maximum(cmax, c.max(axis=1, keepdims=True))
    else:
        cmin, cmax = c, c
    c_lo, c_hi = crank_cos_range(r1, r2, r3, r4)
    motion, fold = _cos_transmission(r1, r2, r3, r4, cmin, cmax, c_lo, c_hi)
    reach = any(bool((c_lo[0] <= ct + 1e-12) & (ct - 1e-12 <= c_hi[0])) for ct in (1.0, -1.0))

    def deg(cm):
        return float(np.degrees(np.arccos(np.clip(cm, 0.0, 1.0)))) if np.isfinite(cm) else float("nan")

    return {"worst_transmission_angle_deg": deg(motion[0]),
            "fold_distance_deg": deg(fold[0]) if reach else None}


def evaluate_design(case: PathCase, design: dict[str, Any]) -> dict[str, Any]:
    """Recompute a design's objective and constraint state, by the case's conventions.

    ``design`` holds the case's variable names (``theta2`` may be given as a list). Returns
    ``error``, ``feasible``, ``violation``, ``assembled_at_all_targets``, the coupler
    points ``path`` and the worst transmission angles (:func:`transmission_angles`).
    """
    prob = PathProblem(case)
    z = prob.internal(design)
    ev = prob.evaluate(z[None, :])
    vals, th, _ = prob.unpack(z[None, :])
    pose = fourbar_position(*(vals[k][:, None] for k in LENGTHS), th, branch=case.branch,
                            rcx=vals["rcx"][:, None], rcy=vals["rcy"][:, None], x0=vals["x0"][:, None],
                            y0=vals["y0"][:, None], theta0=vals["theta0"][:, None])
    return {
        "error": float(ev.error[0]), "feasible": bool(ev.feasible[0]), "violation": float(ev.violation[0]),
        "assembled_at_all_targets": bool(ev.assembled_at_all_targets[0]), "path": pose.C[0],
        "theta2": th[0], **transmission_angles(case, design),
    }
