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
from mechsyn.kinematics.groups import Plan, cons_of, geometry_memo
from mechsyn.kinematics.positions import TrackedPositions, continuous_angles, solve_positions
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
    (:func:`_link_angles`); NaN rows where the chain is not assembled, NaN rates where
    they are not finite (a singular configuration: a group folded flat)."""
    N, nl = U.shape[0], C.shape[1]
    q, qd, qdd = np.full((3, S.n, N), np.nan)  # component-major (returned transposed)
    Z = C[0, :, :N]
    for a, c in ((q, C[1]), (qd, C[2]), (qdd, C[3])):
        a[0:3 * nl:3], a[1:3 * nl:3] = c[:, :N].real, c[:, :N].imag
    qd[2:3 * nl:3], qdd[2:3 * nl:3] = W[:, :N], AL[:, :N]
    ok = np.all(np.isfinite(Z), axis=0)
    with np.errstate(invalid="ignore"):
        _link_angles(S, plan, U, Z.real, Z.imag, ok, q[2:3 * nl:3])
    q, qd, qdd = q.T, qd.T, qdd.T
    if not ok.all():
        for a in (q, qd, qdd):
            a[~ok] = np.nan
    bad = ~(np.all(np.isfinite(qd), axis=1) & np.all(np.isfinite(qdd), axis=1))
    if bad.any():  # at a singular configuration the position exists but the rates do not
        qd[bad] = np.nan
        qdd[bad] = np.nan
    return q, qd, qdd


def frame_driven_links(S: PlanarSystem, plan: Plan) -> dict[int, tuple[int, float]]:
    """Links turned by a frame driver: link -> (driver index, sign of the input), kept
    in the system's memo for the plan (a sweep's angles of these links are the inputs)."""
    memo = geometry_memo(S)
    hit = memo.get(("drive_links", id(plan)))
    if hit is not None and hit[0] is plan:
        return hit[1]
    out = {}
    for step in plan.steps:
        if step.kind == "drive_R" and step.known[0] < 0:
            con = next(c for c in cons_of(S, step.joints[0]) if c.role == "drive")
            out[step.links[0]] = (con.driver, 1.0 if con.b == step.links[0] else -1.0)
    memo[("drive_links", id(plan))] = (plan, out)
    return out


def _link_angles(S: PlanarSystem, plan: Plan, U: np.ndarray, cos: np.ndarray, sin: np.ndarray,
                 ok: np.ndarray, out: np.ndarray) -> None:
    """Continuous angles of the chain's links into ``out`` (nl, N) from their rotations
    ``cos``, ``sin`` (nl, N): the links of frame drivers take the input itself, the
    others ``atan2`` made continuous (:func:`continuous_angles`; ``ok``: the rows
    assembled)."""
    drive_links, others, ref = _angle_plan(S, plan)
    N = out.shape[1]
    for i, (k, sgn) in drive_links.items():
        np.multiply(U[:N, k], sgn, out=out[i])
    if not isinstance(others, slice) and not others:
        return
    # atan2 only for the links not driven directly (a range of links: into out itself)
    ang = np.arctan2(sin[others, :N], cos[others, :N], out=out[others] if isinstance(others, slice) else None)
    if ok.any():
        continuous_angles(ang, ref, ok, None, fresh=True)
    if not isinstance(others, slice):
        out[others] = ang


def _angle_plan(S: PlanarSystem, plan: Plan) -> tuple:
    """The links turned by frame drivers, the others (a slice when they are a range)
    and their drawn angles (m, 1), kept with the system; the links (the topology's):
    the :class:`~mechsyn.kinematics.topology.Topology`'s product ``"angles"``, which a
    refilled geometry shares (:func:`~mechsyn.kinematics.refill.with_geometry`)."""
    memo = geometry_memo(S)
    key = ("angles", id(plan))
    hit = memo.get(key)
    if hit is None or hit[0] is not plan:
        drive_links, others, cols = S.topology.product("angles", lambda: _angle_links(S, plan), plan)
        hit = memo[key] = (plan, (drive_links, others, S.q0[cols][:, None]))
    return hit[1]


def _angle_links(S: PlanarSystem, plan: Plan) -> tuple:
    """The links turned by frame drivers, the others (a slice when they are a range) and
    the columns of their angles in ``q``."""
    drive_links = frame_driven_links(S, plan)
    others = [i for i in range(len(S.links)) if i not in drive_links]
    cols = [3 * i + 2 for i in others]
    if others and others == list(range(others[0], others[-1] + 1)):
        others = slice(others[0], others[-1] + 1)
    return drive_links, others, cols
