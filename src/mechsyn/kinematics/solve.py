"""Position, velocity and acceleration analysis by Newton's method and linear solves.

Positions: Newton-Raphson on ``Phi(q, u) = 0`` with the analytic Jacobian (square
systems: LU; redundant constraints: least squares). A sweep over input values is a
continuation: each step is predicted from the velocities (``Phi_q dq = B du``),
corrected by Newton and halved when Newton fails or jumps, so the solution follows the
file's assembly branch. Where the step cannot be made smaller and still converge, the
mechanism cannot be assembled (a dead point: ``Phi_q`` singular at the limit).

Velocities: ``Phi_q q' = B u'``; accelerations: ``Phi_q q'' = gamma + B u''``
(Haug 1989, eqs. 3.3.9-3.3.11), both with the LU factors of ``Phi_q``.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np
import scipy.linalg as sla

from mechsyn.errors import MechsynInputError, OverActuatedError
from mechsyn.kinematics.groups import decompose
from mechsyn.kinematics.plane import cross
from mechsyn.kinematics.positions import solve_positions
from mechsyn.kinematics.refill import joint_points
from mechsyn.kinematics.sweep import Event, Sweep, connecting_path, driver_kinds, turns
from mechsyn.kinematics.system import PlanarSystem
from mechsyn.progress import ProgressCallback, report
from mechsyn.structure.drives import DriveCheck, excess_drives

__all__ = ["Sweep", "assemble", "sweep", "check_mobility", "newton", "drawn_checks"]


def _lu(J: np.ndarray) -> tuple | None:
    """The LU factors of a square ``J`` (an exactly singular one too: a zero pivot, no
    warning), None when ``J`` is not square or LAPACK refuses it."""
    if J.shape[0] != J.shape[1]:
        return None
    try:
        with warnings.catch_warnings():  # a singular J: the callers' least-squares answer
            warnings.simplefilter("ignore", sla.LinAlgWarning)
            return sla.lu_factor(J, check_finite=False)
    except (sla.LinAlgError, ValueError):
        return None


def _solve_lin(J: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """``J x = rhs`` by LU, else (not square, singular) in the least-squares sense."""
    lu = _lu(J)
    x = None if lu is None else sla.lu_solve(lu, rhs, check_finite=False)
    return x if x is not None and np.all(np.isfinite(x)) else sla.lstsq(J, rhs, check_finite=False,
                                                                           lapack_driver="gelsy")[0]


def newton(S: PlanarSystem, q: np.ndarray, u: np.ndarray, tol: float | None = None,
           max_iter: int = 12, polish: bool = False) -> tuple[np.ndarray, bool]:
    """Newton-Raphson from ``q`` (n,) at inputs ``u`` (n_inputs,); returns (q, converged).

    ``polish``: one more step after convergence where the Jacobian is well conditioned
    (the sweep's positions then agree with the closed form to round-off). ``tol`` bounds
    the residual of every equation relative to its size (lengths over the mechanism's
    size, angles in radians): the decisions do not change when the mechanism is scaled."""
    tol = tol if tol is not None else 1e-12
    q = q.copy()
    u2 = u[None]
    prev = np.inf
    for _ in range(max_iter):
        r = S.residual(q[None], u2)[0]
        norm = _norm(S, r)
        if not np.isfinite(norm):
            return q, False
        if norm < tol:
            if polish and norm > 1e-3 * tol:  # one more step: the error squares (a polish, not a new solve)
                dq = _solve_lin(S.jacobian(q[None])[0], -r)
                if np.all(np.isfinite(dq)) and float(np.abs(dq).max()) <= 1e2 * norm:  # well conditioned
                    q2 = q + dq
                    if _norm(S, S.residual(q2[None], u2)[0]) <= norm:
                        q = q2
            return q, True
        if norm > 4 * prev and prev < 1e-3:
            return q, False
        prev = norm
        dq = _solve_lin(S.jacobian(q[None])[0], -r)
        if not np.all(np.isfinite(dq)):
            return q, False
        q += dq
    return q, bool(_norm(S, S.residual(q[None], u2)[0]) < tol * 10)


def _norm(S: PlanarSystem, r: np.ndarray) -> float:
    """The largest residual of the equations ``r`` (m,), each relative to its size."""
    return float(np.abs(r / S.row_scale).max()) if r.size else 0.0


def _rel_step(S: PlanarSystem, dq: np.ndarray) -> float:
    """The largest change of ``dq`` (the first unknowns, or all n) relative to the
    mechanism's size (lengths) or in radians (angles)."""
    return float(np.abs(dq / S.col_scale[:len(dq)]).max()) if dq.size else 0.0


def check_mobility(S: PlanarSystem, q: np.ndarray | None = None) -> dict:
    """Rank of ``Phi_q`` at ``q``: free coordinates beyond the inputs, redundant constraints."""
    q = S.q0 if q is None else q
    rank = _rank(S.unit_jacobian(S.jacobian(q[None])[0]))[0]  # dimensionless: the same rank at any scale
    return {"unknowns": S.n, "equations": S.m, "rank": rank, "free": S.n - rank,
            "redundant": S.m - rank}


def _rank(J: np.ndarray) -> tuple[int, float]:
    """The rank of a dimensionless ``Phi_q`` and the tolerance it is counted with: its
    singular values above 1e-9 of the largest (and of 1)."""
    sv = np.linalg.svd(J, compute_uv=False) if J.size else np.zeros(0)
    tol = 1e-9 * max(1.0, float(sv.max()) if sv.size else 1.0)
    return int(np.sum(sv > tol)), tol


def drive_check(S: PlanarSystem, given: tuple = ()) -> DriveCheck | None:
    """The drivers of ``S`` against its mobility at the drawn configuration (None there when
    it is singular: the rank at a dead point is not the mechanism's): the drivers given an
    input (``given``, in order) are taken first, then the others in the file's order; a
    driver whose rate the ones before it fix is in excess (:func:`excess_drives` on the
    drivers' rows of ``Phi_q`` times a basis of the motions its other rows allow)."""
    key = ("drive check", given)
    if key in S.cache:
        return S.cache[key]
    out = None
    if S.drivers and not singular_configuration(S):
        J = S.unit_jacobian(S.jacobian(S.q0[None])[0])
        B = S.input_matrix()
        closure = ~np.any(B != 0, axis=1)
        tol = _rank(J)[1]
        _, s, vt = np.linalg.svd(J[closure], full_matrices=True)
        motions = vt[int(np.sum(s > tol)):].T  # the rates every loop closure allows
        names = [d.joint for d in S.drivers]
        rows = {d: list(np.flatnonzero(B[:, k] != 0)) for k, d in enumerate(names)}
        order = [d for d in given if d in rows] + [d for d in names if d not in given]
        out = DriveCheck(names, motions.shape[1], excess_drives(J @ motions, rows, order, tol), "kinematics")
    S.cache[key] = out
    return out


def require_drives_given(S: PlanarSystem, given: tuple) -> None:
    """Raise :class:`~mechsyn.errors.OverActuatedError` when a driver without an input is in
    excess (:func:`drive_check`): held at its drawn value, it would stop every other drive."""
    if len(S.drivers) <= len(given):
        return
    check = drive_check(S, tuple(given))
    idle = [d for d in (check.excess if check else []) if d not in given]
    if idle:
        names = ", ".join(idle)
        raise OverActuatedError(check.text(f"give {names} an input too, or drop `actuated: true` on {names}"),
                                check=check, source=S.mech.source or None, field="inputs")


def generic_free(S: PlanarSystem, q: np.ndarray | None = None, trials: int = 3) -> int:
    """Free coordinates of the mechanism in general position: the rank of ``Phi_q`` at
    configurations near ``q`` (a dead-centre or folded file configuration lowers the rank
    at ``q`` only)."""
    q = S.q0 if q is None else q
    rng = np.random.default_rng(0)
    best = S.n
    for _ in range(trials):
        dq = rng.normal(size=S.n) * 1e-3
        dq[:3 * len(S.links)] *= np.where(np.arange(3 * len(S.links)) % 3 == 2, 1.0, S.scale)
        best = min(best, check_mobility(S, q + dq)["free"])
    return best


def singular_configuration(S: PlanarSystem, q: np.ndarray | None = None) -> bool:
    """``Phi_q`` loses rank at ``q`` though the mechanism is determined in general position."""
    if q is None:
        memo = S.cache.get("singular_drawn")
        if memo is None:
            memo = S.cache["singular_drawn"] = singular_configuration(S, S.q0)
        return memo
    return check_mobility(S, q)["free"] > 0 and generic_free(S, q) == 0


def drawn_checks(S: PlanarSystem, plan: Any) -> bool:
    """The checks of :func:`assemble` at the drawn configuration (assembled, determined,
    singular or not) from the groups of a plan of R drives and RRR dyads, without the
    rank machinery; True when they are settled (the verdict of
    :func:`singular_configuration` is then kept with ``S``), False when the general
    path must decide.

    Each link's dimensions are read from its drawn joint points, so the drawn pose closes
    every group by construction: what is left is each group's shape. An RRR group with
    ends ``A``, ``C`` and middle joint ``B`` (``e1 = B - A``, ``e2 = B - C``) is folded
    (the Jacobian's block of the group, and so ``Phi_q``, loses rank: Haug 1989, sec. 3.4)
    when ``|e1 x e2| / (|e1| |e2|)``, the sine of the angle at ``B``, is zero. Only clear
    cases are settled here: the sine below 1e-13 (singular) or the sine times the shorter
    link above 1e-5 of the mechanism's size (regular), links not shorter than 1e-3 of it;
    a degenerate link (coincident joints), a group near a fold and every other plan go to
    the general test, so the answers and messages are those of :func:`assemble`. A group
    whose middle joint is a double joint (two R pairs at one point) is tested the same way
    at that point.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.kinematics.analysis import compile_plan
    >>> kp = compile_plan(ms.examples.load("crank_rocker"), inputs=("A",))
    >>> drawn_checks(kp.system, kp.groups), singular_configuration(kp.system)
    (True, False)
    """
    memo = S.cache.get("drawn_checks")
    if memo is not None and memo[0] is plan:
        return memo[1]
    settled = _drawn_checks(S, plan)
    S.cache["drawn_checks"] = (plan, settled)
    return settled


def _drawn_checks(S: PlanarSystem, plan: Any) -> bool:
    groups = _drawn_groups(S, plan)
    if groups is None:
        return False
    pts = joint_points(S)
    singular = False
    short_link, near_fold = 1e-3 * S.scale, 1e-5 * S.scale
    for ia, ib, ic in groups:
        (ax, ay), (bx, by), (cx, cy) = pts[ia], pts[ib], pts[ic]
        e1x, e1y, e2x, e2y = bx - ax, by - ay, bx - cx, by - cy
        L1, L2 = math.hypot(e1x, e1y), math.hypot(e2x, e2y)
        short = L2 if L2 < L1 else L1  # min(L1, L2)
        if not short >= short_link:  # degenerate or short link, NaN: the general test
            return False
        sine = abs(e1x * e2y - e1y * e2x) / (L1 * L2)
        if sine <= 1e-13:
            singular = True
        elif sine * short < near_fold:
            return False
    S.cache["singular_drawn"] = singular
    return True


def _drawn_groups(S: PlanarSystem, plan: Any) -> list | None:
    """The file indices of the joints (ends, middle, end) of every RRR group of ``plan``,
    or None when :func:`drawn_checks` does not apply (a plan other than R drives and RRR
    dyads, or not as many equations as unknowns): the topology's part of the checks,
    kept with the programs the systems of one topology share."""
    def build() -> list | None:
        ok = plan is not None and S.m == S.n and all(s.kind in ("drive_R", "RRR") and set(s.data) <= {"double"}
                                                     for s in plan.steps)
        index = {j.id: k for k, j in enumerate(S.mech.joints)}
        return [tuple(index[j] for j in s.joints) for s in plan.steps if s.kind == "RRR"] if ok else None

    return S.topology.product("drawn checks", build, plan)


def _require_determined(S: PlanarSystem, q: np.ndarray) -> None:
    """Raise when the inputs leave free coordinates at ``q`` (a singular file configuration,
    a dead centre or folded, is not: the sweep reports it)."""
    free = check_mobility(S, q)["free"]
    if free > 0 and generic_free(S, q) > 0:
        passive = [j for j, mode in S.vll.items() if mode == "passive"]
        hint = "mark more joints actuated"
        if passive:
            hint = (f"lock the free VLL ({', '.join(f'--vll {p}=locked' for p in passive)}) or give its "
                    f"length as an input (--input {passive[0]}=...)")
        raise MechsynInputError(
            f"the mechanism has {free} free coordinate(s) beyond its {len(S.drivers)} input(s): "
            "its motion is not determined by the inputs", source=S.mech.source or "<mechanism>", hint=hint)


def assemble(S: PlanarSystem, u: np.ndarray | None = None) -> np.ndarray:
    """The configuration at inputs ``u`` reached from the file's assembled configuration.

    The file's configuration is first made exact by Newton, then followed continuously
    from its own input values to ``u`` (so the file chooses the assembly branch).
    """
    memo = S.cache.get("assembled")
    if memo is not None:  # the checks below depend on the system only: done once per system
        return memo.copy() if u is None else _reach(S, memo, u)
    u_asm = np.array([d.assembled for d in S.drivers])
    q, ok = newton(S, S.q0, u_asm, max_iter=30)
    src = S.mech.source or "<mechanism>"
    if not ok:
        worst = worst_joint(S, S.q0, u_asm)
        raise MechsynInputError(
            f"the joint points of the file do not assemble (largest error at joint {worst})", source=src,
            hint="check the joint points: each link's joints must keep their distances")
    moved = _rel_step(S, (q - S.q0)[:3 * len(S.links)]) if S.links else 0.0
    if moved > 1e-6:
        raise MechsynInputError(
            f"the file's configuration is not assembled: joint {worst_joint(S, S.q0, u_asm)} is off "
            f"by up to {moved * S.scale:.3g}", source=src,
            hint="give joint points of one consistent configuration")
    _require_determined(S, q)
    S.cache["assembled"] = q.copy()
    if u is None:
        return q
    return _reach(S, q, u)


def _reach(S: PlanarSystem, q: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Follow the drawn configuration ``q`` to the inputs ``u``."""
    u_asm = np.array([d.assembled for d in S.drivers])
    qq = _track(S, q, u_asm, np.asarray(u, float), depth=14)
    if qq is None:
        raise MechsynInputError("the mechanism cannot reach the requested input from its file configuration",
                                field="inputs")
    return qq


def worst_joint(S: PlanarSystem, q: np.ndarray, u: np.ndarray) -> str:
    """The joint whose equations are furthest from holding at ``q`` with the inputs ``u``."""
    r = np.abs(S.residual(q[None], u[None])[0] / S.row_scale)
    best, worst = -1.0, "?"
    for row, con in S.blocks():
        v = float(r[row:row + con.rows].max())
        if v > best:
            best, worst = v, con.joint
    return worst


#: The smallest pivot of the dimensionless Jacobian's LU, over its largest, below which the
#: configuration is taken as singular (round-off of a pivot that is zero in exact arithmetic).
SINGULAR_PIVOT = 1e-13


def _factor(S: PlanarSystem, q: np.ndarray) -> tuple[object, np.ndarray, float, float]:
    """LU of ``Phi_q`` at q, ``dq/du`` (n, k), det sign and a singularity measure.

    ``Phi_q`` is factored made dimensionless (:meth:`PlanarSystem.unit_jacobian`), so the
    measure, min |U_ii| / max |U_ii| of its LU factors (0 at a singular point), is the
    same at any scale of the mechanism.
    """
    J = S.unit_jacobian(S.jacobian(q[None])[0])
    B = S.input_matrix() / S.row_scale[:, None]
    lu = _lu(J)
    if lu is not None:
        X = sla.lu_solve(lu, B, check_finite=False)
        d = np.abs(np.diag(lu[0]))
        piv = int(np.sum(lu[1] != np.arange(len(lu[1]))))
        sign = float(np.prod(np.sign(np.diag(lu[0]))) * (-1) ** piv)
        # a pivot within round-off of zero is a singular point, whatever the LAPACK's last
        # bits (0 with one, 3e-17 and a tangent of 1e16 with another): the least-squares
        # tangent below, the same everywhere
        if np.all(np.isfinite(X)) and d.min() > SINGULAR_PIVOT * d.max():
            return lu, X * S.col_scale[:, None], sign, float(d.min() / max(d.max(), 1e-300))
    X = sla.lstsq(J, B, check_finite=False)[0] * S.col_scale[:, None]
    sv = np.linalg.svd(J, compute_uv=False)
    return (J,), X, 0.0, float(sv[min(J.shape) - 1] / max(sv.max(), 1e-300)) if sv.size else 1.0


def _solve_with(S: PlanarSystem, fac: tuple, rhs: np.ndarray) -> np.ndarray:
    """``Phi_q x = rhs`` with the factors of :func:`_factor` (of the dimensionless ``Phi_q``)."""
    rhs = rhs / S.row_scale
    if len(fac) == 2:
        return sla.lu_solve(fac, rhs, check_finite=False) * S.col_scale
    return sla.lstsq(fac[0], rhs, check_finite=False)[0] * S.col_scale


def _settle(S: PlanarSystem, q: np.ndarray, u: np.ndarray, fac: tuple) -> tuple[np.ndarray, tuple]:
    """Near a singular configuration (pivot ratio below 1e-3), Newton's iterations continued
    to round-off: at a fold Newton converges only linearly, so the sweep's tolerance leaves
    the position about the square root of it away (a pivot ratio near 1e-6 at an exact dead
    point, rates of 1e5 presented as numbers); continued until the residual stops
    decreasing, the pivot ratio is as small as floats can resolve, and a sample at a
    singular position is recognised as one (the closed form's test: within 1e-12 of it)."""
    if fac[3] >= 1e-3:
        return q, fac
    u2 = u[None]
    best = _norm(S, S.residual(q[None], u2)[0])
    for _ in range(60):
        if best == 0.0:
            break
        dq = _solve_lin(S.jacobian(q[None])[0], -S.residual(q[None], u2)[0])
        if not np.all(np.isfinite(dq)) or _rel_step(S, dq) > 1e-4:
            break
        q2 = q + dq
        r2 = _norm(S, S.residual(q2[None], u2)[0])
        if r2 >= best:
            break
        q, best = q2, r2
    return q, _factor(S, q)


def _step_ok(S: PlanarSystem, q_old: np.ndarray, q_new: np.ndarray, q_pred: np.ndarray) -> bool:
    """Reject a Newton correction much larger than the predicted step (a branch jump)."""
    nl = 3 * len(S.links)
    step = np.abs(q_pred - q_old)[:nl]
    corr = np.abs(q_new - q_pred)[:nl]
    scale = np.where(np.arange(nl) % 3 == 2, 1.0, S.scale)
    return bool(np.max(corr / scale) <= max(0.25 * np.max(step / scale), 1e-6))


def _track(S: PlanarSystem, q: np.ndarray, ua: np.ndarray, ub: np.ndarray, depth: int = 10,
           X: np.ndarray | None = None) -> np.ndarray | None:
    """Follow the branch from (q, ua) to ub; None when it cannot be assembled.

    ``X = dq/du`` at q (computed when not given) predicts the step.
    """
    du = ub - ua
    if X is None:
        X = _factor(S, q)[1]
    q_pred = q + X @ du
    q_new, ok = newton(S, q_pred, ub, polish=True)
    if ok and _step_ok(S, q, q_new, q_pred):
        return q_new
    if depth == 0:
        return None
    um = ua + du / 2
    qm = _track(S, q, ua, um, depth - 1, X)
    return None if qm is None else _track(S, qm, um, ub, depth - 1)


def _extrapolate(hist: list, u: np.ndarray) -> np.ndarray:
    """Predict the configuration at ``u`` by the polynomial through the last (up to three)
    configurations of the run, in the arc length of the inputs (the smooth branch)."""
    u_last = hist[-1][0]
    step = u - u_last
    norm = float(np.linalg.norm(step))
    if norm == 0.0:
        return hist[-1][1]
    direction = step / norm
    s = [float(direction @ (h[0] - u_last)) for h in hist[-3:]]

    def weight(a: int) -> float:  # the Lagrange basis polynomial of node a at the arc length norm
        return math.prod((norm - sb) / (s[a] - sb) if s[a] != sb else 0.0 for b, sb in enumerate(s) if b != a)

    return sum(weight(a) * h[1] for a, h in enumerate(hist[-3:]))


def _continue(S: PlanarSystem, hist: list, u: np.ndarray) -> np.ndarray | None:
    """The next configuration of the run ``hist`` [(u, q, factor)] at ``u`` on the branch
    whose velocity is continuous.

    The tangent predictor (``dq/du`` at the last configuration) is used while the last
    configuration is regular and no singular point lies in the step; when the last
    configuration is singular (its tangent is not unique) or ``det Phi_q`` changes sign
    within the step (a change or branch point was crossed, where Newton may land on either
    branch), the prediction is the polynomial through the last configurations of the run,
    which continues the smooth branch.
    """
    u0, q0, (_, X0, det0, sig0) = hist[-1]
    regular = sig0 >= 1e-6
    nxt = _track(S, q0, u0, u, X=X0) if regular else None
    if len(hist) < 2:  # no run to extrapolate: the tangent's answer, or off the singular start
        return nxt if nxt is not None or regular else _leave_singular(S, q0, X0, u0, u)
    if nxt is not None and _factor(S, nxt)[2] * det0 >= 0:
        return nxt
    cand, ok = newton(S, _extrapolate(hist, u), u, max_iter=40, polish=True)
    return cand if ok else nxt


def _leave_singular(S: PlanarSystem, q0: np.ndarray, X0: np.ndarray, u0: np.ndarray,
                    u: np.ndarray) -> np.ndarray | None:
    """The first configuration at ``u`` from a singular one ``q0`` (a file drawn at a dead
    centre or folded): Newton from the tangent's guess, else from guesses along the
    Jacobian's null direction, on its positive side first (near a fold the configuration
    moves as the square root of the input's step, so the guesses are that far out). Which
    of the branches meeting at ``q0`` is taken is arbitrary (the sweep's notes say so); the
    rule only makes it the same whatever the linear algebra's pivoting (an exactly singular
    LU gave a usable tangent with one LAPACK and none with another)."""
    pred = q0 + X0 @ (u - u0)
    cand, ok = newton(S, pred, u, max_iter=40)
    if ok:
        return cand
    unit = np.array([1.0 if d.type == "R" else S.scale for d in S.drivers])
    reach = float(np.sqrt(np.max(np.abs(u - u0) / unit, initial=0.0)))
    v = np.linalg.svd(S.unit_jacobian(S.jacobian(q0[None])[0]))[2][-1]
    v *= np.sign(v[np.argmax(np.abs(v))])
    dq = v * S.col_scale
    dq *= S.scale / max(float(np.linalg.norm(dq)), 1e-300)
    for guess in (pred + reach * dq, pred - reach * dq, pred + 0.3 * reach * dq, pred - 0.3 * reach * dq):
        cand, ok = newton(S, guess, u, max_iter=40)
        if ok:
            return cand
    return None


def _elbows(S: PlanarSystem, q: np.ndarray) -> np.ndarray:
    """Assembly-mode signature of a configuration: at every R pair joining two moving links
    that each carry another joint, the side to which the second link turns from the first
    (the sign of ``(P_J - P_a) x (P_b - P_J)``; for a dyad, its assembly mode)."""
    mech, out = S.mech, []

    def glob(link: str, jid: str) -> np.ndarray:  # the joint's point on the link at q
        return S.point(q[None], S.index(link), S.to_local(link, mech.joint(jid).point))[0]

    def other(j: Any, link: str) -> str | None:  # the link's first joint other than j
        return next((k.id for k in mech.joints_of(link) if k.id != j.id), None)

    for j in mech.joints:
        a, b = j.links
        if j.type == "R" and mech.ground not in (a, b) and (oa := other(j, a)) and (ob := other(j, b)):
            P = glob(a, j.id)
            out.append(np.sign(cross(P - glob(a, oa), glob(b, ob) - P)))
    return np.array(out)


def _nearest_mode(S: PlanarSystem, cands: list, u: np.ndarray, q_drawn: np.ndarray, det: float) -> np.ndarray:
    """Of configurations at ``u``, the one in the assembly mode nearest the drawn one.

    When the mechanism splits into dyads, each dyad's drawn mode gives the configuration
    directly (closed form, polished by Newton). Otherwise: the candidate (with those found
    along the nearest-singular direction of each) whose elbow signature
    (:func:`_elbows`) matches the drawn one most, then whose ``det Phi_q`` has the drawn
    sign."""
    plan = decompose(S)
    if plan is not None:
        u_asm = np.array([d.assembled for d in S.drivers])
        _, sig = solve_positions(S, plan, u_asm[None])
        with np.errstate(invalid="ignore"):
            qc = solve_positions(S, plan, u[None], sigmas=sig)[0][0]
        if np.all(np.isfinite(qc)):
            qc, good = newton(S, qc, u, max_iter=10)
            if good:
                return qc
    pool = list(cands)
    for c in cands:
        pool.extend(_other_mode(S, c, u))
    ref = _elbows(S, q_drawn)

    def score(c: np.ndarray) -> tuple:
        return (int(np.sum(_elbows(S, c) == ref)), _factor(S, c)[2] * det > 0)

    return max(pool, key=score)


def _other_mode(S: PlanarSystem, q: np.ndarray, u: np.ndarray) -> list:
    """Configurations at ``u`` other than ``q``, searched from ``q`` along the direction in
    which ``Phi_q`` is nearest singular (where two assembly modes meet near a fold, they
    differ along it)."""
    J = S.unit_jacobian(S.jacobian(q[None])[0])
    v = np.linalg.svd(J)[2][-1]
    v = v / max(float(np.abs(v).max()), 1e-300) * S.col_scale  # lengths in the mechanism's size
    for a in (0.05, 0.2, 0.5, 1.0):
        for sgn in (1.0, -1.0):
            c, good = newton(S, q + sgn * a * v, u, max_iter=30)
            if good and _rel_step(S, c - q) > 1e-6:
                return [c]
    return []


def _crossing(S: PlanarSystem, q: np.ndarray, ua: np.ndarray, ub: np.ndarray, det: float,
              iters: int = 40) -> np.ndarray:
    """Bisection for the input between ``ua`` (configuration ``q``, ``det Phi_q`` of sign
    ``det``) and ``ub`` where ``det Phi_q`` changes sign along the branch (a change or
    branch point); ``ub`` when the branch cannot be followed there. Next to the singular
    point the sign of ``det`` is decided by round-off, so the result is accurate to about
    1e-8 rad, not to the closed form's 1e-13."""
    size = np.array([1.0 if d.type == "R" else S.scale for d in S.drivers])
    for _ in range(iters):
        if np.abs((ub - ua) / size).max() < 1e-13:
            break
        um = (ua + ub) / 2
        qm = _track(S, q, ua, um, depth=4)
        if qm is None:
            return ub
        if _factor(S, qm)[2] * det > 0:
            q, ua = qm, um
        else:
            ub = um
    return (ua + ub) / 2


def _limit(S: PlanarSystem, q: np.ndarray, ua: np.ndarray, ub: np.ndarray,
           iters: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """Bisection for the last input between ua (assembled) and ub (not) that assembles."""
    for _ in range(iters):
        um = (ua + ub) / 2
        qm = _track(S, q, ua, um, depth=3)
        if qm is None:
            # near the fold Newton converges only linearly: give it room (no branch check,
            # both branches meet there)
            qm, ok = newton(S, q, um, max_iter=60)
            if not ok:
                qm = None
        if qm is None:
            ub = um
        else:
            q, ua = qm, um
    return ua, q


def sweep(S: PlanarSystem, inputs: np.ndarray, speeds: np.ndarray | None = None,
          progress: ProgressCallback | None = None, refine_limits: bool = True) -> Sweep:
    """Positions, velocities, accelerations over input values (N, n_inputs), by continuation.

    ``speeds`` are the input rates (rad/s or length/s; default 1 for every input).
    Events (``dead point``: the input where assembly ends, refined by bisection;
    ``reassembled``: the mechanism assembles again after a gap, possibly on another
    branch; ``singular``: ``det Phi_q`` changes sign between two steps, a branch point
    was crossed) are listed in ``Sweep.events``. ``progress(state)``
    (:class:`mechsyn.progress.Progress`, stage ``"sweep"``) is called after each row: rows
    done of all.
    """
    inputs = np.atleast_2d(np.asarray(inputs, float))
    N, k = inputs.shape
    if k != len(S.drivers):
        raise ValueError(f"expected {len(S.drivers)} input columns, got {k}")
    # an R input differing from the file's angle by whole turns is the same configuration:
    # start from the equivalent value nearest the file's (a full turn could cross a toggle)
    kinds, _ = driver_kinds(S)
    shift = np.array(turns(kinds, [d.assembled for d in S.drivers], inputs[0].tolist()))
    if np.any(shift):
        return _sweep_shifted(S, inputs, shift, speeds, progress, refine_limits)
    speeds = np.ones(k) if speeds is None else np.asarray(speeds, float)
    q_start = assemble(S)
    q, qd, qdd = np.full((3, N, S.n), np.nan)  # positions, velocities, accelerations
    det_sign, sig = np.full((2, N), np.nan)  # the sign of det Phi_q and the pivot ratio
    out = (q, qd, qdd, det_sign, sig)
    events: list[Event] = []
    u_asm = np.array([d.assembled for d in S.drivers])
    hist, cur = _approach(S, q_start, u_asm, inputs[0], refine_limits, events)
    drawn_det = hist[0][2][2]
    cur_u = inputs[0]
    last_good: tuple[np.ndarray, np.ndarray] | None = (q_start, u_asm)
    for i in range(N):
        u = inputs[i]
        if cur is not None and i > 0:
            nxt = _continue(S, hist, u)
            if nxt is None:
                ul = _limit(S, cur, cur_u, u)[0] if refine_limits else cur_u
                events.append(Event(i, "dead point", "assembly ends: the Jacobian becomes singular (dead point / "
                                                     "limit of the working range)", ul.tolist()))
                last_good = (cur, cur_u)
            cur = nxt
            cur_u = u
        elif cur is None and last_good is not None:
            got = _reassemble(S, out, inputs, i, q_start, last_good[0], drawn_det, speeds, refine_limits, events)
            if got is not None:
                cur, cur_u, hist = got, u, [(u, got, _factor(S, got))]
        if cur is not None:
            cur, hist = _store(S, out, inputs, i, cur, hist, speeds, refine_limits, events)
        report(progress, i + 1, N, "sweep")
    assembled = np.all(np.isfinite(q), axis=1)
    for i in np.flatnonzero(np.isfinite(sig) & (sig < 1e-6)).tolist():
        events.append(Event(i, "singular", input=inputs[i].tolist(),
                       message=f"near-singular configuration (pivot ratio {sig[i]:.1e}): a change, branch or "
                                  "dead point; the branch may switch here and positions are accurate only to "
                                  "about the square root of the solver tolerance"))
    events.sort(key=lambda e: e.index)
    return Sweep(S, inputs, speeds, q, qd, qdd, assembled, events)


def _sweep_shifted(S: PlanarSystem, inputs: np.ndarray, shift: np.ndarray, speeds: np.ndarray | None,
                   progress: ProgressCallback | None, refine_limits: bool) -> Sweep:
    """The sweep of inputs shifted by whole turns ``shift`` next to the file's values,
    given back at the inputs' own values."""
    sw = sweep(S, inputs - shift, speeds, progress, refine_limits)
    sw.inputs = inputs
    # a link driven from the frame takes the input's own turn count (same positions)
    for con in S.cons:
        if con.role == "drive" and con.kind == "angle" and shift[con.driver]:
            if con.a < 0 and con.b >= 0:
                sw.q[:, 3 * con.b + 2] += shift[con.driver]
            elif con.b < 0 and con.a >= 0:
                sw.q[:, 3 * con.a + 2] -= shift[con.driver]
    sw.events = [e.with_(input=(np.asarray(e.input) + shift).tolist()) for e in sw.events]
    return sw


def _approach(S: PlanarSystem, q_start: np.ndarray, u_asm: np.ndarray, u_first: np.ndarray,
              refine_limits: bool, events: list) -> tuple[list, np.ndarray | None]:
    """From the drawn configuration to the first input on the smooth branch: the run's
    history and the configuration there (None, with a dead-point event, when it cannot
    be reached)."""
    hist = [(u_asm, q_start, _factor(S, q_start))]
    nxt = None
    kinds, _ = driver_kinds(S)  # the path in steps of 5 degrees (R) or 5 % of the size (P)
    path = connecting_path(kinds, S.scale, u_asm.tolist(), u_first.tolist(), step=5.0, max_rows=2000)[1:]
    for u in list(path) + [u_first]:
        nxt = _continue(S, hist, u)
        if nxt is None:
            break
        hist.append((u, nxt, _factor(S, nxt)))
    if nxt is not None:
        return hist, hist[-1][1]
    if refine_limits:
        ul, _ = _limit(S, hist[-1][1], hist[-1][0], u_first)
        events.append(Event(0, "dead point", "the mechanism cannot move from its file configuration to the first "
                            "input", ul.tolist(), before_sweep=True))
    return hist, None


def _fill(S: PlanarSystem, out: tuple, j: int, qj: np.ndarray, f: tuple, speeds: np.ndarray) -> None:
    """Row ``j`` of the sweep's arrays from a configuration and its factors."""
    q, qd, qdd, det_sign, sig = out
    q[j] = qj
    fac, X, det_sign[j], sig[j] = f
    qd[j] = X @ speeds
    qdd[j] = _solve_with(S, fac, S.gamma(qj[None], qd[j][None])[0])
    if sig[j] < 1e-6:  # singular: the rates are not defined here
        qd[j] = qdd[j] = np.nan


def _reassemble(S: PlanarSystem, out: tuple, inputs: np.ndarray, i: int, q_start: np.ndarray,
                q_last: np.ndarray, drawn_det: float, speeds: np.ndarray, refine_limits: bool,
                events: list) -> np.ndarray | None:
    """After a gap: the configuration at row ``i`` in the mode nearest the drawn one (of
    those Newton reaches from the drawn and from the last one), the branch followed
    backwards into the gap as far as it assembles; None when none is found."""
    u = inputs[i]
    cands = [c for c, good in (newton(S, guess, u, max_iter=15) for guess in (q_start, q_last)) if good]
    if not cands:
        return None
    cand = _nearest_mode(S, cands, u, q_start, drawn_det)
    q = out[0]
    bq, bu, j = cand, u, i - 1
    while j >= 0 and not np.isfinite(q[j, 0]):
        nb = _track(S, bq, bu, inputs[j])
        if nb is None:
            break
        nb, f_j = _settle(S, nb, inputs[j], _factor(S, nb))
        _fill(S, out, j, nb, f_j, speeds)
        bq, bu, j = nb, inputs[j], j - 1
    if refine_limits and j >= 0:
        ul, _ = _limit(S, bq, bu, inputs[j])
        events.append(Event(j + 1, "dead point", "assembly starts again here: the other limit of a working range",
                            ul.tolist()))
    events.append(Event(j + 1, "reassembled", "assembles again after a gap, in the assembly mode of the drawn "
                        "configuration (the mode nearest the drawn one)", bu.tolist()))
    return cand


def _store(S: PlanarSystem, out: tuple, inputs: np.ndarray, i: int, cur: np.ndarray, hist: list,
           speeds: np.ndarray, refine_limits: bool, events: list) -> tuple[np.ndarray, list]:
    """Row ``i`` of the sweep from the configuration ``cur`` (settled near a singular
    point), the run's history extended, a det-sign change reported as a crossing."""
    q, det_sign, sig = out[0], out[3], out[4]
    u = inputs[i]
    cur, f = _settle(S, cur, u, _factor(S, cur))
    _fill(S, out, i, cur, f, speeds)
    if i > 0 and np.isfinite(q[i - 1, 0]):
        hist.append((u, cur, f))
        hist = hist[-3:]
    if (i > 0 and np.isfinite(det_sign[i - 1]) and det_sign[i] * det_sign[i - 1] < 0
            and sig[i - 1] >= 1e-6 and sig[i] >= 1e-6):  # (a singular sample is reported itself)
        uc = _crossing(S, q[i - 1], inputs[i - 1], u, det_sign[i - 1]) if refine_limits else u
        events.append(Event(i, "singular", "det(Phi_q) changed sign: a singular (branch/change) point was "
                            "crossed between this input and the previous (at the input given)", uc.tolist(),
                            crossed=True))
    return cur, hist
