"""Server-side logic of the studio's editor: invalid states in the studio's words, and the
DXF plates / SVG drawing exports.

The routes are registered by :func:`routes` (one line in :mod:`mechsyn.web._app`). Every
function takes and returns plain JSON-able data, like :mod:`mechsyn.web._service`.

Diagnostics are ``{"level", "message", "elements", "blocks"}``: ``level`` is ``error``,
``warning`` or ``note``; ``elements`` the ``{"kind", "id"}`` the message names (outlined on
the canvas); ``blocks`` true when simulating would be pointless (a structure, drives that
fight, parts joined to nothing, a spatial file).

Examples
--------
>>> from mechsyn.io import load_mechanism, mechanism_to_dict
>>> from mechsyn.web._service import example_path
>>> d = mechanism_to_dict(load_mechanism(example_path("fourbar")))
>>> check(d)["mobility"], check(d)["diagnostics"]
(1, [])
"""

from __future__ import annotations

import functools
import io
import math
from typing import Any

import numpy as np
from starlette.concurrency import run_in_threadpool
from starlette.responses import Response
from starlette.routing import Route

from mechsyn.errors import MechsynInputError
from mechsyn.export.drawing import drawing_of
from mechsyn.export.dxf import layout_to_dxf
from mechsyn.export.plates import link_plates
from mechsyn.io import load_mechanism
from mechsyn.kinetostatics import forces as _forces
from mechsyn.progress import Progress, ProgressCallback
from mechsyn.results import to_jsonable
from mechsyn.structure.drives import DriveCheck
from mechsyn.structure.report import analyze as structure_report
from mechsyn.web import _service
from mechsyn.web._design import motion_results
from mechsyn.web._routing import _heavy, _parsed, api
from mechsyn.web._schema import ForcesBody, MechanismBody, mechanism_types
from mechsyn.web._spatial import check_note


def _names(ids: list[str]) -> str:
    return ids[0] if len(ids) == 1 else ", ".join(ids[:-1]) + " and " + ids[-1]


def _diag(level: str, message: str, elements: list[tuple[str, str]], blocks: bool, short: str = "") -> dict[str, Any]:
    """One diagnostic; ``short`` is the few words written next to the element on the canvas."""
    return {"level": level, "message": message, "blocks": blocks, "short": short or message.split(":")[0],
            "elements": [{"kind": k, "id": i} for k, i in elements]}


def connection_problems(data: dict[str, Any]) -> list[dict[str, Any]]:
    """Links joined to nothing, links with one joint (dangling) and parts not connected to the
    frame of a mechanism dict (checked before it is validated: the file loader refuses a
    disconnected mechanism), in the studio's words: what to do on the canvas, not in the file."""
    ground = data.get("ground", "frame")
    names = [link if isinstance(link, str) else str(link.get("name")) for link in data.get("links", [])]
    joints = [j for j in data.get("joints", []) if isinstance(j, dict)]
    joints_of: dict[str, list] = {n: [] for n in names}
    for j in joints:
        for link in j.get("links", []):
            joints_of.setdefault(str(link), []).append(j)
    out = []
    for j in joints:  # a pivot just placed: not a file error, the next step of a build
        if len(j.get("links", [])) < 2:
            kind = "pivot" if ground in j.get("links", []) else "joint"
            out.append(_diag("note", f"{kind} {j.get('id')} is not joined to a moving link yet: choose Link, click "
                             f"{j.get('id')} and then the places of the link's other joints (Enter finishes)",
                             [("joint", str(j.get("id")))], True, "not joined yet"))
    for name, js in joints_of.items():
        if name == ground:
            continue
        if not js:
            out.append(_diag("error", f"link {name} is joined to nothing: join it with Link or delete it",
                             [("link", name)], True, "joined to nothing"))
        elif len(js) == 1 and not js[0].get("actuated"):  # a driven end link (a crank, a serial end) is fine
            out.append(_diag("error", f"link {name} has one joint ({js[0].get('id')}): join it to another "
                             "link with Link, or delete it", [("link", name)], True, "one joint only"))
    seen, todo = {ground}, [ground]
    while todo:
        link = todo.pop()
        for j in joints_of.get(link, []):
            for other in map(str, j.get("links", [])):
                if other not in seen:
                    seen.add(other)
                    todo.append(other)
    loose = [n for n in joints_of if n not in seen and joints_of[n]]
    if loose:
        many = len(loose) > 1
        out.append(_diag("error", f"link{'s' if many else ''} {_names(loose)} {'are' if many else 'is'} not "
                         "connected to the frame: add a Pivot and join it to them with Link",
                         [("link", n) for n in loose], True, "not connected to the frame"))
    return out


