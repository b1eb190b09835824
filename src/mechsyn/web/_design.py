"""The studio as a designer's tool (issue 40): dimensions typed as design variables, the
3-pose Burmester curves to choose from, the instant centres of a pose, a cam's profile and
robots driven by their tool point. Each function takes and returns plain JSON-able data
and makes its call into the library (:mod:`mechsyn.kinematics.dimensions`,
:mod:`mechsyn.synthesis.exact`, :mod:`mechsyn.kinematics.centres`,
:mod:`mechsyn.kinematics.inverse`); :func:`routes` registers them (one line in
:mod:`mechsyn.web._app`).

Examples
--------
>>> from mechsyn.io import load_mechanism, mechanism_to_dict
>>> from mechsyn.web._service import example_path
>>> d = mechanism_to_dict(load_mechanism(example_path("crank_rocker")))
>>> out = set_dimension(d, {"link": "rocker", "kind": "length", "value": 3.2})
>>> [round(x["value"], 9) for x in dimension_list(out["mechanism"]) if x["kind"] == "length"]
[4.0, 1.0, 3.5, 3.2]
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from starlette.concurrency import run_in_threadpool
from starlette.routing import Route

from mechsyn.errors import MechsynInputError
from mechsyn.io import mechanism_to_dict
from mechsyn.kinematics import dimensions as dims
from mechsyn.kinematics.centres import instant_centres
from mechsyn.kinematics.analysis import drawn_inputs, simulate
from mechsyn.kinematics.derived import grashof, is_fourbar
from mechsyn.kinematics.inverse import posed, simulate_inverse
from mechsyn.results import to_jsonable
from mechsyn.synthesis.exact import _rot, center_point_curve
from mechsyn.synthesis.export import fourbar_mechanism_dict
from mechsyn.synthesis.fourbar import fourbar_position
from mechsyn.synthesis.motion_choice import linkage_from_pivots, motion_choices, motion_quality
from mechsyn.web import _service
from mechsyn.web._routing import _heavy, _parsed, api
from mechsyn.web._schema import BurmesterBody, CentresBody, DimensionBody, MechanismBody, PoseBody, ReachBody


def _number(value: Any, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise MechsynInputError(f"expected a number, got {str(value)[:40]!r}", field=field)
    return float(value)


# --------------------------------------------------------------------------- dimensions
def dimension_list(data: Any) -> list[dict[str, Any]]:
    """Every dimension of a planar mechanism dict (:func:`mechsyn.kinematics.dimensions.dimensions`)."""

    mech = _service.build(data)
    if mech.kind != "planar":
        return []
    return [d.to_dict() for d in dims.dimensions(mech)]


def set_dimension(data: Any, change: Any) -> dict[str, Any]:
    """The mechanism with one dimension changed and re-assembled on the drawn branch:
    ``change`` is ``{"link", "kind", "value", "joints"}`` (kinds of
    :class:`mechsyn.kinematics.dimensions.Dimension`). Returns ``{"mechanism", "notes"}``;
    where it cannot assemble, the library's one-line error (nothing changes)."""

    if not isinstance(change, dict):
        raise MechsynInputError("the change must be an object {link, kind, value}", field="change")
    mech = _service.build(data)
    kind, link = change.get("kind", "length"), str(change.get("link", ""))
    value = _number(change.get("value"), kind if kind in ("offset", "angle") else "length")
    joints = [str(j) for j in change.get("joints") or []]
    if kind == "length":
        new = dims.set_length(mech, link, value)
    elif kind == "side":
        new = dims.set_side(mech, link, tuple(joints[:2]), value)
    elif kind in ("offset", "angle"):
        if not joints:
            raise MechsynInputError("name the slider's P joint", field="joints")
        new = dims.set_slider(mech, joints[0], **{kind: value})
    else:
        raise MechsynInputError(f"unknown dimension {str(kind)[:20]!r}", field="kind",
                                hint="length, side, offset or angle")
    return {"mechanism": mechanism_to_dict(new), "notes": _grashof_change(mech, new)}


def _grashof_change(old: Any, new: Any) -> list[str]:
    """A four-bar whose Grashof class the change altered, in words."""
    if not is_fourbar(old):
        return []

    a, b = grashof(old), grashof(new)
    if a.classification == b.classification:
        return []
    return [f"the four-bar is now {b.classification} (was {a.classification}): {b.expression}"]


