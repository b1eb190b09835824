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
* goes by blocks of rows (:mod:`mechsyn.kinematics.spatial_track`): predicts every row of
  a block from its first pose to second order (the velocity and acceleration twists along
  the input step, through the exponential of a twist) and corrects all rows at once by
  Newton steps ``δξ = -J⁺ g`` (the minimum-norm least-squares step with the pseudo-inverse
  of the Jacobian at the regular rank ``r``), accepting a pose when every residual is under
  ``1e-12`` of the length scale and the corrector moved it less than half its predictor's
  step (else a branch jump); blocks shorten after trouble, down to one row, whose step is
  halved down to ``1/4096`` of a row;
* takes velocities ``ξ = J⁺ b`` (``b``: the input rates on the drive rows) and accelerations
  ``ξ̇ = -J⁺ γ`` from the same Jacobian in twist form, never by differencing positions;
* handles idle mobilities (a rod spinning between two ball joints, a Delta's bars): they
  are the null space of ``J``, and the minimum-norm steps and rates leave them at rest
  (the idle links keep their drawn spin). Drives that leave a motion of a joint point or
  a named point free are refused at the start (the motion would be arbitrary);
* reports, never hides: the closure residual of every row (``residual``, in units of the
  length scale), rows where the Jacobian's regular rank drops (``singular``: its ``r``-th
  singular value below ``1e-8`` of the largest; rates NaN there), singular configurations
  passed between rows (``singular`` with ``crossed``:
  :func:`~mechsyn.kinematics.spatial_track.crossings`), the end of an assembled
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

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from mechsyn.errors import EngineDeclined, MechsynInputError
from mechsyn.kinematics.simulation import PointMotion, resolve_points
from mechsyn.kinematics.spatial_model import SpatialModel, compile_spatial
from mechsyn.kinematics.spatial_track import RANK_TOL, State, Tracker, crossings, walk
from mechsyn.kinematics.spatial_result import LinkPose, SpatialSimulation
from mechsyn.kinematics.sweep import Event, by_row
from mechsyn.kinematics.system import build_system
from mechsyn.model.mechanism import Mechanism
from mechsyn.structure.screws import as_spatial

__all__ = ["SpatialEngine", "simulate_spatial", "planar_as_spatial", "RANK_TOL", "CLOSURE_TOL"]

#: Largest residual of an accepted row that the result may carry (the issue's bound).
CLOSURE_TOL = 1e-9


class SpatialEngine:
    """The spatial engine behind :func:`mechsyn.simulate`: every ``kind: spatial``
    mechanism, and a planar mechanism of R and P pairs as its 3-D equivalent
    (:func:`planar_as_spatial`), so that it can check the planar engines.

    Examples
    --------
    >>> import mechsyn as ms
    >>> s = SpatialEngine().simulate(ms.examples.load("bennett"), {"R1": ms.input_grid(0, 90, 45)})
    >>> s.engine, s.point("R3").shape, bool(s.residual.max() < 1e-9)
    ('spatial', (3, 3), True)
    >>> p = SpatialEngine().simulate(ms.examples.load("crank_rocker"), {"A": [60.0, 90.0]})
    >>> p.point("M").shape, bool(abs(p.point("M")[:, 2]).max() == 0.0)
    ((2, 3), True)
    """

    name = "spatial"

    def simulate(self, mech: Mechanism, inputs: dict[str, Any], speeds: dict[str, float] | None = None,
                 points: list[str] | None = None, progress: Any = None, **_: Any) -> SpatialSimulation:
        if mech.kind == "spatial":
            return simulate_spatial(mech, inputs, speeds=speeds, points=points, progress=progress)
        spatial, zero = planar_as_spatial(mech, tuple(inputs))
        values = {jid: np.asarray(v, float) for jid, v in inputs.items()}
        res = simulate_spatial(spatial, {jid: v - zero[jid] for jid, v in values.items()}, speeds=speeds,
                               points=points, progress=progress)
        events = [e.with_(input={j: v + zero[j] for j, v in e.input.items()}) for e in res.events]
        return replace(res, inputs={jid: np.atleast_1d(v) for jid, v in values.items()}, events=events)


