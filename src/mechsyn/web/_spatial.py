"""Server side of the studio's 3-D view of spatial mechanisms (``static/view3d.js``).

:func:`view` runs the library's spatial kinematics (:func:`mechsyn.simulate`, the
``SpatialSimulation`` that ``mechsyn simulate`` prints) over a sweep of the file's first
drive and returns what the page draws: every joint's position and axes at every row, the
paths of the named points, which rows are assembled, the events (singular positions, dead
points, reassembly) and the notes. :func:`engine_problem` says in one line why the engine
cannot move a file (the studio then keeps its top view and the note of
:func:`check_note`). Nothing here imports Matplotlib.

Conventions are the engine's: inputs are measured from the drawn assembly (degrees for an
R or H drive, the file's length unit for a P drive); a joint's point is carried by its
second link, its ``axis`` by its first link and a U joint's ``axis2`` by its second link
(``mechsyn.plot.spatial.joint_frames`` draws them the same way).

Examples
--------
>>> from mechsyn.io import load_mechanism, mechanism_to_dict
>>> from mechsyn.web._service import example_path
>>> v = view(mechanism_to_dict(load_mechanism(example_path("bennett"))), steps=36)
>>> v["engine"], len(v["assembled"]), sorted(j["id"] for j in v["joints"])
('spatial', 36, ['R1', 'R2', 'R3', 'R4'])
>>> v["joints"][0]["position"][0]
[0.0, 0.0, 0.0]
"""

from __future__ import annotations

from typing import Any

import numpy as np
from starlette.routing import Route

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import simulate
from mechsyn.results import to_jsonable
from mechsyn.web import _service
from mechsyn.web._routing import _body, _heavy, _int, _need, api

#: Largest number of rows of one sweep (the planar routes' limit).
MAX_STEPS = _service.MAX_STEPS


