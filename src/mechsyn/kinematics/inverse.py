"""Inverse kinematics by the same engines: a point of a link (a robot's tool point, a
parallel platform's centre) given on a path instead of the drives' values.

:func:`simulate_inverse` finds, target by target along the path, the drive values that
put the point there: Gauss-Newton on the drives, each residual and its Jacobian (one
finite-difference row per drive) from one call of :func:`mechsyn.kinematics.analysis.simulate`
(the planar engines, or the spatial engine for a ``kind: spatial`` file), each target
started from the previous one's solution (continuation: the assembly branch of the
drawn pose is kept). Where the point cannot follow (the target outside the workspace,
or a singular position where the drives lose control of it), the path stops there and
the result says so (``boundary``, ``message``) with the nearest point reached.

:func:`posed` gives the mechanism file at one row of a simulation (its joints, axes and
named points moved there): the drawn pose a designer continues from.

Examples
--------
>>> import numpy as np, mechsyn as ms
>>> from mechsyn.kinematics.inverse import simulate_inverse
>>> m = ms.load("five_bar_5r")                      # two drives, A and E; tool point "tool"
>>> r = simulate_inverse(m, "tool", [[2.2, 3.4], [2.4, 3.3]])
>>> r.ok, ms.simulate(m, r.inputs, points=["tool"]).point("tool").round(9).tolist()
(True, [[2.2, 3.4], [2.4, 3.3]])
>>> simulate_inverse(m, "tool", [[2.0, 40.0]]).message[:44]
'tool cannot follow beyond target 1 (2, 40): '
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import drawn_inputs, simulate
from mechsyn.kinematics.plane import to_frame
from mechsyn.model.mechanism import Mechanism

__all__ = ["InverseResult", "simulate_inverse", "simulate_path", "posed", "is_point_path"]

#: Gauss-Newton iterations per target; the largest step of an R drive (degrees) and of a P
#: drive (fraction of the length scale) in one iteration.
MAX_ITER, MAX_TURN, MAX_SLIDE = 30, 15.0, 0.1


@dataclass
class InverseResult:
    """The drives' values (deg for R, length for P, in the engine's convention) that put
    ``point`` on every reached target, and where the path stopped."""

    point: str
    targets: np.ndarray                 # (N, d)
    inputs: dict[str, np.ndarray]       # drive -> (N,), NaN after the boundary
    reached: np.ndarray                 # (N,) bool
    nearest: np.ndarray                 # (N, d): where the point is (the nearest reachable where not reached)
    boundary: int | None = None         # the first target not reached
    message: str = ""
    notes: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        return bool(self.reached.all())


def _scale(mech: Mechanism) -> float:
    pts = np.array([np.asarray(j.point, float) for j in mech.joints if j.point is not None])
    return float(np.ptp(pts, axis=0).max()) if len(pts) > 1 else 1.0


def simulate_inverse(mech: Mechanism, point: str, path: Any, *, start: dict[str, float] | None = None,
                     tol: float = 1e-9) -> InverseResult:
    """The drives' values moving ``point`` (a named point or a joint id) along ``path``
    (rows of 2 coordinates for a planar file, 3 for a spatial one), from the drawn pose
    (or the drives' values ``start``). The mechanism needs as many drives as the point has
    coordinates (a planar five-bar: 2; a Delta robot: 3). ``tol``: the distance to a
    target that counts as reached, relative to the mechanism's size.
    """

    drives = [j for j in mech.joints if j.actuated]
    T = np.atleast_2d(np.asarray(path, float))  # (one target: a row)
    d = 2 if mech.kind == "planar" else 3
    if T.ndim != 2 or T.shape[1] != d or not np.isfinite(T).all():
        raise MechsynInputError(f"the path of {point} must be rows of {d} numbers", field="path")
    if len(drives) != d:
        raise MechsynInputError(f"the tool point has {d} coordinates but the mechanism {len(drives)} drive"
                                f"{'s' if len(drives) != 1 else ''}: inverse kinematics needs as many drives",
                                field="drives", hint="mark as many drives as the point's coordinates")
    names = [j.id for j in drives]
    u = np.array([(start or drawn_inputs(mech))[n] for n in names], float)
    L = _scale(mech)
    step = np.array([1e-6 if j.type == "R" else 1e-7 * L for j in drives])
    cap = np.array([MAX_TURN if j.type == "R" else MAX_SLIDE * L for j in drives])
    out = np.full((len(T), d), np.nan)
    U = np.full((len(T), d), np.nan)
    reached = np.zeros(len(T), bool)
    boundary, message = None, ""

    def where(u_now: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
        rows = np.vstack([u_now, u_now + np.diag(step)])
        sim = simulate(mech, {n: rows[:, k] for k, n in enumerate(names)}, points=[point])
        if not np.asarray(sim.assembled, bool).all():
            return None, None
        X = np.asarray(sim.point(point), float)[:, :d]
        return X[0], ((X[1:] - X[0]) / step[:, None]).T

    for i, target in enumerate(T):
        u, x, why = _solve(where, u, target, cap, tol * L)
        out[i] = x if x is not None else np.nan
        if why is None:
            U[i], reached[i] = u, True
            continue
        boundary = i
        message = (f"{point} cannot follow beyond target {i + 1} {_fmt(target)}: {why}"
                   + (f"; it reaches {_fmt(x)}, {np.linalg.norm(x - target):.4g} away (the workspace boundary)"
                      if x is not None else ""))
        break
    return InverseResult(point, T, {n: U[:, k] for k, n in enumerate(names)}, reached, out, boundary, message)


def is_point_path(mech: Mechanism, inputs: dict[str, Any]) -> bool:
    """Whether ``inputs`` gives a point's path (one key, a named point or an undriven joint,
    with rows of coordinates) rather than the drives' values."""
    if len(inputs) != 1:
        return False
    (key, value), = inputs.items()
    driven = {j.id for j in mech.joints if j.actuated}
    known = key in mech.points or any(j.id == key for j in mech.joints)
    return known and key not in driven and np.ndim(value) == 2