# --------------------------------------------------------------------------- motion synthesis
def motion_results(poses: Any, pivots: Any = None, show_all: bool = False) -> dict[str, Any]:
    """The Synthesis tab's motion results through 3 to 5 ``poses`` (rows x, y, angle in
    radians): ranked and labelled four-bars (:func:`mechsyn.synthesis.motion_choice.motion_choices`),
    or, for 3 poses and two moving ``pivots`` (drawing coordinates at pose 1), the linkage they
    give. Each result carries its mechanism, the guided point's path over the motion and its
    pivots (fixed, moving, and the moving ones' positions at every pose) for the canvas; for 4
    poses ``curves`` has the centre-point and circle-point curves (pose 1)."""


    P = np.asarray(poses, float)
    if pivots is not None:
        if not isinstance(pivots, list) or len(pivots) != 2:
            raise MechsynInputError("give two moving pivots [[x, y], [x, y]]", field="pivots")
        a, b = (np.asarray([_number(v, "pivots") for v in p], float) if isinstance(p, list) and len(p) == 2
                else _bad_pivot() for p in pivots)
        choices = [motion_quality(linkage_from_pivots(P, a, b), P)]
    else:
        choices = motion_choices(P, keep_unbuildable=show_all)
    results = [_motion_item(c, P) for c in choices]
    out: dict[str, Any] = {"kind": "motion", "targets": P[:, :2].tolist(), "results": results, "notes": []}
    if pivots is None:
        out["notes"].append(f"{len(results)} linkage{'s' if len(results) != 1 else ''} shown, each verified by simulation"
                            + ("" if show_all else " (buildable only: one branch, the poses in order, at most "
                               "10× the poses' size)")
                            + ("; drag a moving pivot (◯) on the canvas or type it to see its linkage"
                               if len(P) == 3 else ""))
    if len(P) == 4:
        M, Ps = center_point_curve(P, n_dir=240)
        keep = np.linalg.norm(M - P[:, :2].mean(0), axis=1) < 5 * (float(np.ptp(P[:, :2], axis=0).max()) or 1.0)

        out["curves"] = {"centre": M[keep].tolist(), "circle": [(_rot(P[0, 2]) @ p + P[0, :2]).tolist() for p in Ps[keep]]}
        out["notes"].append("on the canvas: the centre-point curve (red, where fixed pivots may go) and the "
                            "circle-point curve (green, their moving pivots at pose 1)")
    return out


def _bad_pivot() -> Any:
    raise MechsynInputError("a pivot is [x, y]", field="pivots")


def _motion_item(c: Any, P: Any) -> dict[str, Any]:
    """One motion result for the Synthesis tab."""


    r = c.result
    d = r.design()
    item: dict[str, Any] = {"error": float(r.position_error), "feasible": bool(c.buildable), "label": c.label(),
                            "quality": to_jsonable(c.to_dict())}
    pose = fourbar_position(d["r1"], d["r2"], d["r3"], d["r4"], c.crank_angles(), branch=r.branch, rcx=d["rcx"],
                            rcy=d["rcy"], x0=d["x0"], y0=d["y0"], theta0=d["theta0"])
    item["path"] = _service._xy(np.asarray(pose.C).reshape(-1, 2))
    item["pivots"] = {"fixed": [r.O2.tolist(), r.O4.tolist()],
                      "moving": [[(_rot(a) @ p + P[j, :2]).tolist() for j, a in enumerate(P[:, 2])] for p in (r.pA, r.pB)]}
    try:
        item["mechanism"] = fourbar_mechanism_dict(d["r1"], d["r2"], d["r3"], d["r4"], float(r.theta2[0]),
                                                   branch=r.branch, rcx=d["rcx"], rcy=d["rcy"], x0=d["x0"],
                                                   y0=d["y0"], theta0=d["theta0"],
                                                   name="Four-bar motion generator (Burmester)")
    except ValueError:  # not assembled at the first pose (a defect shown with all results)
        pass
    return item