def _sweep_of(mech, steps: int) -> tuple[str, np.ndarray, int]:
    """The first drive, its inputs from the drawn assembly and the row of the drawn pose: a
    full turn for an R or H drive (row 0), ± half the length scale for a P drive (the middle
    row of an odd number of rows: ``steps`` or one more)."""
    drives = [j for j in mech.joints if j.actuated]
    if not drives:
        raise MechsynInputError("no drive: nothing moves", field="joints",
                                hint="mark a joint with actuated: true (an R, P or H pair)")
    if not 2 <= int(steps) <= MAX_STEPS:
        raise MechsynInputError(f"steps must be within 2..{MAX_STEPS}", field="steps")
    n, drive = int(steps), drives[0]
    if drive.type == "P":
        pts = np.array([j.point for j in mech.joints if j.point is not None], float)
        span = float(np.ptp(pts, axis=0).max()) if len(pts) > 1 else 1.0
        n |= 1
        return drive.id, span * (np.arange(n) - n // 2) / (n - 1), n // 2  # the middle one exactly 0
    return drive.id, np.linspace(0.0, 360.0, n + 1)[:n], 0


def engine_problem(data: Any) -> str | None:
    """Why the spatial engine cannot move this mechanism (its message and fix), or None.

    Runs the engine on the drawn pose only (one row: the pair types, the drive and whether
    the drives determine the motion), which costs a few tens of milliseconds.
    """

    mech = _service.build(data)
    try:
        drive, _, _ = _sweep_of(mech, 2)
        simulate(mech, {drive: [0.0]})
    except MechsynInputError as err:
        return err.message + (f" (fix: {err.hint})" if err.hint else "")
    return None


def check_note(data: Any) -> dict[str, Any]:
    """The studio check's note on a spatial file: the 3-D view where the engine moves it,
    else the structure-and-rank-only note with the engine's reason. Blocks the planar
    simulation either way (the 3-D view runs its own)."""
    problem = engine_problem(data)
    if problem is None:
        msg = ("spatial mechanism: 3-D view (drag to orbit, wheel to zoom, Reset; the input slider moves the "
               "first drive); structure and rank analysis in the Analysis tab")
    else:
        msg = ("spatial mechanism: structure and rank analysis only (see the Analysis tab); the drawing is its "
               f"top view. Spatial kinematics cannot move it: {problem}")
    return {"level": "note", "message": msg, "blocks": True, "elements": []}


def _rows(a: np.ndarray, ok: np.ndarray, digits: int) -> list:
    """(N, 3) or (N, k, 3) rows as lists, None where not assembled or not finite."""
    a = np.round(np.asarray(a, float), digits)
    return [v.tolist() if good and np.isfinite(v).all() else None for v, good in zip(a, ok)]


def _poses(sim, names) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Rotation (N, 3, 3) and translation (N, 3) of every link; the frame stays as drawn."""
    n = len(sim.assembled)
    out = {name: (np.tile(np.eye(3), (n, 1, 1)), np.zeros((n, 3))) for name in names}
    for name, pose in sim.links.items():
        out[name] = (np.asarray(pose.rotation, float), np.asarray(pose.translation, float))
    return out


def _joint(j, poses, ok: np.ndarray, digits: int) -> dict[str, Any]:
    """A joint's type, links, position and axes (unit vectors) at every row."""
    Ra, _ = poses[j.links[0]]
    Rb, tb = poses[j.links[1]]
    out: dict[str, Any] = {"id": j.id, "type": j.type, "links": list(j.links), "actuated": bool(j.actuated),
                           "position": _rows(Rb @ np.asarray(j.point, float) + tb, ok, digits)}
    axes = []
    if j.axis is not None:
        axes.append(Ra @ (np.asarray(j.axis, float) / np.linalg.norm(j.axis)))
    if getattr(j, "axis2", None) is not None:
        axes.append(Rb @ (np.asarray(j.axis2, float) / np.linalg.norm(j.axis2)))
    if axes:
        out["axes"] = _rows(np.stack(axes, axis=1), ok, 6)
    return out


def view(data: Any, steps: int = 180) -> dict[str, Any]:
    """The 3-D view of a spatial mechanism dict over a sweep of its first drive.

    Returns ``{"mechanism", "engine", "method", "ground", "links", "input", "home",
    "assembled", "joints", "paths", "length_scale", "residual", "working_ranges", "events",
    "notes"}``: ``input`` the drive (``joint``, ``type``, ``unit``, ``values`` from the drawn
    assembly), ``home`` the row of the drawn pose; each joint ``{"id", "type", "links",
    "actuated", "position": [[x, y, z] | None per row], "axes": [[[ux, uy, uz], ...] | None
    per row]}``; ``paths`` the named points' ``link`` and positions per row (every joint off
    the frame, with its second link, when the file names none); ``residual`` the largest closure residual over the assembled
    rows (fraction of the length scale). Rows that are not assembled are None, never
    numbers. Raises :class:`~mechsyn.errors.MechsynInputError` for a planar file, a file
    without a drive, or one the engine cannot move (its message names the pair or drive).
    """

    mech = _service.build(data)
    if mech.kind != "spatial":
        raise MechsynInputError("the 3-D view is for spatial files", field="kind", hint="kind: spatial")
    drive, values, home = _sweep_of(mech, steps)
    named = list(mech.points)
    sim = simulate(mech, {drive: values}, points=named or None)
    d = sim.to_dict()
    ok = np.asarray(sim.assembled, bool)
    L = float(sim.length_scale)
    digits = int(max(0, 10 - np.floor(np.log10(L)))) if L > 0 else 10  # 1e-10 of the length scale
    poses = _poses(sim, mech.link_names)
    shown = named or [j.id for j in mech.joints if j.point is not None and mech.ground not in j.links]
    res = np.asarray(sim.residual, float)[ok]
    return to_jsonable({
        "mechanism": mech.name, "engine": sim.engine, "method": sim.method, "ground": mech.ground,
        "links": list(mech.link_names), "input": {**d["input"], "type": sim.input_types[drive]}, "home": home,
        "assembled": ok.tolist(),
        "joints": [_joint(j, poses, ok, digits) for j in mech.joints if j.point is not None],
        "paths": {n: {"link": mech.points[n].link if n in mech.points else mech.joint(n).links[1],
                      "position": _rows(sim.point(n), ok, digits)} for n in shown},
        "length_scale": L, "residual": float(res.max()) if res.size else None,
        "working_ranges": d["working_ranges"], "events": d["events"], "notes": d["notes"],
    })


def routes() -> list:
    """The 3-D view's route, ``POST /api/spatial/view`` ``{"mechanism", "steps"?}``
    (registered by :func:`mechsyn.web._app._routes`; the sweep runs as a capped,
    cancellable worker process, :func:`mechsyn.web._routing._heavy`)."""

    @api
    async def view_route(request) -> Any:
        body = await _body(request)
        return await _heavy(request, "_spatial:view", _need(body, "mechanism"), _int(body.get("steps", 180), "steps"))

    return [Route("/api/spatial/view", view_route, methods=["POST"])]
