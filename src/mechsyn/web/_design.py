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

from starlette.concurrency import run_in_threadpool
from starlette.routing import Route

from mechsyn.errors import MechsynInputError
from mechsyn.results import to_jsonable
from mechsyn.web import _service
from mechsyn.web._routing import _body, _heavy, _need, api


def _number(value: Any, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise MechsynInputError(f"expected a number, got {str(value)[:40]!r}", field=field)
    return float(value)


# --------------------------------------------------------------------------- dimensions
def dimension_list(data: Any) -> list[dict[str, Any]]:
    """Every dimension of a planar mechanism dict (:func:`mechsyn.kinematics.dimensions.dimensions`)."""
    from mechsyn.kinematics.dimensions import dimensions

    mech = _service.build(data)
    if mech.kind != "planar":
        return []
    return [d.to_dict() for d in dimensions(mech)]


def set_dimension(data: Any, change: Any) -> dict[str, Any]:
    """The mechanism with one dimension changed and re-assembled on the drawn branch:
    ``change`` is ``{"link", "kind", "value", "joints"}`` (kinds of
    :class:`mechsyn.kinematics.dimensions.Dimension`). Returns ``{"mechanism", "notes"}``;
    where it cannot assemble, the library's one-line error (nothing changes)."""
    from mechsyn.io import mechanism_to_dict
    from mechsyn.kinematics import dimensions as dims

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
    if not _service._is_four_bar(old):
        return []
    from mechsyn.kinematics.derived import grashof

    a, b = grashof(old), grashof(new)
    if a.classification == b.classification:
        return []
    return [f"the four-bar is now {b.classification} (was {a.classification}): {b.expression}"]


# --------------------------------------------------------------------------- routes
def routes() -> list:
    """The routes of this module (quick ones in the server's threads)."""

    @api
    async def dimensions_route(request) -> Any:
        return {"dimensions": await run_in_threadpool(dimension_list, _need(await _body(request), "mechanism"))}

    @api
    async def dimension_route(request) -> Any:
        body = await _body(request)
        return await run_in_threadpool(set_dimension, _need(body, "mechanism"), _need(body, "change"))

    return [Route("/api/design/dimensions", dimensions_route, methods=["POST"]),
            Route("/api/design/dimension", dimension_route, methods=["POST"])]
