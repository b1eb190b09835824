"""Driver-R + RRR chains in closed form with every group's assembly mode by row: the
kernel's program (:mod:`mechsyn.kinematics.kernel`, the one closed-form pass) run with
the tracked engines' signs (:func:`tracked_pass`: signs given by row, or chosen group by
group from each group's discriminant as the pass reaches it), the links' poses and
continuous angles from its record (:func:`chain_poses`), and :func:`solve_all` (the
positions and rates of any plan: this chain where it applies, else the generic steps of
:mod:`mechsyn.kinematics.positions` with batched linear solves for the rates).

RRR: ``B = A + f d + sigma g R90 d`` with ``d = C - A`` (the kernel's circle
intersection); rates ``omega_1 = (v_C - v_A) . e2 / (e1 x e2)``, ``omega_2 = (v_C -
v_A) . e1 / (e1 x e2)`` with ``e1 = B - A``, ``e2 = B - C``, and likewise the
accelerations (Artobolevsky, *Theory of Mechanisms and Machines*, ch. 4).
"""

from __future__ import annotations

import numpy as np

from mechsyn.kinematics import kernel
from mechsyn.kinematics.groups import Plan
from mechsyn.kinematics.positions import TrackedPositions, solve_positions
from mechsyn.kinematics.system import PlanarSystem

__all__ = ["chain_poses", "solve_all", "tracked_pass"]


def solve_all(S: PlanarSystem, plan: Plan, inputs: np.ndarray, speeds: np.ndarray,
              chunk: int = 20000, tracked: TrackedPositions | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, velocities, accelerations (N, n) for all inputs (closed form where possible).

    ``tracked``: the sweep's positions and modes from
    :func:`mechsyn.kinematics.tracking.solve_tracked` (the drawn branch followed through
    bifurcations); without it every group keeps its drawn mode.
    """
    inputs = np.atleast_2d(np.asarray(inputs, float))
    if plan.closed_form_rates:
        return chain_poses(S, plan, inputs, *tracked_pass(S, plan, inputs, speeds,
                                                          tracked.sigmas if tracked is not None else None)[:3])
    q = tracked.q if tracked is not None else solve_positions(S, plan, inputs)[0]
    ok = np.all(np.isfinite(q), axis=1)
    qd = np.full_like(q, np.nan)
    qdd = np.full_like(q, np.nan)
    idx = np.flatnonzero(ok)
    for start in range(0, len(idx), chunk):
        sel = idx[start:start + chunk]
        qd[sel], qdd[sel] = S.rates(q[sel], speeds)
    return q, qd, qdd


def tracked_pass(S: PlanarSystem, plan: Plan, U: np.ndarray, speeds: np.ndarray, sigmas: list | None) -> tuple:
    """The kernel's record ``(C, W, AL, D)`` (:func:`mechsyn.kinematics.kernel.run`) of
    the chain over the input rows ``U`` (M, k) with every RRR group's assembly mode by
    row from ``sigmas`` (by plan step): an array, the signs by row; a callable (a
    :data:`~mechsyn.kinematics.groups.Chooser` of the tracked engines), called in the
    order of the steps with the group's normalised discriminant on every row (the
    upstream groups in the signs already chosen: one pass of the kernel per chooser) and
    the group's drawn mode, giving the signs; None or a number: the drawn mode."""
    prog = kernel.program(S, plan)
    fp, groups = prog[1], prog[0][4]
    picks = [] if sigmas is None else [(g, k) for g, k in enumerate(groups)
                                        if isinstance(sigmas[k], np.ndarray) or callable(sigmas[k])]
    SG = np.repeat(fp[:, 2].real[:, None], U.shape[0], axis=1) if picks else None  # (steps, M): drawn modes
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        for g, k in picks:
            sg = sigmas[k]
            if callable(sg):
                sg = sg(kernel.run(prog, U, speeds, 0.0, signs=SG)[3][g], float(fp[k, 2].real))
            SG[k] = sg
        return kernel.run(prog, U, speeds, 0.0, signs=SG)[:4]


def chain_poses(S: PlanarSystem, plan: Plan, U: np.ndarray, C: np.ndarray, W: np.ndarray, AL: np.ndarray) -> tuple:
    """Pose coordinates (origin, angle) and their rates ``q, qd, qdd`` (N, n) of the first
    N rows (``U`` (N, k)) of a kernel's record (:func:`tracked_pass`): every link's
    origin and rates as the kernel placed them, its angle continuous from the drawn one
    (:func:`mechsyn.kinematics.kernel.link_poses`, the regular pass's); NaN rows where
    the chain is not assembled, NaN rates where they are not finite (a singular
    configuration: a group folded flat)."""
    N = U.shape[0]
    folds = not np.isfinite(C[0, :, :N]).all()  # (one run when assembled throughout, else run by run)
    q, qd, qdd, *_ = kernel.link_poses(S, plan, (C, W, AL), U, None, folds)
    q, qd, qdd = q.T, qd.T, qdd.T
    bad = ~(np.isfinite(qd).all(axis=1) & np.isfinite(qdd).all(axis=1))
    if not folds and bad.any():  # at a singular configuration the position exists but the rates do not
        qd[bad] = qdd[bad] = np.nan
    return q, qd, qdd