def simulate_path(mech: Mechanism, inputs: dict[str, Any], **kwargs: Any) -> Any:
    """:func:`mechsyn.kinematics.analysis.simulate` with a point's path as the input
    (``{"tool": rows}``, :func:`is_point_path`): the drives' values by
    :func:`simulate_inverse`, then the forward simulation at them (its ``inputs`` are the
    drives'; ``kwargs`` go to ``simulate``). A path that leaves the workspace raises
    :class:`~mechsyn.errors.MechsynInputError` naming where (call :func:`simulate_inverse`
    for the part reached).

    (``simulate`` itself does not dispatch here: this module is built on it, and the
    package keeps no import cycle.)

    Examples
    --------
    >>> import mechsyn as ms
    >>> s = simulate_path(ms.load("five_bar_5r"), {"tool": [[2.2, 3.4], [2.4, 3.3]]})
    >>> sorted(s.inputs), s.point("tool").round(9).tolist()
    (['A', 'E'], [[2.2, 3.4], [2.4, 3.3]])
    """
    if not is_point_path(mech, inputs):
        raise MechsynInputError("give one point's path, e.g. {'tool': [[x, y], ...]}", field="inputs",
                                hint="a named point or an undriven joint, with rows of its coordinates")
    (point, path), = inputs.items()
    res = simulate_inverse(mech, point, path)
    if not res.ok:
        raise MechsynInputError(res.message, field="inputs",
                                hint="keep the path inside the workspace, or call simulate_inverse for the part reached")
    points = kwargs.pop("points", None)
    if points is not None and point not in points:
        points = list(points) + [point]
    return simulate(mech, res.inputs, points=points, **kwargs)


def _fmt(p: Any) -> str:
    return "(" + ", ".join(f"{float(c):.4g}" for c in p) + ")"


