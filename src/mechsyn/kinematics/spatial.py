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
* handles idle mobilities: a bar between two ball joints (a Delta's, an RSSR's rod) is no
  unknown (one distance equation between its ends: its pose follows them, carried from row
  to row with no spin, defined through any turn of its line); other idle motions are the
  null space of ``J``, and the minimum-norm steps and rates leave them at rest (the idle
  links keep their drawn spin, to first order). Drives that leave a motion of a joint point
  or a named point free are refused at the start (the motion would be arbitrary);
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

from dataclasses import replace
from typing import Any

import numpy as np

from mechsyn.errors import EngineDeclined, MechsynInputError
from mechsyn.kinematics.simulation import PointMotion, resolve_points
from mechsyn.kinematics.spatial_model import (INPUT_NAMES, SpatialModel, bar_motion, compile_spatial, input_kind,
                                              pair_error, planar_as_spatial)
from mechsyn.kinematics.spatial_result import LinkPose, SpatialSimulation
from mechsyn.kinematics.spatial_singular import crossings
from mechsyn.kinematics.spatial_track import (PAIR_TOL, RANK_TOL, State, Tracker, Walk, free_motions, singular_tol,
                                              turning_column, walk)
from mechsyn.kinematics.sweep import as_event
from mechsyn.kinematics.system import build_system
from mechsyn.model.mechanism import Mechanism
from mechsyn.progress import ProgressCallback, report

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
                 points: list[str] | None = None, progress: ProgressCallback | None = None,
                 **_: Any) -> SpatialSimulation:
        if mech.kind != "spatial":  # a P input's zero: the joint's origin (an R input's: planar_as_spatial)
            slides = _planar_slides(mech, tuple(inputs))
            mech = replace(mech, joints=tuple(replace(j, attrs={**j.attrs, "slide0": slides[j.id]}) if j.id in slides
                                              else j for j in mech.joints))
        return simulate_spatial(mech, inputs, speeds=speeds, points=points, progress=progress)


def _planar_slides(mech: Mechanism, inputs: tuple[str, ...]) -> dict[str, float]:
    """The drawn slide of each driven P joint of a planar mechanism (the spatial engine
    measures a slide from the drawn assembly, the planar engines from the joint's origin);
    a mechanism the spatial engine cannot take as its 3-D equivalent (a pair other than R
    and P, a VLL) is an :class:`~mechsyn.errors.EngineDeclined`."""
    other = next((j for j in mech.joints if j.type not in ("R", "P")), None)
    if other is not None:
        raise EngineDeclined("spatial", mech.name, f"joint {other.id} is a {other.type} pair; it takes planar "
                                                   "mechanisms of R and P pairs only")
    vll = next((j for j in mech.joints if j.vll), None)
    if vll is not None:
        raise EngineDeclined("spatial", mech.name, f"joint {vll.id} is a VLL ({vll.vll}); it takes plain R and "
                                                   "P pairs only")
    drivers = {d.joint: d for d in build_system(mech).drivers}
    for jid in inputs:
        if jid not in drivers:
            raise MechsynInputError(f"joint {jid!r} is not driven", source=mech.source, field="inputs",
                                    hint="driven joints: " + (", ".join(drivers) or "(none)"))
    return {j: float(d.assembled) for j, d in drivers.items() if d.type == "P" and j in inputs}