def burmester(params: Any) -> dict[str, Any]:
    """The linkage of two moving pivots picked for 3 poses (``params``: ``targets`` [x, y],
    ``angles`` in degrees, ``pivots``), quick enough for a drag."""

    if not isinstance(params, dict):
        raise MechsynInputError("expected {targets, angles, pivots}", field="body")
    T = np.asarray(params.get("targets"), float)
    A = np.asarray(params.get("angles"), float)
    if T.shape != (3, 2) or A.shape != (3,) or not (np.isfinite(T).all() and np.isfinite(A).all()):
        raise MechsynInputError("moving pivots are picked for 3 poses [x, y] with 3 angles", field="targets")
    return motion_results(np.column_stack([T, np.radians(A)]), params.get("pivots"))


# --------------------------------------------------------------------------- instant centres, cams
def centres(data: Any, inputs: Any = None) -> dict[str, Any]:
    """Every pair of links' instant centre at the drive values ``inputs`` (``{drive: value}``,
    the drawn pose when None): :func:`mechsyn.kinematics.centres.instant_centres`, links
    numbered in file order (the frame first as drawn in the file)."""

    mech = _service.build(data)
    if inputs is not None and not isinstance(inputs, dict):
        raise MechsynInputError("inputs must be {drive: value}", field="inputs")
    vals = {str(k): _number(v, "inputs") for k, v in (inputs or {}).items()}
    number = {n: k + 1 for k, n in enumerate(mech.link_names)}
    return {"centres": [{**c.to_dict(), "numbers": [number[c.links[0]], number[c.links[1]]]}
                        for c in instant_centres(mech, vals)]}


def cam_profiles(data: Any) -> list[dict[str, Any]]:
    """The profile of every cam joint in the drawn pose (a circle sampled at 3° steps, or the
    profile's points), with the cam link and its pivot (an R joint of the cam link)."""

    mech = _service.build(data)
    out = []
    for j in mech.joints:
        prof = j.attrs.get("profile") if j.type == "cam" else None
        if prof is None:
            continue
        if isinstance(prof, dict) and "points" in prof:
            prof = prof["points"]
        if isinstance(prof, dict):
            c, r = np.asarray(prof["center"], float), float(prof["radius"])
            t = np.radians(np.arange(0, 360, 3.0))
            pts = np.column_stack([c[0] + r * np.cos(t), c[1] + r * np.sin(t)])
        else:
            pts = np.asarray(prof, float)
        cam = j.links[0]
        pivot = next((x.id for x in mech.joints_of(cam) if x.type == "R"), None)
        out.append({"joint": j.id, "link": cam, "pivot": pivot, "points": pts.tolist()})
    return out


# --------------------------------------------------------------------------- robots
def _tool_points(mech: Any) -> list[str]:
    """The points a tool may be: the named points, then the joints off the frame of the link
    with the most joints (a parallel robot's platform) and the other moving joints."""
    counts = {n: len(mech.joints_of(n)) for n in mech.moving_links}
    platform = max(counts, key=counts.get) if counts else None
    on = [j.id for j in mech.joints if platform in j.links and mech.ground not in j.links]
    rest = [j.id for j in mech.joints if mech.ground not in j.links and j.id not in on]
    return list(mech.points) + on + rest


def drives(data: Any) -> dict[str, Any]:
    """Every drive's value at the drawn pose (the engine's convention: a planar R drive's angle
    in degrees, a spatial file's drives 0 at the drawn assembly) and the tool point choices
    with their drawn positions."""


    mech = _service.build(data)
    values = drawn_inputs(mech)
    out = {"drives": [{"id": j.id, "type": j.type, "value": values[j.id]} for j in mech.joints if j.actuated],
           "tools": [], "spatial": mech.kind != "planar", "length_scale": _service._scale(mech)}
    if len(out["drives"]) >= 2:
        names = _tool_points(mech)
        sim = _pose_sim(mech, values, names)
        out["tools"] = [{"id": n, "at": np.asarray(sim.point(n)[0], float).tolist()} for n in names]
    return out


def _pose_sim(mech: Any, values: dict[str, float], names: list[str]) -> Any:

    return simulate(mech, {k: [float(v)] for k, v in values.items()}, points=names)


def _joint_names(mech: Any) -> list[str]:
    return [j.id for j in mech.joints if j.id not in mech.points] + list(mech.points)


