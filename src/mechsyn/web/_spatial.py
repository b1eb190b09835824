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
from mechsyn.structure.rank import analyze_rank
from mechsyn.web import _service
from mechsyn.web._routing import _heavy, _parsed, api
from mechsyn.web._schema import SweepBody

#: Largest number of rows of one sweep (the planar routes' limit).
MAX_STEPS = _service.MAX_STEPS


def _sweep_of(mech, steps: int) -> tuple[str, np.ndarray, int]:
    """The first drive, its inputs and the row of the drawn pose: a full turn from the drawn
    pose's input for an R, H or U drive (row 0; the input is measured from the joint's
    ``zero`` when the file gives one), ± half the length scale for a P or C drive (the middle
    row of an odd number of rows: ``steps`` or one more)."""
    drives = [j for j in mech.joints if j.actuated]
    if not drives:
        raise MechsynInputError("no drive: nothing moves", field="joints",
                                hint="mark a joint with actuated: true (an R, P or H pair)")
    if not 2 <= int(steps) <= MAX_STEPS:
        raise MechsynInputError(f"steps must be within 2..{MAX_STEPS}", field="steps")
    n, drive = int(steps), drives[0]
    if drive.type in ("P", "C"):  # a C pair's input is its slide
        pts = np.array([j.point for j in mech.joints if j.point is not None], float)
        span = float(np.ptp(pts, axis=0).max()) if len(pts) > 1 else 1.0
        n |= 1
        return drive.id, span * (np.arange(n) - n // 2) / (n - 1), n // 2  # the middle one exactly 0
    from mechsyn.kinematics.spatial_model import input_zero

    drawn = float(np.degrees(input_zero(mech, drive)))  # the drawn pose's input (its zero: the file format)
    return drive.id, drawn + np.linspace(0.0, 360.0, n + 1)[:n], 0


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
    else the structure-and-rank-only note with the engine's reason; an error naming the
    drives when the file cannot move at all (:func:`rigid_problem`). Blocks the planar
    simulation either way (the 3-D view runs its own)."""
    rigid = rigid_problem(data)
    if rigid is not None:
        return rigid
    problem = engine_problem(data)
    if problem is None:
        drives = sum(1 for j in (data.get("joints") or []) if isinstance(j, dict) and j.get("actuated"))
        moves = ("each drive has its own slider below the drawing, the long one sweeps the first" if drives > 1
                 else "the input slider moves the drive")
        msg = (f"spatial mechanism: 3-D view (drag to orbit, wheel to zoom, Reset; {moves}); structure and rank "
               "analysis in the Analysis tab")
    else:
        msg = ("spatial mechanism: structure and rank analysis only (see the Analysis tab); the drawing is its "
               f"top view. Spatial kinematics cannot move it: {problem}")
    return {"level": "note", "message": msg, "blocks": True, "elements": []}


def rigid_problem(data: Any) -> dict[str, Any] | None:
    """An error when a spatial file with drives cannot move at the drawn pose: its finite
    mobility (the local dimension of the configuration space, idle motions left out) is 0,
    as for a Bennett linkage whose special geometry an edit broke. The message carries the
    rank method's reading (:func:`mechsyn.structure.rank.mobility_reading`). None when it
    moves, has no drive, or the rank method cannot read its geometry.

    Examples
    --------
    >>> from mechsyn.io import load_mechanism, mechanism_to_dict
    >>> from mechsyn.web._service import example_path
    >>> rigid_problem(mechanism_to_dict(load_mechanism(example_path("bennett")))) is None
    True
    >>> d = rigid_problem(mechanism_to_dict(load_mechanism(example_path("spatial_4r_generic"))))
    >>> d["level"], d["message"][:61]
    ('error', 'spatial mechanism, rigid at the drawn pose: finite mobility 0')
    """
    mech = _service.build(data)
    drives = [j.id for j in mech.joints if j.actuated]
    try:
        ra = analyze_rank(mech)
    except MechsynInputError:  # the rank method cannot read the geometry (told in the Analysis tab)
        return None
    if not drives or ra.finite_mobility is None or ra.finite_mobility - len(ra.idle_mobilities) > 0:
        return None
    idle = f", {len(ra.idle_mobilities)} idle" if ra.idle_mobilities else ""
    names = ", ".join(drives)
    return {"level": "error", "blocks": True, "short": "rigid: cannot turn",
            "message": (f"spatial mechanism, rigid at the drawn pose: finite mobility {ra.finite_mobility}{idle}, "
                        f"so the drive on {names} cannot move it ({ra.mobility_reading}). If an edit made it rigid, "
                        "a special geometry that let it move (e.g. Bennett's condition on the link lengths and "
                        "twists) no longer holds: undo it (Ctrl+Z) or move the joint back"),
            "elements": [{"kind": "joint", "id": d} for d in drives]}


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


def _sweep(data: Any, steps: int):
    """The spatial file's sweep of its first drive: ``(mech, drive, home, sim, ok, digits,
    shown)``, ``digits`` the decimals of 1e-10 of the length scale, ``shown`` the named
    points (every joint off the frame when the file names none)."""
    mech = _service.build(data)
    if mech.kind != "spatial":
        raise MechsynInputError("the 3-D view is for spatial files", field="kind", hint="kind: spatial")
    drive, values, home = _sweep_of(mech, steps)
    named = list(mech.points)
    sim = simulate(mech, {drive: values}, points=named or None)
    L = float(sim.length_scale)
    digits = int(max(0, 10 - np.floor(np.log10(L)))) if L > 0 else 10
    shown = named or [j.id for j in mech.joints if j.point is not None and mech.ground not in j.links]
    return mech, drive, home, sim, np.asarray(sim.assembled, bool), digits, shown


def _common(mech, drive: str, home: int, sim) -> dict[str, Any]:
    """The fields the view and the plots share: the input, the rows and what happened."""
    d = sim.to_dict()
    return {"mechanism": mech.name, "engine": sim.engine, "method": sim.method, "ground": mech.ground,
            "input": {**d["input"], "type": sim.input_types[drive]}, "home": home,
            "assembled": np.asarray(sim.assembled, bool).tolist(), "length_scale": float(sim.length_scale),
            "working_ranges": d["working_ranges"], "events": d["events"], "notes": d["notes"]}


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

    mech, drive, home, sim, ok, digits, shown = _sweep(data, steps)
    poses = _poses(sim, mech.link_names)
    res = np.asarray(sim.residual, float)[ok]
    return to_jsonable({
        **_common(mech, drive, home, sim), "links": list(mech.link_names),
        "joints": [_joint(j, poses, ok, digits) for j in mech.joints if j.point is not None],
        "paths": {n: {"link": _link_of(mech, n), "position": _rows(sim.point(n), ok, digits)} for n in shown},
        "residual": float(res.max()) if res.size else None,
    })


def _link_of(mech, name: str) -> str:
    """The link a shown point rides on: a named point's, or a joint's second link."""
    return mech.points[name].link if name in mech.points else mech.joint(name).links[1]


def _values(a: np.ndarray, ok: np.ndarray, significant: int = 10) -> list:
    """Rows of ``a`` rounded to ``significant`` digits of its largest finite magnitude, None
    where not assembled or not finite (the plots' values: rates grow large near a dead point)."""
    a = np.asarray(a, float)
    good = a[ok][np.isfinite(a[ok])]
    big = float(np.abs(good).max()) if good.size else 0.0
    digits = int(significant - 1 - np.floor(np.log10(big))) if big > 0 else significant
    return _rows(a, ok, digits) if a.ndim > 1 else [
        float(v) if g and np.isfinite(v) else None for v, g in zip(np.round(a, digits), ok)]


def plots(data: Any, steps: int = 180) -> dict[str, Any]:
    """What the studio's Plots tab draws for a spatial file, over the 3-D view's sweep (the
    same rows, so its cursor is the view's input slider): ``ms.simulate``'s
    ``SpatialSimulation`` at a drive speed of 1 (rad/s for an R or H drive, length unit/s
    for a P drive; the page scales velocities by the speed typed, accelerations by its
    square).

    Returns the view's common fields (``input``, ``home``, ``assembled``, ``events``,
    ``working_ranges``, ``notes``, ``length_scale``) and ``pairs`` (each pair's rotation in
    degrees or slide in length units from the drawn assembly, ``{"joint", "kind": "angle" |
    "slide", "unit", "values"}`` keyed as ``SpatialSimulation.joints``), ``points`` (the
    view's points: ``link``, ``position``, ``velocity``, ``acceleration`` as [x, y, z] per
    row) and ``links`` (every moving link's ``angular_velocity`` and
    ``angular_acceleration``, [x, y, z] per row). Rows that are not assembled are None.

    Examples
    --------
    >>> from mechsyn.io import load_mechanism, mechanism_to_dict
    >>> from mechsyn.web._service import example_path
    >>> p = plots(mechanism_to_dict(load_mechanism(example_path("spherical_fourbar"))), steps=36)
    >>> sorted(p["pairs"]), p["pairs"]["D"]["unit"], sorted(p["points"])
    (['A', 'B', 'C', 'D'], 'deg', ['P'])
    """

    mech, drive, home, sim, ok, digits, shown = _sweep(data, steps)
    pairs = {}
    for key, v in sim.joints.items():
        slide = key.endswith("/slide") or mech.joint(key.split("/")[0]).type == "P"
        pairs[key] = {"joint": key.split("/")[0], "kind": "slide" if slide else "angle",
                      "unit": "length" if slide else "deg", "values": _values(v, ok)}
    points = {}
    for n in shown:
        pm = sim.points[n]
        points[n] = {"link": _link_of(mech, n), "position": _rows(pm.position, ok, digits),
                     "velocity": _values(pm.velocity, ok), "acceleration": _values(pm.acceleration, ok)}
    links = {n: {"angular_velocity": _values(lp.angular_velocity, ok),
                 "angular_acceleration": _values(lp.angular_acceleration, ok)} for n, lp in sim.links.items()}
    return to_jsonable({**_common(mech, drive, home, sim), "pairs": pairs, "points": points, "links": links})


def routes() -> list:
    """The 3-D view's routes, ``POST /api/spatial/view`` and ``POST /api/spatial/plots``
    ``{"mechanism", "steps"?}`` (registered by :func:`mechsyn.web._app._routes`; each sweep
    runs as a capped, cancellable worker process, :func:`mechsyn.web._routing._heavy`)."""

    def on_sweep(name: str):
        @api
        async def route(request) -> Any:
            body = await _parsed(request, SweepBody)
            return await _heavy(request, f"_spatial:{name}", body.mechanism, body.steps)
        return route

    return [Route("/api/spatial/view", on_sweep("view"), methods=["POST"]),
            Route("/api/spatial/plots", on_sweep("plots"), methods=["POST"])]