def _solve(where, u: np.ndarray, target: np.ndarray, cap: np.ndarray, tol: float
           ) -> tuple[np.ndarray, np.ndarray | None, str | None]:
    """Gauss-Newton on the drives from ``u`` to put the point at ``target``: ``(u, where
    the point is, None)`` when reached, else the reason (the last ``u`` kept)."""
    best_u, best_x, best_r = u, None, np.inf
    for _ in range(MAX_ITER):
        x, J = where(u)
        if x is None:  # a step left the assembled region: back towards the last good drives
            if best_x is None:
                return u, None, "the mechanism does not assemble there"
            u = 0.5 * (u + best_u)
            continue
        r = x - target
        nr = float(np.linalg.norm(r))
        if nr < best_r:
            best_u, best_x, best_r = u, x, nr
        if nr <= tol:
            return u, x, None
        sv = np.linalg.svd(J, compute_uv=False)
        if sv[-1] <= 1e-9 * sv[0]:
            return best_u, best_x, "a singular position: the drives lose control of the point"
        du = -np.linalg.lstsq(J, r, rcond=None)[0]
        du *= min(1.0, float(np.min(cap / np.maximum(np.abs(du), 1e-300))))
        u = u + du
    return best_u, best_x, "out of reach (the nearest reachable point is on the workspace boundary)"


def posed(mech: Mechanism, sim: Any, row: int) -> Mechanism:
    """``mech`` drawn at row ``row`` of its simulation ``sim`` (which must have the joints
    among its points for a planar file): every joint's point, a P joint's axis (turned
    with its first link; a spatial joint's axes with their links) and named points."""
    if mech.kind == "planar":
        return _posed_planar(mech, sim, row)
    return _posed_spatial(mech, sim, row)


def _posed_planar(mech: Mechanism, sim: Any, row: int) -> Mechanism:
    S = sim.system
    turn = {name: math.radians(float(sim.links[name].angle[row])) - float(S.angle0[i])
            for i, name in enumerate(S.links) if name in sim.links}
    joints = []
    for j in mech.joints:
        ch: dict[str, Any] = {}
        if j.id in sim.points:
            ch["point"] = np.asarray(sim.points[j.id].position[row], float)
        if j.axis is not None and j.links[0] in turn:
            a = np.asarray(j.axis, float)
            ch["axis"] = to_frame(math.cos(turn[j.links[0]]), math.sin(turn[j.links[0]]), a[0], a[1])
        joints.append(replace(j, **ch) if ch else j)
    points = {n: replace(p, at=np.asarray(sim.points[n].position[row], float)) if n in sim.points else p
              for n, p in mech.points.items()}
    return replace(mech, joints=tuple(joints), points=points)


def _posed_spatial(mech: Mechanism, sim: Any, row: int) -> Mechanism:
    def pose(link: str) -> tuple[np.ndarray, np.ndarray]:
        if link in sim.links:
            return np.asarray(sim.links[link].rotation[row], float), np.asarray(sim.links[link].translation[row], float)
        return np.eye(3), np.zeros(3)

    joints = []
    for j in mech.joints:
        Ra, _ = pose(j.links[0])
        Rb, tb = pose(j.links[1])
        ch: dict[str, Any] = {}
        if j.point is not None:
            ch["point"] = Rb @ np.asarray(j.point, float) + tb
        if j.axis is not None:
            ch["axis"] = Ra @ np.asarray(j.axis, float)
        for attr, R in (("axis2", Rb), ("normal", Ra)):  # (a second axis turns with the second link)
            if getattr(j, attr, None) is not None:
                ch[attr] = R @ np.asarray(getattr(j, attr), float)
        joints.append(replace(j, **ch) if ch else j)
    points = {}
    for n, p in mech.points.items():
        R, t = pose(p.link)
        points[n] = replace(p, at=R @ np.asarray(p.at, float) + t)
    return replace(mech, joints=tuple(joints), points=points)