def drive_problems(mech, mobility: int, excess: list[str] | None = None) -> list[dict[str, Any]]:
    """A structure with a drive, more drives than the mobility (``excess``: the rank method's
    drives in excess, :func:`mechsyn.structure.drives.excess_drives`; else the last ones),
    fewer (motion undetermined), none at all."""
    drives = [j.id for j in mech.joints if j.actuated]
    els = [("joint", d) for d in drives]
    n = len(drives)
    if mobility <= 0 and drives:
        return [_diag("error", f"this is a structure, not a mechanism (mobility W = {mobility}): nothing can "
                      f"move, so the drive on {_names(drives)} cannot turn it. Delete a link or a joint, or "
                      "remove the drive", els, True, "a structure: cannot turn")]
    if n > mobility >= 1:  # the same line as analyze's verdict and simulate's refusal
        extra = [d for d in (excess or drives[mobility:]) if d in drives] or drives[mobility:]
        line = DriveCheck(drives, mobility, extra, "rank method").text(
            fix=f"the drives fight each other; remove the drive on {_names(extra)} (Drive, then click it)")
        return [_diag("error", line, [("joint", d) for d in extra], True, "one drive too many")]
    if n == 0 and mobility >= 1:
        return [_diag("note", f"no drive yet (mobility W = {mobility}): select the input joint and press "
                      "Drive to move the mechanism", [], True, "no drive yet")]
    if 0 < n < mobility and not any(j.vll for j in mech.joints):  # a locked VLL joint takes up a freedom
        return [_diag("warning", f"mobility W = {mobility} with {n} drive{'s' if n > 1 else ''}: the motion is "
                      f"not determined. Mark {mobility - n} more joint{'s' if mobility - n > 1 else ''} with "
                      "Drive", els, True, "more drives needed")]
    return []


def check(data: Any) -> dict[str, Any]:
    """The editor's checks of a mechanism dict, fast enough for every edit of its topology.

    Returns ``{"mobility", "mobility_source", "drives", "spatial", "diagnostics"}``. The
    mobility is the structure report's (the rank method where the geometry allows it).
    A file that does not validate raises :class:`~mechsyn.errors.MechsynInputError`
    (shown by the studio next to the element its field names).
    """

    mechanism_types(data)  # a wrong type is an input error here, not a crash of the checks below
    problems = connection_problems(data)
    drives = [str(j.get("id")) for j in data.get("joints", []) if isinstance(j, dict) and j.get("actuated")]
    out: dict[str, Any] = {"mobility": None, "mobility_source": None, "drives": drives,
                           "spatial": data.get("kind", "planar") != "planar", "diagnostics": problems}
    if problems:
        return out
    mech = _service.build(data)
    if out["spatial"]:  # view3d: the 3-D view where the spatial engine moves the file, else the old note
        out["diagnostics"].append(check_note(data))
    try:
        report = structure_report(mech)
    except MechsynInputError as err:
        out["diagnostics"].append(_diag("warning", f"mobility not known: {err.message}", [], False))
        return out
    out["mobility"], out["mobility_source"] = int(report.mobility), report.to_dict().get("mobility_source")
    if not out["spatial"] and not any(d["blocks"] for d in out["diagnostics"]):
        out["diagnostics"] += geometry_problems(data, mech, report.rank, out["mobility"])
    return out


def geometry_problems(data: dict[str, Any], mech, rank, mobility: int) -> list[dict[str, Any]]:
    """The drive checks against the motion the joints' places allow (the rank method's finite
    mobility where it knows it: a four-bar drawn folded moves with one drive although its
    instantaneous mobility is 2; one pulled taut cannot move at all), and a redundant bar named
    when the mechanism moves only thanks to exact dimensions (a double parallelogram)."""
    finite = getattr(rank, "finite_mobility", None) if rank is not None else None
    excess = list(getattr(rank, "excess_drives", None) or [])
    if finite is None or finite >= mobility:  # (idle mobilities, a roller's spin, count in the finite one)
        out = drive_problems(mech, mobility, excess)
    elif finite <= 0 < mobility:
        return [_diag("error", f"cannot move: the links are pulled taut at the drawn places (instantaneous mobility "
                      f"W = {mobility}, finite mobility {finite}: only an infinitesimal motion). Change a link's length "
                      "or move a joint", [("joint", j.id) for j in mech.joints if j.actuated], True, "cannot move")]
    else:
        out = drive_problems(mech, finite, excess)
    if rank is not None and rank.redundant_constraints > 0 and (finite or mobility) >= 1 and not out:
        out += _redundant_bars(data, rank)
    return out


