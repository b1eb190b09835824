"""Spatial kinematics: positions, orientations, velocities and accelerations of a spatial
mechanism (R, P, C, U, S, H pairs) over a sweep of its drives, by continuation from the
drawn assembly.

The engine (:class:`SpatialEngine`, ``name = "spatial"``) answers for ``kind: spatial``
files. Its equations are those of :mod:`mechsyn.kinematics.spatial_model` (each pair as
exactly its class of scalar constraints on the poses of its two links, the drives as one
more equation each); it

* starts from the drawn assembly (the inputs are measured from it: an R or H input is the
  pair's rotation from the drawn position in degrees, right-handed about the file's axis;
  a P input its slide along the axis in the file's length unit), reaches the sweep's row
  nearest the drawn input and goes outwards from there, so the branch is the drawn one;
* predicts each row from the previous one to second order (the velocity and acceleration
  twists per unit input step, through the exponential of a twist) and corrects by Newton
  steps ``δξ = -J⁺ g`` (the minimum-norm least-squares step with the pseudo-inverse of the
  Jacobian at the regular rank ``r``), accepting a pose when every residual is under
  ``1e-12`` of the length scale; the step is halved where the corrector fails or would move
  further than the predictor did (a branch jump), down to ``1/4096`` of a row;
* takes velocities ``ξ = J⁺ b`` (``b``: the input rates on the drive rows) and accelerations
  ``ξ̇ = -J⁺ γ`` from the same Jacobian in twist form, never by differencing positions;
* handles idle mobilities (a rod spinning between two ball joints, a Delta's bars): they
  are the null space of ``J``, and the minimum-norm steps and rates leave them at rest
  (the idle links keep their drawn spin). Drives that leave a motion of a joint point or
  a named point free are refused at the start (the motion would be arbitrary);
* reports, never hides: the closure residual of every row (``residual``, in units of the
  length scale), rows where the Jacobian's regular rank drops (``singular``: its ``r``-th
  singular value below ``1e-8`` of the largest; rates NaN there), the end of an assembled
  range (``dead point``: the drive cannot go on), reassembly after a gap and rows not
  assembled (NaN).

References
----------
.. [1] E. L. Allgower and K. Georg, *Introduction to Numerical Continuation Methods*, SIAM,
   2003, ch. 2 and 6 (predictor-corrector continuation, step-length control).
.. [2] J. M. McCarthy and G. S. Soh, *Geometric Design of Linkages*, 2nd ed., Springer, 2011.
.. [3] C. M. Gosselin and J. Angeles, "Singularity analysis of closed-loop kinematic
   chains", *IEEE Trans. Robotics and Automation* 6(3), 281-290, 1990 (the singularities
   as rank drops of the loop-closure Jacobian).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import PointMotion, resolve_points
from mechsyn.kinematics.spatial_model import (SpatialModel, compile_spatial, convective, frame, jacobian,
                                              measures, move, residual, wrap)
from mechsyn.kinematics.spatial_result import LinkPose, SpatialSimulation
from mechsyn.model.mechanism import Mechanism

__all__ = ["SpatialEngine", "simulate_spatial", "RANK_TOL", "CLOSURE_TOL"]

#: A singular value below this fraction of the largest is a lost direction (rank decisions).
RANK_TOL = 1e-8
#: Residual (in units of the length scale) at which the corrector accepts a pose.
NEWTON_TOL = 1e-12
#: Largest residual of an accepted row that the result may carry (the issue's bound).
CLOSURE_TOL = 1e-9
MAX_HALVINGS = 12


@dataclass
class _Local:
    """The Jacobian at a pose and its pseudo-inverse at rank ``r``."""

    J: np.ndarray
    U: np.ndarray
    s: np.ndarray
    Vt: np.ndarray
    r: int

    @property
    def ratio(self) -> float:
        """``r``-th singular value over the largest (0: the rank has dropped)."""
        return float(self.s[self.r - 1] / self.s[0]) if self.r and len(self.s) >= self.r and self.s[0] > 0 else 0.0

    def solve(self, b: np.ndarray) -> np.ndarray:
        r = self.r
        return self.Vt[:r].T @ ((self.U[:, :r].T @ b) / self.s[:r])


@dataclass
class _State:
    """An assembled pose: link poses, unwrapped H angles, the model's frame and Jacobian."""

    R: np.ndarray
    p: np.ndarray
    href: np.ndarray
    F: Any
    lin: _Local
    g: np.ndarray