def _check_inputs(mech: Mechanism, inputs: dict[str, Any]) -> dict[str, np.ndarray]:
    """The inputs as float arrays, checked: each the input of a joint (:data:`INPUT_NAMES`),
    as many values each, all finite."""
    if not inputs:
        raise MechsynInputError("no input given", field="inputs",
                                hint="give the driven joint's values, e.g. R1=0:360:1 on the command line")
    for name in inputs:
        jid = name.partition("/")[0]
        j = next((j for j in mech.joints if j.id == jid), None)
        if j is None:
            raise MechsynInputError(f"no joint {jid!r} to drive", source=mech.source, field="inputs",
                                    hint="one of " + ", ".join(j.id for j in mech.joints))
        takes = [jid + part for part in INPUT_NAMES.get(j.type, ())]
        if name not in takes:
            what = " and ".join(map(repr, takes)) or "no input (only R, P, H, C and U pairs do)"
            raise MechsynInputError(f"input {name!r}: a {j.type} pair takes {what}", source=mech.source, field="inputs",
                                    hint="a C pair: C=slide, C/turn=angle; a U pair: U, U/2 (angles)")
    out = {name: np.atleast_1d(np.asarray(v, float)) for name, v in inputs.items()}
    if len({len(v) for v in out.values()}) != 1:
        raise MechsynInputError("the inputs have different numbers of values", field="inputs",
                                hint="give every driven joint as many values")
    for jid, v in out.items():
        if not np.all(np.isfinite(v)):
            raise MechsynInputError(f"input {jid} has a value that is not a number", field="inputs")
    return out


def _input_matrix(M: SpatialModel, inputs: dict[str, np.ndarray]) -> np.ndarray:
    """(N, drives) targets in model units (radians, or lengths over the scale) from the
    drawn assembly; the drives without input at 0 (as drawn)."""
    U = np.zeros((len(next(iter(inputs.values()))), len(M.drives)))
    for k, (jid, kind, kk) in enumerate(M.drives):
        if jid in inputs:
            U[:, k] = np.radians(inputs[jid]) - M.zeros[kk] if kind == "angle" else inputs[jid] / M.scale - M.slide0[kk]
    return U


def _undetermined(M: SpatialModel, free: int, drawn: bool) -> MechsynInputError:
    """The error of drives that leave ``free`` motions of a joint point or a named point
    (``drawn``: no row of the sweep assembled, so only the drawn assembly could be judged)."""
    return MechsynInputError(
        f"with the drives {', '.join(d[0] for d in M.drives)} at rest the mechanism can still move "
        f"({free} free motion(s), not only idle spins): its motion is not determined" + (
            ", or the drawn assembly is singular (e.g. a change point, where branches meet) and the sweep cannot "
            "leave it" if drawn else ""), source=M.mech.source, field="joints[].actuated",
        hint="mark more joints actuated: true (each needs an input or keeps its drawn value)"
             + (", or draw the mechanism away from the singular position" if drawn else ""))


def simulate_spatial(mech: Mechanism, inputs: dict[str, Any], speeds: dict[str, float] | None = None,
                     points: list[str] | None = None, progress: ProgressCallback | None = None) -> SpatialSimulation:
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
    mech = planar_as_spatial(mech)  # a planar file: its 3-D equivalent, with the planar zero
    inputs = _check_inputs(mech, inputs)
    # the drives: the inputs, then the file's other driven joints (held at their drawn value)
    M = compile_spatial(mech, tuple(inputs) + tuple(j.id for j in mech.joints if j.actuated and j.id not in inputs))
    if points is None and not mech.points:
        points = [j.id for j in mech.joints if j.point is not None]
    pts = resolve_points(mech, points)
    U = _input_matrix(M, inputs)
    sp, spp, path_note = _input_rates(M, inputs, speeds, U)
    tr = Tracker(M)
    start = tr.state(np.tile(np.eye(3), (1, M.n + 1, 1, 1)), np.zeros((1, M.n + 1, 3)), np.zeros((1, len(M.helix))),
                     np.zeros((1, len(M.drives))))  # the drawn assembly
    extra = tuple((M.index(link), M.local(at)) for link, at in pts.values())
    free = len(free_motions(tr, start, tr.rank_tol, extra))
    rows = _sweep_rows(tr, start, U, (sp, spp), progress)
    if free:  # perhaps only the drawn assembly is singular: judged again at the sweep's most regular row
        k = int(np.argmax(np.where(rows.ok, rows.ratio, -1.0)))
        if not rows.ok.any():
            raise _undetermined(M, free, True)
        free = len(free_motions(tr, tr.state(*rows.at(k), U[k][None]), tr.rank_tol, extra))
        if free:
            raise _undetermined(M, free, False)
    return _result(mech, M, tr, inputs, sp[0], pts, U, rows, [path_note] if path_note else [])