#: The most bars :func:`_redundant_bars` removes one by one (a rank analysis each, ~10 ms).
MAX_BARS_TRIED = 12


def _redundant_bars(data: dict[str, Any], rank) -> list[dict[str, Any]]:
    """A note naming the bars (links of two pins) any one of which repeats a constraint of the
    others: removed, the mechanism keeps its motion and loses the redundant constraint."""
    names = [link if isinstance(link, str) else str(link.get("name")) for link in data.get("links", [])]
    ground = data.get("ground", "frame")
    candidates = []
    for name in names:
        js = [j for j in data["joints"] if name in j.get("links", [])]
        if name != ground and len(js) == 2 and not any(j.get("type") != "R" or j.get("actuated") for j in js):
            candidates.append((name, js))
    if len(candidates) > MAX_BARS_TRIED:  # a rank analysis each: the check stays quick on big files
        return []
    bars = []
    for name, js in candidates:
        rest = {**data, "links": [x for x, n in zip(data["links"], names) if n != name],
                "joints": [j for j in data["joints"] if j not in js],
                "points": {k: p for k, p in (data.get("points") or {}).items() if p.get("link") != name}}
        try:
            r = structure_report(_service.build(rest)).rank
        except MechsynInputError:
            continue
        if r is not None and r.redundant_constraints < rank.redundant_constraints and \
                r.finite_mobility == rank.finite_mobility:
            bars.append(name)
    if not bars:
        return []
    q = rank.redundant_constraints
    which = bars[0] if len(bars) == 1 else "any one of " + ", ".join(bars[:-1]) + " or " + bars[-1]
    return [_diag("note", f"{which} is redundant ({q} redundant constraint{'s' if q > 1 else ''}): it repeats a "
                  "constraint the other links already make, so removing it leaves the motion as it is. It still moves "
                  "only because its dimensions are exact (equal, parallel bars); made with a small error it would jam "
                  "or strain", [("link", b) for b in bars], False, "redundant bar")]


def export_drawing(data: Any) -> str:
    """The mechanism's SVG drawing in model units at the drawn pose, with the paths of its
    named points over a full input turn (``mechsyn export --drawing``)."""

    mech = _service.build(data)
    drives = [j for j in mech.joints if j.actuated]
    sweep = None
    if drives and drives[0].type == "R" and mech.points:
        start = _service._driver_start(mech, drives[0].id)
        sweep = {drives[0].id: start + np.linspace(0.0, 360.0, 181)}
    return drawing_of(mech, None, list(mech.points) if sweep else [], sweep, dimensions=True)


def export_dxf(data: Any) -> str:
    """The link plates laid out on a sheet as DXF text (``mechsyn export --dxf``; needs ezdxf,
    else a :class:`~mechsyn.errors.MechsynInputError` saying how to install it)."""

    doc = layout_to_dxf(link_plates(_service.build(data)))
    buf = io.StringIO()
    doc.write(buf)
    return buf.getvalue()


def _finite_number(value: Any, field: str) -> float:

    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise MechsynInputError(f"expected a number, got {value!r}", field=field)
    return float(value)


def forces(data: Any, gravity: Any = (0.0, 0.0), speed: Any = 1.0, steps: int = 180) -> dict[str, Any]:
    """Drive torque (or force) and joint reactions over the studio's sweep of the first drive
    (``mechsyn forces``: kinetostatics with the file's link masses, inertias and loads, the
    drive turning at ``speed`` rad/s, or moving at ``speed`` units/s, held constant).

    Returns the library's :meth:`~mechsyn.kinetostatics.analysis.ForceAnalysis.to_dict`.
    """

    if not isinstance(gravity, (list, tuple)) or len(gravity) != 2:
        raise MechsynInputError("gravity must be [gx, gy]", field="gravity")
    g = (_finite_number(gravity[0], "gravity"), _finite_number(gravity[1], "gravity"))
    w = _finite_number(speed, "speed")
    mech = _service.build(data)
    drive, values = _service._sweep(mech, steps, None)
    return to_jsonable(_forces(mech, {drive.id: values}, speeds={drive.id: w}, gravity=g).to_dict())