class _Tracker:
    """Predictor-corrector continuation of one model (see the module doc)."""

    def __init__(self, M: SpatialModel, rank: int | None = None) -> None:
        self.M = M
        self.m_c = M.n_constraints
        self.rank = rank
        self.halvings = 0

    def local(self, F: Any) -> _Local:
        J = jacobian(self.M, F)
        U, s, Vt = np.linalg.svd(J, full_matrices=False)
        if self.rank is None:
            self.rank = int(np.count_nonzero(s > RANK_TOL * s[0])) if s.size and s[0] > 0 else 0
        return _Local(J, U, s, Vt, self.rank)

    def state(self, R: np.ndarray, p: np.ndarray, href: np.ndarray, target: np.ndarray) -> _State:
        F = frame(self.M, R, p)
        th, s = measures(self.M, R, p)
        g = residual(self.M, F, th, s, href, target)
        if self.M.helix:
            ia = np.array([h[0] for h in self.M.helix])
            href = href + wrap(th[ia] - href)
        return _State(R, p, href, F, self.local(F), g)

    def rates(self, st: _State, du: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Twists of the links per ``du`` of the inputs (first and second derivatives)."""
        b = np.zeros(len(st.g))
        b[self.m_c:] = du
        x1 = st.lin.solve(b)
        x2 = st.lin.solve(-convective(self.M, st.F, x1))
        return x1, x2

    def correct(self, R: np.ndarray, p: np.ndarray, href: np.ndarray, target: np.ndarray, lin: _Local,
                limit: float, chord: int = 8, full: int = 8) -> tuple[np.ndarray, np.ndarray] | None:
        """Newton corrections (chord steps with ``lin``, then fresh Jacobians) to the pose
        of the inputs ``target``; None when they fail or move further than ``limit``."""
        moved = 0.0
        last = np.inf
        for it in range(chord + full):
            F = frame(self.M, R, p)
            th, s = measures(self.M, R, p)
            g = residual(self.M, F, th, s, href, target)
            err = float(np.abs(g).max(initial=0.0))
            if err < NEWTON_TOL:
                return R, p
            if it >= chord or err > 0.5 * last:  # chord steps stalled: a fresh Jacobian
                dx = -np.linalg.lstsq(jacobian(self.M, F), g, rcond=RANK_TOL)[0]
            else:
                dx = -lin.solve(g)
            last = err
            moved += float(np.abs(dx).max(initial=0.0))
            if moved > limit:
                return None
            R, p = move(R, p, dx)
        return None

    def step(self, st: _State, du: np.ndarray, target: np.ndarray) -> _State | None:
        x1, x2 = self.rates(st, du)
        R, p = move(st.R, st.p, x1 + 0.5 * x2)
        size = float(np.abs(x1).max(initial=0.0))
        out = self.correct(R, p, st.href, target, st.lin, limit=0.5 * size + 1e-9)
        return None if out is None else self.state(*out, st.href, target)

    def advance(self, st: _State, u0: np.ndarray, u1: np.ndarray) -> tuple[_State, bool, _State]:
        """From ``st`` at inputs ``u0`` to ``u1``, halving the step at trouble: (the state at
        ``u1`` or the furthest reached, whether ``u1`` was reached, the last state)."""
        t, h = 0.0, 1.0
        while t < 1.0:
            h = min(h, 1.0 - t)
            nxt = self.step(st, h * (u1 - u0), u0 + (t + h) * (u1 - u0))
            if nxt is None:
                if h < 0.5 ** MAX_HALVINGS:
                    return st, False, st
                h *= 0.5
                self.halvings += 1
                continue
            st, t = nxt, t + h
            h = min(1.0, 2 * h)
        return st, True, st

    def reassemble(self, st: _State, target: np.ndarray) -> _State | None:
        """Newton from the last assembled pose at the inputs ``target`` (after a gap)."""
        out = self.correct(st.R, st.p, st.href, target, st.lin, limit=np.inf, chord=0, full=30)
        return None if out is None else self.state(*out, st.href, target)


class SpatialEngine:
    """The spatial engine behind :func:`mechsyn.simulate`: answers for ``kind: spatial``
    mechanisms (None for planar ones, which other engines answer).

    Examples
    --------
    >>> import mechsyn as ms
    >>> s = SpatialEngine().sweep(ms.examples.load("bennett"), {"R1": ms.input_grid(0, 90, 45)})
    >>> s.engine, s.point("R3").shape, bool(s.residual.max() < 1e-9)
    ('spatial', (3, 3), True)
    """

    name = "spatial"

    def sweep(self, mech: Mechanism, inputs: dict[str, Any], speeds: dict[str, float] | None = None,
              points: list[str] | None = None, progress: Any = None, **_: Any) -> SpatialSimulation | None:
        if mech.kind != "spatial":
            return None
        return simulate_spatial(mech, inputs, speeds=speeds, points=points, progress=progress)


def _check_inputs(mech: Mechanism, inputs: dict[str, Any]) -> dict[str, np.ndarray]:
    if not inputs:
        raise MechsynInputError("no input given", field="inputs",
                                hint="give the driven joint's values, e.g. R1=0:360:1 on the command line")
    out = {}
    for jid, v in inputs.items():
        try:
            j = mech.joint(jid)
        except KeyError:
            raise MechsynInputError(f"no joint {jid!r} to drive", source=mech.source, field="inputs",
                                    hint="one of " + ", ".join(j.id for j in mech.joints)) from None
        if j.type not in ("R", "P", "H"):
            raise MechsynInputError(f"joint {jid} is a {j.type} pair: only R, P and H pairs take an input",
                                    source=mech.source, field="inputs", hint="drive an R, P or H pair")
        out[jid] = np.atleast_1d(np.asarray(v, float))
    sizes = {len(v) for v in out.values()}
    if len(sizes) != 1:
        raise MechsynInputError("the inputs have different numbers of values", field="inputs",
                                hint="give every driven joint as many values")
    for jid, v in out.items():
        if not np.all(np.isfinite(v)):
            raise MechsynInputError(f"input {jid} has a value that is not a number", field="inputs")
    return out


def _drives(mech: Mechanism, inputs: dict[str, np.ndarray]) -> tuple[str, ...]:
    """The input joints, then the file's other driven joints (held at their drawn value)."""
    return tuple(inputs) + tuple(j.id for j in mech.joints if j.actuated and j.id not in inputs)


def _input_matrix(M: SpatialModel, inputs: dict[str, np.ndarray]) -> np.ndarray:
    """(N, drives) targets in model units: radians, or lengths over the scale."""
    N = len(next(iter(inputs.values())))
    U = np.zeros((N, len(M.drives)))
    for k, (jid, kind, _) in enumerate(M.drives):
        if jid in inputs:
            U[:, k] = np.radians(inputs[jid]) if kind == "angle" else inputs[jid] / M.scale
    return U


def _check_determined(M: SpatialModel, st: _State, pts: dict[str, tuple[str, np.ndarray]]) -> None:
    """Refuse drives that leave a joint point or a named point free to move."""
    lin = st.lin
    N = lin.Vt[lin.r:].T  # the motions with every drive at rest
    if N.size == 0:
        return
    X = N.reshape(M.n, 6, -1)
    worst = 0.0
    checks = [(M.index(j.links[k]), M.local(j.point)) for j in M.mech.joints if j.point is not None
              for k in (0, 1)]
    checks += [(M.index(link), M.local(at)) for link, at in pts.values()]
    for i, x in checks:
        if i < M.n:
            w, v = X[i, :3], X[i, 3:]
            worst = max(worst, float(np.abs(v + np.cross(w.T, x).T).max(initial=0.0)))
    if worst > 1e-6:
        raise MechsynInputError(
            f"with the drives {', '.join(d[0] for d in M.drives)} at rest the mechanism can still move "
            f"({N.shape[1]} free motion(s), not only idle spins): its motion is not determined",
            source=M.mech.source, field="joints[].actuated",
            hint="mark more joints actuated: true (each needs an input or keeps its drawn value)")


def simulate_spatial(mech: Mechanism, inputs: dict[str, Any], speeds: dict[str, float] | None = None,
                     points: list[str] | None = None, progress: Any = None) -> SpatialSimulation:
    """Kinematics of a spatial mechanism over a sweep of its drives (see the module doc).

    ``inputs``: joint id -> values, measured from the drawn assembly (degrees for R and H,
    the file's length unit for P); the file's other driven joints stay as drawn.
    ``speeds``: input rates (rad/s, length/s; default 1). ``points``: named points or
    joint ids to report (default: the file's points, else every joint with a point).

    Examples
    --------
    >>> import mechsyn as ms
    >>> s = ms.simulate(ms.examples.load("rssr"), {"A": ms.input_grid(0, 60, 30)})
    >>> s.engine, s.point("C").shape, bool(s.assembled.all())
    ('spatial', (3, 3), True)
    """
    inputs = _check_inputs(mech, inputs)
    M = compile_spatial(mech, _drives(mech, inputs))
    if points is None and not mech.points:
        points = [j.id for j in mech.joints if j.point is not None]
    pts = resolve_points(mech, points)
    sp = np.array([float((speeds or {}).get(d[0], 1.0)) for d in M.drives])
    sp = np.where([d[1] == "slide" for d in M.drives], sp / M.scale, sp)
    tr = _Tracker(M)
    n = M.n
    R0, p0 = np.tile(np.eye(3), (n + 1, 1, 1)), np.zeros((n + 1, 3))
    start = tr.state(R0, p0, np.zeros(len(M.helix)), np.zeros(len(M.drives)))
    _check_determined(M, start, pts)
    U = _input_matrix(M, inputs)
    rows = _sweep_rows(tr, start, U, sp, progress)
    return _result(mech, M, tr, inputs, sp, pts, U, rows, start)


@dataclass
class _Rows:
    """Per-row arrays of a sweep (link poses and twists in model units)."""

    R: np.ndarray
    p: np.ndarray
    xi: np.ndarray
    xid: np.ndarray
    ok: np.ndarray
    res: np.ndarray
    ratio: np.ndarray
    theta: np.ndarray
    slide: np.ndarray
    events: list


def _empty_rows(M: SpatialModel, N: int) -> _Rows:
    n = M.n
    nan = np.nan
    return _Rows(np.full((N, n, 3, 3), nan), np.full((N, n, 3), nan), np.full((N, 6 * n), nan),
                 np.full((N, 6 * n), nan), np.zeros(N, bool), np.full(N, nan), np.full(N, nan),
                 np.full((N, M.angles.size), nan), np.full((N, M.slides.size), nan), [])


def _store(tr: _Tracker, out: _Rows, k: int, st: _State, sp: np.ndarray, U: np.ndarray) -> None:
    M = tr.M
    out.R[k], out.p[k] = st.R[:-1], st.p[:-1]
    out.ok[k] = True
    out.res[k] = float(np.abs(st.g[:tr.m_c]).max(initial=0.0))
    out.ratio[k] = st.lin.ratio
    th, s = measures(M, st.R, st.p)
    out.theta[k], out.slide[k] = th, s
    if st.lin.ratio < RANK_TOL:
        out.events.append({"index": k, "kind": "singular", "input": _input_dict(M, U[k]),
                           "message": f"singular configuration: the Jacobian's rank drops below {st.lin.r} "
                                      f"(singular value ratio {st.lin.ratio:.2g}); rates not defined here (null)"})
        return
    x1, x2 = tr.rates(st, sp)
    out.xi[k], out.xid[k] = x1, x2


def _input_dict(M: SpatialModel, u: np.ndarray) -> dict[str, float]:
    return {jid: float(np.degrees(v)) if kind == "angle" else float(v * M.scale)
            for (jid, kind, _), v in zip(M.drives, u)}


def _sweep_rows(tr: _Tracker, start: _State, U: np.ndarray, sp: np.ndarray, progress: Any) -> _Rows:
    """Every row from the drawn assembly: to the nearest row, then outwards both ways."""
    N = U.shape[0]
    out = _empty_rows(tr.M, N)
    k0 = int(np.argmin(np.abs(U).max(axis=1)))
    zero = np.zeros(U.shape[1])
    st, ok, _ = tr.advance(start, zero, U[k0])
    if not ok:
        out.events.append({"index": k0, "kind": "not assembled", "input": _input_dict(tr.M, U[k0]),
                           "message": "the drawn assembly cannot be moved to this input (a dead point or a "
                                      "singular configuration lies between)"})
        if progress is not None:
            progress(N)
        return out
    _store(tr, out, k0, st, sp, U)
    for order in (range(k0 + 1, N), range(k0 - 1, -1, -1)):
        _walk(tr, out, st, U, k0, list(order), sp)
    if progress is not None:
        progress(N)
    out.events.sort(key=lambda e: e["index"])
    return out


def _walk(tr: _Tracker, out: _Rows, st: _State, U: np.ndarray, k0: int, order: list[int],
          sp: np.ndarray) -> None:
    """Continue from row ``k0`` (state ``st``) through the rows of ``order``."""
    prev, gap = k0, False
    for k in order:
        if gap:
            nxt = tr.reassemble(st, U[k])
            if nxt is None:
                continue
            out.events.append({"index": k, "kind": "reassembled", "input": _input_dict(tr.M, U[k]),
                               "message": "assembles again after a gap (Newton from the last assembled pose; "
                                          "the assembly branch may differ from the drawn one)"})
            st, gap = nxt, False
        else:
            nxt, ok, last = tr.advance(st, U[prev], U[k])
            if not ok:
                out.events.append({"index": k, "kind": "dead point", "input": _input_dict(tr.M, U[k]),
                                   "message": "a limit of the working range: the drive cannot reach this value "
                                              f"from the previous row (singular value ratio "
                                              f"{last.lin.ratio:.2g} where the continuation stopped)"})
                st, gap = last, True
                continue
            st = nxt
        _store(tr, out, k, st, sp, U)
        prev = k


def _result(mech: Mechanism, M: SpatialModel, tr: _Tracker, inputs: dict[str, np.ndarray], sp: np.ndarray,
            pts: dict, U: np.ndarray, rows: _Rows, start: _State) -> SpatialSimulation:
    """The result in the file's units."""
    L, c = M.scale, M.centre
    ok = rows.ok
    X = rows.xi.reshape(len(ok), M.n, 6)
    Xd = rows.xid.reshape(len(ok), M.n, 6)
    links = {}
    for i, name in enumerate(M.links):
        Ri, pi = rows.R[:, i], rows.p[:, i]
        t = c - np.einsum("kij,j->ki", Ri, c) + L * pi
        links[name] = LinkPose(Ri, t, X[:, i, :3], Xd[:, i, :3])
    pm = {}
    for name, (link, at) in pts.items():
        pm[name] = _point_motion(M, rows, X, Xd, link, M.local(at))
    joints = {jid: np.degrees(_unwrap(rows.theta[:, k], ok)) for k, jid in enumerate(M.angle_joints)}
    joints.update({jid: rows.slide[:, k] * L for k, jid in enumerate(M.slide_joints) if jid not in joints})
    notes = []
    idle = M.n * 6 - start.lin.r
    if idle:
        notes.append(f"{idle} idle motion(s) with the drives at rest (e.g. a rod spinning between ball joints): "
                     "held at their drawn position (minimum-norm steps and rates)")
    if tr.halvings:
        notes.append(f"the continuation step was halved {tr.halvings} time(s) where the corrector had trouble")
    bad = ok & (rows.res > CLOSURE_TOL)
    if bad.any():
        notes.append(f"closure residual above {CLOSURE_TOL:g} of the length scale at {int(bad.sum())} row(s)")
    types = {jid: mech.joint(jid).type for jid in inputs}
    speeds = {d[0]: float(v * (L if d[1] == "slide" else 1.0)) for d, v in zip(M.drives, sp) if d[0] in inputs}
    return SpatialSimulation(
        mechanism=mech.name, inputs=inputs, input_types=types, speeds=speeds, assembled=ok, points=pm,
        links=links, joints=joints, residual=rows.res, singular_ratio=rows.ratio, length_scale=L,
        rank=start.lin.r, idle=idle, events=rows.events, notes=notes, model=M)


def _point_motion(M: SpatialModel, rows: _Rows, X: np.ndarray, Xd: np.ndarray, link: str,
                  x0: np.ndarray) -> PointMotion:
    L, c = M.scale, M.centre
    i = M.index(link)
    N = len(rows.ok)
    if i == M.n:
        P = np.tile(c + L * x0, (N, 1))
        P[~rows.ok] = np.nan
        z = np.where(rows.ok[:, None], 0.0, np.nan) * np.ones((N, 3))
        return PointMotion(P, z, z.copy(), link)
    x = np.einsum("kij,j->ki", rows.R[:, i], x0) + rows.p[:, i]
    w, v, wd, vd = X[:, i, :3], X[:, i, 3:], Xd[:, i, :3], Xd[:, i, 3:]
    xd = v + np.cross(w, x)
    xdd = vd + np.cross(wd, x) + np.cross(w, xd)
    return PointMotion(c + L * x, L * xd, L * xdd, link)


def _unwrap(a: np.ndarray, ok: np.ndarray) -> np.ndarray:
    out = a.copy()
    good = np.flatnonzero(ok)
    if len(good):
        out[good] = np.unwrap(a[good])
        k = good[np.argmin(np.abs(out[good]))]  # the turn nearest the drawn assembly
        out[good] -= 2 * np.pi * np.round(out[k] / (2 * np.pi))
    return out