def planar_as_spatial(mech: Mechanism, inputs: tuple[str, ...]) -> tuple[Mechanism, dict[str, float]]:
    """A planar mechanism of R and P pairs as a spatial one
    (:func:`mechsyn.structure.screws.as_spatial`: points at ``z = 0``, R axes along ``z``)
    and the planar value of each driven joint in the drawn configuration (degrees for R,
    lengths for P): a planar input ``u`` is the spatial engine's ``u - zero`` (its inputs
    are measured from the drawn assembly), so an input value is the same pose in both.
    Anything else is an :class:`~mechsyn.errors.EngineDeclined`."""
    other = next((j for j in mech.joints if j.type not in ("R", "P")), None)
    if other is not None:
        raise EngineDeclined("spatial", mech.name, f"joint {other.id} is a {other.type} pair; it takes planar "
                                                   "mechanisms of R and P pairs only")
    vll = next((j for j in mech.joints if j.vll), None)
    if vll is not None:
        raise EngineDeclined("spatial", mech.name, f"joint {vll.id} is a VLL ({vll.vll}); it takes plain R and "
                                                   "P pairs only")
    drivers = build_system(mech).drivers
    zero = {d.joint: float(np.degrees(d.assembled)) if d.type == "R" else float(d.assembled) for d in drivers}
    for jid in inputs:
        if jid not in zero:
            raise MechsynInputError(f"joint {jid!r} is not driven", source=mech.source, field="inputs",
                                    hint="driven joints: " + (", ".join(zero) or "(none)"))
    return as_spatial(mech), zero


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
            raise MechsynInputError(f"joint {jid} ({j.type} pair) cannot take an input: only R, P and H pairs do",
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


def _check_determined(M: SpatialModel, st: State, pts: dict[str, tuple[str, np.ndarray]]) -> None:
    """Refuse drives that leave a joint point or a named point free to move at the pose
    ``st`` (one pose)."""
    lin = st.lin
    _, _, Vt = np.linalg.svd(lin.Jc[0], full_matrices=True)
    N = lin.twists(Vt[lin.r:].T[None])[0]  # the motions with every drive at rest, as (ω, v)
    if N.size == 0:
        return
    X = N.reshape(M.n, 6, -1)
    worst = 0.0
    checks = [(M.index(j.links[k]), M.local(j.point)) for j in M.mech.joints if j.point is not None
              for k in (0, 1)]
    checks += [(M.index(link), M.local(at)) for link, at in pts.values()]
    for i, x0 in checks:
        if i < M.n:
            x = st.R[0, i] @ x0 + st.p[0, i]
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
    if M.n < SMALL_LINKS:  # BLAS does not thread matrices this small
        return _simulate(mech, M, inputs, speeds, points, progress)
    from threadpoolctl import threadpool_limits  # deferred: finding the BLAS costs more than a small sweep

    with threadpool_limits(limits=1, user_api="blas"):  # many small SVDs: threads only contend
        return _simulate(mech, M, inputs, speeds, points, progress)


#: From this many moving links the sweep runs with one BLAS thread: BLAS threads only slow
#: its many small products and solves down (a Bennett sweep: 74 ms with one thread, 156 ms
#: with two on a busy machine); below it (no links: never) finding the BLAS libraries
#: would cost more than it saves.
SMALL_LINKS = 0


def _simulate(mech: Mechanism, M: SpatialModel, inputs: dict[str, np.ndarray], speeds: dict[str, float] | None,
              points: list[str] | None, progress: Any) -> SpatialSimulation:
    if points is None and not mech.points:
        points = [j.id for j in mech.joints if j.point is not None]
    pts = resolve_points(mech, points)
    # input rates (default 1); the drives held at their drawn value do not move
    sp = np.array([float((speeds or {}).get(d[0], 1.0)) if d[0] in inputs else 0.0 for d in M.drives])
    sp = np.where([d[1] == "slide" for d in M.drives], sp / M.scale, sp)
    tr = Tracker(M)
    n = M.n
    R0, p0 = np.tile(np.eye(3), (1, n + 1, 1, 1)), np.zeros((1, n + 1, 3))
    start = tr.state(R0, p0, np.zeros((1, len(M.helix))), np.zeros((1, len(M.drives))))
    try:
        _check_determined(M, start, pts)
        later = None
    except MechsynInputError as exc:  # perhaps only the drawn assembly is singular: judge on the sweep
        later = exc
    U = _input_matrix(M, inputs)
    rows = _sweep_rows(tr, start, U, sp, progress)
    if later is not None:
        if not rows.ok.any():
            raise MechsynInputError(
                f"{later.message}, or the drawn assembly is singular (e.g. a change point, where "
                "branches meet) and the sweep cannot leave it", source=M.mech.source, field=later.field,
                hint=f"{later.hint}, or draw the mechanism away from the singular position")
        k = int(np.argmax(np.where(rows.ok, rows.ratio, -1.0)))  # the most regular row
        R = np.concatenate([rows.R[k], np.eye(3)[None]])[None]
        p = np.vstack([rows.p[k], np.zeros((1, 3))])[None]
        _check_determined(M, tr.state(R, p, np.zeros((1, len(M.helix))), U[k][None]), pts)
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


def _input_dict(M: SpatialModel, u: np.ndarray) -> dict[str, float]:
    return {jid: float(np.degrees(v)) if kind == "angle" else float(v * M.scale)
            for (jid, kind, _), v in zip(M.drives, u)}


_MESSAGES = {
    "not assembled": "the drawn assembly cannot be moved to this input (a dead point or a singular "
                     "configuration lies between)",
    "dead point": "a limit of the working range: the drive cannot reach this value from the previous row "
                  "(singular value ratio {:.2g} where the continuation stopped)",
    "reassembled": "assembles again after a gap (Newton from the last assembled pose; the assembly branch "
                   "may differ from the drawn one)",
}


def _regular_rank(tr: Tracker, st: State) -> None:
    """The regular rank: the drawn assembly's, unless rows of the sweep (its first, middle
    and last assembled rows, by SVD) have a higher one: then the drawn assembly is
    singular, ``tr.rank`` becomes the higher rank and ``tr.drawn_singular`` is set."""
    rows = np.unique([0, len(st.g) // 2, len(st.g) - 1])
    sv = np.linalg.svd(st.lin.Jc[rows], compute_uv=False)
    rank = int(np.max(np.count_nonzero(sv > RANK_TOL * sv[:, :1], axis=1)))
    if rank > (tr.rank or 0):
        tr.drawn_singular, tr.rank, st.lin.r = tr.rank, rank, rank
        st.lin.__dict__.pop("ratio", None)


def _sweep_rows(tr: Tracker, start: State, U: np.ndarray, sp: np.ndarray, progress: Any) -> _Rows:
    """Poses of every row by continuation from the drawn assembly, then the closure residual,
    the rank test and the rates of all assembled rows at once."""
    M = tr.M

    def event(k: int, kind: str, detail: Any) -> Event:
        return Event(k, kind, _MESSAGES[kind].format(detail), input=_input_dict(M, U[k]))  # type: ignore[arg-type]

    w = walk(tr, start, U, event)
    N, n = len(U), M.n
    out = _Rows(w.R[:, :-1], w.p[:, :-1], np.full((N, 6 * n), np.nan), np.full((N, 6 * n), np.nan), w.ok,
                np.full(N, np.nan), np.full(N, np.nan), np.full((N, M.angles.size), np.nan),
                np.full((N, M.slides.size), np.nan), w.events)
    idx = np.flatnonzero(w.ok)
    if len(idx):
        st = tr.state(w.R[idx], w.p[idx], w.href[idx], U[idx])
        _regular_rank(tr, st)
        out.res[idx] = np.abs(st.g[:, :tr.m_c]).max(axis=1, initial=0.0)
        out.ratio[idx] = st.lin.ratio
        out.theta[idx], out.slide[idx] = st.F.theta, st.F.s
        x1, x2 = tr.rates(st, np.broadcast_to(sp, (len(idx), len(sp))), refine=2)
        regular = st.lin.ratio >= RANK_TOL
        out.xi[idx[regular]], out.xid[idx[regular]] = x1[regular], x2[regular]
        for k, r in zip(idx[~regular], st.lin.ratio[~regular]):
            out.events.append(Event(int(k), "singular", "singular configuration: the Jacobian's rank drops below "
                                    f"{st.lin.r} (singular value ratio {r:.2g}); rates not defined here (null)",
                                    input=_input_dict(M, U[k])))
        for k, u, r in crossings(tr, w, U, out.ratio):
            out.events.append(Event(k, "singular", f"a singular configuration lies between rows {k - 1} and {k + 1} "
                                    f"(singular value ratio {r:.2g} there): the sweep passes it on the branch it "
                                    "was on (the predictor's tangent)", input=_input_dict(M, u), crossed=True))
        out.events.sort(key=by_row)
    if progress is not None:
        progress(N)
    return out


def _result(mech: Mechanism, M: SpatialModel, tr: Tracker, inputs: dict[str, np.ndarray], sp: np.ndarray,
            pts: dict, U: np.ndarray, rows: _Rows, start: State) -> SpatialSimulation:
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
    joints.update({jid + ("/slide" if jid in joints else ""): rows.slide[:, k] * L  # a C or H pair: both
                   for k, jid in enumerate(M.slide_joints)})
    notes = []
    idle = M.n * 6 - tr.rank
    if tr.drawn_singular is not None:
        notes.append(f"the file's configuration is singular (rank {tr.drawn_singular} there, {tr.rank} along the "
                     "sweep): the branch chosen from it is arbitrary")
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
        rank=tr.rank, idle=idle, events=rows.events, notes=notes, model=M)


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
