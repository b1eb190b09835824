"""Server side of the studio's 3-D view of spatial mechanisms (``static/view3d.js``) and of
its Plots tab (``static/tabs3d.js``).

:func:`simulate` runs the library's spatial kinematics (:func:`mechsyn.simulate`) over a
sweep of the file's first drive and returns the ``SpatialSimulation``'s
:meth:`~mechsyn.kinematics.spatial_result.SpatialSimulation.to_dict` (what ``mechsyn
simulate --json`` prints): the page places every joint and its axes from the links' poses
(``x = rotation @ x0 + translation``; a joint's point is carried by its second link, its
``axis`` by its first link and a U joint's ``axis2`` by its second link, as
``mechsyn.plot.spatial.joint_frames`` draws them). :func:`engine_problem` says in one line
why the engine cannot move a file (the studio then keeps its top view and the note of
:func:`check_note`). Nothing here imports Matplotlib.

Conventions are the engine's: an R input is measured from the joint's zero (degrees for an
R or H drive, the file's length unit for a P drive).

Examples
--------
>>> from mechsyn.io import load_mechanism, mechanism_to_dict
>>> from mechsyn.web._service import example_path
>>> v = simulate(mechanism_to_dict(load_mechanism(example_path("bennett"))), steps=36)
>>> v["engine"], len(v["assembled"]), sorted(v["points"])
('spatial', 36, ['R1', 'R2', 'R3', 'R4'])
>>> v["input"]["joint"], v["input"]["unit"], sorted(v["links"]["link2"])[:2]
('R1', 'deg', ['angular_acceleration', 'angular_velocity'])
"""

from __future__ import annotations

from typing import Any

import numpy as np
from starlette.routing import Route

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import simulate as _simulate
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
    from mechsyn.kinematics.simulation import input_grid
    from mechsyn.kinematics.spatial_model import input_zero

    drawn = float(np.degrees(input_zero(mech, drive)))  # the drawn pose's input (its zero: the file format)
    return drive.id, input_grid(drawn, drawn + 360.0 - 360.0 / n, 360.0 / n)[:n], 0  # (`--input` gives the same)


def engine_problem(data: Any) -> str | None:
    """Why the spatial engine cannot move this mechanism (its message and fix), or None.

    Runs the engine on the drawn pose only (one row: the pair types, the drive and whether
    the drives determine the motion), which costs a few tens of milliseconds.
    """

    mech = _service.build(data)
    try:
        drive, _, _ = _sweep_of(mech, 2)
        _simulate(mech, {drive: [0.0]})
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


def simulate(data: Any, steps: int = 180) -> dict[str, Any]:
    """The spatial kinematics of a mechanism dict over a sweep of its first drive (a full
    turn from the drawn pose for an R, H or U drive, row 0; ± half the length scale for a P
    or C drive, the drawn pose the middle row), at a drive speed of 1 (rad/s, length unit/s):
    :meth:`SpatialSimulation.to_dict <mechsyn.kinematics.spatial_result.SpatialSimulation.to_dict>`
    (the named points, else every joint). Raises :class:`~mechsyn.errors.MechsynInputError`
    for a planar file, a file without a drive, or one the engine cannot move (its message
    names the pair or drive)."""
    mech = _service.build(data)
    if mech.kind != "spatial":
        raise MechsynInputError("the 3-D view is for spatial files", field="kind", hint="kind: spatial")
    drive, values, _ = _sweep_of(mech, steps)
    return _simulate(mech, {drive: values}, points=list(mech.points) or None).to_dict()


def routes() -> list:
    """The 3-D view's route, ``POST /api/spatial/simulate`` ``{"mechanism", "steps"?}``
    (registered by :func:`mechsyn.web._app._routes`; the sweep runs as a capped, cancellable
    worker process, :func:`mechsyn.web._routing._heavy`)."""

    @api
    async def route(request) -> Any:
        body = await _parsed(request, SweepBody)
        return await _heavy(request, "_spatial:simulate", body.mechanism, body.steps)

    return [Route("/api/spatial/simulate", route, methods=["POST"])]