def synthesize_motion(params: dict[str, Any], progress: ProgressCallback) -> dict[str, Any]:
    """Motion generation through 3 to 5 clicked poses (``params["targets"]`` [x, y] and
    ``params["angles"]`` in degrees): Burmester theory, each four-bar verified by simulation,
    labelled and ranked by :func:`mechsyn.synthesis.motion_choice.motion_choices` (the
    unbuildable ones left out unless ``params["all"]``); for 3 poses, with two moving pivots
    ``params["pivots"]`` (drawing coordinates at pose 1) the linkage they give."""

    T = np.asarray(params.get("targets"), float)
    A = np.asarray(params.get("angles", [0.0] * len(T)), float)
    if T.ndim != 2 or T.shape[1:] != (2,) or not 3 <= len(T) <= 5 or not np.isfinite(T).all():
        raise MechsynInputError("give 3 to 5 poses: click 3 to 5 target points", field="targets",
                                hint="then type each pose's angle in the Synthesis tab")
    if A.shape != (len(T),) or not np.isfinite(A).all():
        raise MechsynInputError("give one angle (degrees) per pose", field="angles")
    progress(Progress(0, 1, "Burmester"))
    out = motion_results(np.column_stack([T, np.radians(A)]), params.get("pivots"), bool(params.get("all", False)))
    progress(Progress(1, 1, "Burmester", min((x["error"] for x in out["results"]), default=None)))
    return out


# the documented extension point of the studio's synthesis kinds
_service.SYNTHESIS_KINDS.setdefault("motion", ("Motion through 3-5 poses (Burmester)", synthesize_motion))


def examples() -> list[dict[str, str]]:
    """The Examples menu: the planar examples (:func:`mechsyn.web._service.examples`), then the
    spatial ones with joint points (opened for structure and rank analysis), each with its ``kind``."""
    planar = [{**e, "kind": "planar"} for e in _service.examples()]
    return planar + [dict(e) for e in _spatial_examples(_service._examples_dir())]


@functools.lru_cache(maxsize=4)
def _spatial_examples(root) -> tuple[dict[str, str], ...]:

    out = []
    for p in sorted(root.rglob("*")) if root is not None else []:
        if p.suffix not in _service.EXAMPLE_SUFFIXES or not p.is_file():
            continue
        try:
            mech = load_mechanism(p)
        except Exception:  # case files and arms are not mechanisms: not listed
            continue
        if mech.kind != "planar" and all(j.point is not None for j in mech.joints):
            out.append({"name": p.stem, "title": mech.name, "group": p.parent.name, "kind": mech.kind})
    return tuple(out)


def routes() -> list:
    """The studio editor's routes (registered by :func:`mechsyn.web._app._routes`). The
    check, forces and the exports run as capped, cancellable worker processes
    (:func:`mechsyn.web._routing._heavy`): nothing heavy in the server's process (a check
    of a large mechanism took minutes there, issue 42)."""

    def on_mechanism(name, media_type=None):
        @api
        async def route(request) -> Any:
            out = await _heavy(request, f"_studio:{name}", (await _parsed(request, MechanismBody)).mechanism)
            return Response(out, media_type=media_type) if media_type else out
        return route

    @api
    async def examples_route(request) -> Any:
        return {"examples": await run_in_threadpool(examples)}

    @api
    async def forces_route(request) -> Any:
        body = await _parsed(request, ForcesBody)
        return await _heavy(request, "_studio:forces", body.mechanism, body.gravity, body.speed, body.steps)

    return [Route("/api/studio/examples", examples_route),
            Route("/api/studio/forces", forces_route, methods=["POST"]),
            Route("/api/studio/check", on_mechanism("check"), methods=["POST"]),
            Route("/api/studio/drawing", on_mechanism("export_drawing", "image/svg+xml"), methods=["POST"]),
            Route("/api/studio/dxf", on_mechanism("export_dxf", "application/dxf"), methods=["POST"])]