def _second_derivative(f: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``d²f/dx²`` of samples ``f`` at increasing or decreasing ``x`` (at least 3): the
    three-point formula inside, the second derivative of the cubic through the first (last)
    four points at the ends (of the parabola through three when there are only three)."""
    out = np.empty_like(f)
    h0, h1 = np.diff(x)[:-1], np.diff(x)[1:]
    out[1:-1] = 2 * ((f[2:] - f[1:-1]) / h1 - (f[1:-1] - f[:-2]) / h0) / (h0 + h1)
    k = min(4, len(f))
    for sl, at in ((slice(0, k), 0), (slice(len(f) - k, len(f)), len(f) - 1)):
        c = np.polyfit(x[sl] - x[at], f[sl], k - 1)
        out[at] = 2 * c[-3]
    return out


def _input_rates(M: SpatialModel, inputs: dict[str, np.ndarray], speeds: dict[str, float] | None,
                 U: np.ndarray) -> tuple[np.ndarray, np.ndarray, str]:
    """Per row, the drives' rates and their time derivatives (model units), and a note.

    With one moving input, or ``speeds`` given for every input, each input moves at its
    speed (default 1) and the drives held at their drawn value do not move. Several inputs
    without their speeds are a path: the main (first) input moves at its speed ``s`` and
    every other follows the path, ``u̇_j = s du_j/du_1`` and ``ü_j = s² d²u_j/du_1²`` (the
    path's derivatives, second-order differences of the given input values: exact on
    straight and parabolic paths); a path along which the main input does not move
    monotonically falls back to constant speeds, with a note."""
    N, D = U.shape
    speeds = speeds or {}
    scale = np.array([1.0 if kind == "angle" else 1.0 / M.scale for _, kind, _ in M.drives])
    given = np.array([float(speeds.get(d[0], 1.0)) if d[0] in inputs else 0.0 for d in M.drives]) * scale
    moving = [k for k in range(D) if np.ptp(U[:, k]) > 0]
    names = [M.drives[k][0] for k in moving]
    if len(moving) < 2 or all(n in speeds for n in names) or N < 3:
        return np.tile(given, (N, 1)), np.zeros((N, D)), ""
    u = U[:, 0]  # the main input's (the inputs are the first drives, in order)
    if not (np.all(np.diff(u) > 0) or np.all(np.diff(u) < 0)):
        return np.tile(given, (N, 1)), np.zeros((N, D)), (
            f"the inputs {', '.join(names)} move together but {M.drives[0][0]} does not move one way along them: "
            "every input at its constant speed")
    s = given[0]
    sp, spp = np.zeros((N, D)), np.zeros((N, D))
    for k in moving:
        sp[:, k] = s * np.gradient(U[:, k], u, edge_order=2)
        spp[:, k] = s * s * _second_derivative(U[:, k], u)
    return sp, spp, (f"the inputs {', '.join(names)} follow one path: rates from its derivative with "
                     f"{M.drives[0][0]} at its speed")


def _input_dict(M: SpatialModel, u: np.ndarray) -> dict[str, float]:
    """Model targets -> the inputs as the user gives them (deg from the joint's zero, lengths)."""
    return {jid: float(np.degrees(v + M.zeros[kk])) if kind == "angle" else float((v + M.slide0[kk]) * M.scale)
            for (jid, kind, kk), v in zip(M.drives, u)}


_MESSAGES = {
    "not assembled": "the drawn assembly cannot be moved to this input (a dead point or a singular "
                     "configuration lies between)",
    "dead point": "a limit of the working range (its input refined between the last row reached and this "
                  "one): the drive cannot go on (singular value ratio {:.2g} where the continuation stopped)",
    "reassembled": "assembles again after a gap, in another assembly than the drawn one (no motion from the "
                   "drawn assembly reaches these rows: Newton from the last pose before the gap)",
    "other way round": "reached the other way round from the drawn assembly (the input taken modulo 360 degrees): the "
             "drawn circuit, on from the sweep's other end",
    "refused": "not assembled here: Newton converged to a pose where pair {} is not the file's pair (its axis "
               "reversed or a slide half-turned: another root of its equations), refused",
    "singular": "singular configuration (singular value ratio {:.2g}): a change or dead point on this row; rates "
                "not defined here (null)",
    "crossed": "a singular configuration lies between this row and the next (singular value ratio {:.2g} there): "
               "the sweep passes it on the branch it was on (the predictor's tangent)",
}


def _regular_rank(tr: Tracker, st: State) -> None:
    """The regular rank: the drawn assembly's, unless rows of the sweep (its first, middle
    and last assembled rows, by SVD) have a higher one: then the drawn assembly is
    singular, ``tr.rank`` becomes the higher rank and ``tr.drawn_singular`` is set."""
    rows = np.unique([0, len(st.g) // 2, len(st.g) - 1])
    sv = np.linalg.svd(st.lin.Jc[rows], compute_uv=False)
    rank = int(np.max(np.count_nonzero(sv > tr.rank_tol * sv[:, :1], axis=1)))
    if rank > (tr.rank or 0):
        tr.drawn_singular, tr.rank, st.lin.r = tr.rank, rank, rank
        st.lin.__dict__.pop("ratio", None)


def _sweep_rows(tr: Tracker, start: State, U: np.ndarray, rates: tuple[np.ndarray, np.ndarray],
                progress: ProgressCallback | None) -> Walk:
    """Poses of every row by continuation from the drawn assembly, then the closure residual,
    the rank test and the rates of all assembled rows at once."""
    M = tr.M

    def event(k: int, kind: str, detail: Any, at: np.ndarray | None = None, last: int | None = None) -> dict:
        """An event at row ``k``; ``at``: its input's offset from row ``k``'s (a refined limit);
        ``last``: the assembled row it bounds."""
        e = {"index": k, "kind": kind, "input": _input_dict(M, U[k] if at is None else U[k] + at),
             "message": _MESSAGES[kind].format(detail)}
        if last is not None:
            e["last"] = int(last)
        return e

    out = walk(tr, start, U, event)
    N = len(U)
    out.xi, out.xid = np.full((N, 6 * M.n), np.nan), np.full((N, 6 * M.n), np.nan)
    out.res, out.ratio = np.full(N, np.nan), np.full(N, np.nan)
    out.theta, out.slide = np.full((N, len(M.angle_joints)), np.nan), np.full((N, len(M.slide_joints)), np.nan)
    for _ in range(2):  # (again when the check refuses rows: the state of the others)
        idx = np.flatnonzero(out.ok)
        st = tr.state(out.R[idx], out.p[idx], out.href[idx], U[idx], rates=(rates[0][idx], rates[1][idx]))
        if _verify(tr, out, idx, st, event).all():
            break
    if len(idx):
        _regular_rank(tr, st)
        out.res[idx] = np.abs(st.g[:, :tr.m_c]).max(axis=1, initial=0.0)
        out.ratio[idx] = st.lin.ratio
        out.theta[idx], out.slide[idx] = st.theta, st.s
        x1, x2 = st.x
        regular = st.lin.ratio >= singular_tol(M)
        found = crossings(tr, out, U, out.ratio, st.lin.Jc, idx)
        on_row = {c[3] for c in found if c[3] is not None}
        regular &= ~np.isin(idx, list(on_row))
        out.xi[idx[regular]], out.xid[idx[regular]] = x1[regular], x2[regular]
        _singular_events(out, U, idx[~regular], found, event)
        out.events.sort(key=lambda e: e["index"])
    report(progress, N, N, "sweep")
    return out


def _verify(tr: Tracker, w: Any, idx: np.ndarray, st: State, event: Any) -> np.ndarray:
    """Every row the walk assembled checked again before it is reported: its closure
    residual and the pair check (each R, C, H, P pair's relative rotation is the one its
    reported joint value gives, so the joint values close every loop:
    :func:`~mechsyn.kinematics.spatial_model.pair_error`); a row that fails is not assembled,
    with an event naming the pair. Returns the mask of ``idx`` (the assembled rows, state
    ``st``) kept."""
    M = tr.M
    err = pair_error(M, st.R)
    res = np.abs(st.g).max(axis=1)
    bad = (res > closure_tol(tr)) | (err.max(axis=1, initial=0.0) > PAIR_TOL)
    for k, e in zip(idx[bad], err[bad]):
        w.ok[k] = False
        w.events.append(event(int(k), "refused", M.pairs.ids[int(np.argmax(e))] if e.size else "-"))
    return ~bad


def closure_tol(tr: Tracker) -> float:
    """The largest closure residual a reported row may carry: ``CLOSURE_TOL`` of the length
    scale, or ten times the corrector's tolerance where the file's coordinates need more."""
    return max(CLOSURE_TOL, 10 * tr.tol)


def _singular_events(out: Walk, U: np.ndarray, rows: np.ndarray, found: list, event: Any) -> None:
    """Events of the singular rows (rates null) and of the crossings between rows (``kind``
    ``singular``, ``crossed``)."""
    on_row = {c[3]: c[1] - U[c[3]] for c in found if c[3] is not None}
    out.events += [event(int(k), "singular", out.ratio[k], at=on_row.get(k)) for k in rows]
    out.events += [{**event(int(k), "crossed", r, at=u - U[k]), "kind": "singular", "crossed": True}
                   for k, u, r, at in found if at is None]


def _result(mech: Mechanism, M: SpatialModel, tr: Tracker, inputs: dict[str, np.ndarray], sp: np.ndarray,
            pts: dict, U: np.ndarray, rows: Walk, more: list[str]) -> SpatialSimulation:
    """The result in the file's units."""
    L, c = M.scale, M.centre
    ok = rows.ok
    R, p, X, Xd = bar_motion(M, rows.R[:, :-1], rows.p[:, :-1], rows.xi, rows.xid)
    X, Xd = X.reshape(len(ok), -1, 6), Xd.reshape(len(ok), -1, 6)
    links = {name: LinkPose(R[:, i], c - np.einsum("kij,j->ki", R[:, i], c) + L * p[:, i], X[:, i, :3], Xd[:, i, :3])
             for i, name in enumerate(M.all_links)}
    pm = {name: _point_motion(M, ok, (R, p, X, Xd), link, M.local(at)) for name, (link, at) in pts.items()}
    joints = {jid: np.degrees(_unwrap(rows.theta[:, k], ok) + M.zeros[k]) for k, jid in enumerate(M.angle_joints)}
    for name, v in inputs.items():  # an angle input reads as itself (the same turn)
        if input_kind(mech, name) != "P":
            joints[name.replace("/turn", "")] = np.where(ok, v, np.nan)
    joints.update({jid + ("/slide" if jid in joints else ""): (rows.slide[:, k] + M.slide0[k]) * L  # C, H: both
                   for k, jid in enumerate(M.slide_joints)})
    notes = []
    rank = tr.rank + 5 * len(M.bars)  # (a bar's two S pairs: five more than its distance)
    idle = 6 * len(M.all_links) - rank
    if tr.drawn_singular is not None:
        notes.append(f"the file's configuration is singular (rank {tr.drawn_singular + rank - tr.rank} there, "
                     f"{rank} along the sweep): the branch chosen from it is arbitrary")
    if idle:
        notes.append(f"{idle} idle motion(s) with the drives at rest (e.g. a rod spinning between ball joints): "
                     "held at their drawn position (minimum-norm steps and rates)")
    if tr.halvings:
        notes.append(f"the continuation step was halved {tr.halvings} time(s) where the corrector had trouble")
    bad = ok & (rows.res > closure_tol(tr))
    if bad.any():
        notes.append(f"closure residual above {closure_tol(tr):g} of the length scale at {int(bad.sum())} row(s)")
    notes += _reach_notes(M, tr, U, rows) + more
    types = {jid: input_kind(mech, jid) for jid in inputs}
    speeds = {d[0]: float(v * (L if d[1] == "slide" else 1.0)) for d, v in zip(M.drives, sp) if d[0] in inputs}
    return SpatialSimulation(
        mechanism=mech.name, inputs=inputs, input_types=types, speeds=speeds, assembled=ok, points=pm,
        links=links, joints=joints, residual=rows.res, singular_ratio=rows.ratio, length_scale=L,
        rank=rank, idle=idle, events=[as_event(e) for e in rows.events], notes=notes, model=M,
        reached=np.where(ok, rows.how, 0).astype(int), held=tuple(d[0] for d in M.drives if d[0] not in inputs),
        zero={k: v for k, v in _input_dict(M, np.zeros(len(M.drives))).items() if k in inputs})


def _reach_notes(M: SpatialModel, tr: Tracker, U: np.ndarray, rows: Walk) -> list[str]:
    """What the summary says about how the rows were reached (:func:`~.spatial_track.walk`)."""
    notes = []
    how = np.where(rows.ok, rows.how, 0)
    if (how == 2).any():
        notes.append(f"{int((how == 2).sum())} row(s) reached going the other way round from the drawn assembly "
                     "(the input modulo 360): the drawn circuit")
    if (how == 3).any():
        notes.append(f"{int((how == 3).sum())} row(s) in another assembly than the drawn one: no motion from the "
                     "drawn assembly reaches them (re-assembled by Newton after a gap)")
    if tr.rejected:
        notes.append(f"{tr.rejected} converged pose(s) refused: another root of a pair's equations (an R axis "
                     "reversed or a slide half-turned), not the file's pairs")
    col = turning_column(M, U)
    if col is not None:
        u, name = U[:, col], M.drives[col][0]
        turns = rows.ok & (np.abs(np.mod(u + np.pi, 2 * np.pi) - np.pi) < 1e-9) & (np.abs(u) > 1e-9)
        off = [k for k in np.flatnonzero(turns) if np.abs(rows.R[k] - np.eye(3)).max() > 1e-6
               or np.abs(rows.p[k]).max() > 1e-6]
        if off:
            notes.append(f"at {name} = {_input_dict(M, U[off[0]])[name]:.6g} (the drawn input, a turn on) the "
                         "mechanism is in another assembly than drawn: its circuit takes more than one turn of the "
                         "input")
    return notes


def _point_motion(M: SpatialModel, ok: np.ndarray, motion: tuple, link: str, x0: np.ndarray) -> PointMotion:
    """A point ``x0`` (model units) of ``link`` (the frame, or one of :attr:`SpatialModel.all_links`),
    with ``motion`` the poses and twists of all links."""
    L, c = M.scale, M.centre
    if link not in M.all_links:  # the frame: at rest
        z = np.where(ok[:, None], 0.0, np.nan) * np.ones((1, 3))
        return PointMotion(c + L * x0 + z, z, z.copy(), link)
    R, p, X, Xd = motion
    i = M.all_links.index(link)
    x = np.einsum("kij,j->ki", R[:, i], x0) + p[:, i]
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