def pose(data: Any, values: Any) -> dict[str, Any]:
    """The mechanism drawn with its drives at ``values`` (``{drive: value}``, the engine's
    convention, :func:`drives`), followed from the drawn pose: ``{"mechanism"}``, or an
    error saying it does not assemble there."""

    mech = _service.build(data)
    if not isinstance(values, dict):
        raise MechsynInputError("values must be {drive: value}", field="values")
    u = drawn_inputs(mech)
    for k, v in values.items():
        if k not in u:
            raise MechsynInputError(f"{str(k)[:20]} is not a drive", field="values", hint=", ".join(u))
        u[k] = _number(v, "values")
    sim = _pose_sim(mech, u, _joint_names(mech))
    if not bool(sim.assembled[0]):
        raise MechsynInputError("the mechanism does not assemble with the drives there", field="values",
                                hint="move the drive back")
    return {"mechanism": mechanism_to_dict(posed(mech, sim, 0))}


def reach(data: Any, point: Any, target: Any, steps: int = 8) -> dict[str, Any]:
    """Inverse kinematics from the drawn pose: tool ``point`` moved in ``steps`` straight steps
    to ``target`` (:func:`mechsyn.kinematics.inverse.simulate_inverse`); ``{"mechanism"
    (drawn at the last target reached), "reached", "message", "values"}``."""


    mech = _service.build(data)
    if not isinstance(point, str) or point not in _tool_points(mech):
        raise MechsynInputError(f"{str(point)[:20]!r} is no point of this mechanism", field="point")
    if not isinstance(target, list) or not all(isinstance(c, (int, float)) for c in target):
        raise MechsynInputError("the target is [x, y] (or [x, y, z])", field="target")
    T = np.asarray([_number(c, "target") for c in target], float)
    u0 = drawn_inputs(mech)
    p0 = np.asarray(_pose_sim(mech, u0, [point]).point(point)[0], float)
    path = p0 + np.linspace(0, 1, steps + 1)[1:, None] * (T - p0)
    res = simulate_inverse(mech, point, path, start=u0)
    k = int(np.flatnonzero(res.reached)[-1]) if res.reached.any() else -1
    out: dict[str, Any] = {"reached": bool(res.ok), "message": res.message, "mechanism": None, "values": None}
    if k >= 0:
        vals = {n: float(v[k]) for n, v in res.inputs.items()}
        sim = _pose_sim(mech, vals, _joint_names(mech))
        out["mechanism"], out["values"] = mechanism_to_dict(posed(mech, sim, 0)), vals
    return out


# --------------------------------------------------------------------------- routes
def routes() -> list:
    """The routes of this module (quick ones in the server's threads)."""

    @api
    async def dimensions_route(request) -> Any:
        body = await _parsed(request, MechanismBody)
        return {"dimensions": await run_in_threadpool(dimension_list, body.mechanism)}

    @api
    async def dimension_route(request) -> Any:
        body = await _parsed(request, DimensionBody)
        return await run_in_threadpool(set_dimension, body.mechanism, body.change)

    @api
    async def burmester_route(request) -> Any:
        return await run_in_threadpool(burmester, (await _parsed(request, BurmesterBody)).model_dump())

    @api
    async def drives_route(request) -> Any:
        return await _heavy(request, "_design:drives", (await _parsed(request, MechanismBody)).mechanism)

    @api
    async def pose_route(request) -> Any:
        body = await _parsed(request, PoseBody)
        return await _heavy(request, "_design:pose", body.mechanism, body.values)

    @api
    async def reach_route(request) -> Any:
        body = await _parsed(request, ReachBody)
        return await _heavy(request, "_design:reach", body.mechanism, body.point, body.target)

    @api
    async def centres_route(request) -> Any:
        body = await _parsed(request, CentresBody)
        return await _heavy(request, "_design:centres", body.mechanism, body.inputs)

    @api
    async def cams_route(request) -> Any:
        return {"cams": await run_in_threadpool(cam_profiles, (await _parsed(request, MechanismBody)).mechanism)}

    return [Route("/api/design/burmester", burmester_route, methods=["POST"]),
            Route("/api/design/centres", centres_route, methods=["POST"]),
            Route("/api/design/cams", cams_route, methods=["POST"]),
            Route("/api/design/drives", drives_route, methods=["POST"]),
            Route("/api/design/pose", pose_route, methods=["POST"]),
            Route("/api/design/reach", reach_route, methods=["POST"]),
            Route("/api/design/dimensions", dimensions_route, methods=["POST"]),
            Route("/api/design/dimension", dimension_route, methods=["POST"])]
