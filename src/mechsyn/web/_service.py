"""Every call of mechsyn studio into the library, in one place.

The routes (:mod:`mechsyn.web._app`) never import the library themselves: they call
these functions, which take and return plain JSON-able data. When the library's public
reports land (``mechsyn.analyze``, an incremental ``simulate``), only this module changes.
"""

from __future__ import annotations

import functools
import math
import re
import threading
from collections import OrderedDict
from dataclasses import replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.simulation import rows
from mechsyn.progress import Progress, ProgressCallback
from mechsyn.results import to_jsonable

MAX_STEPS = 2000
#: The largest mechanism :func:`quick_simulate` answers in the server's process (a
#: linkage drawn by hand; larger files, whose parse and sweep take longer, go to a worker
#: that is stopped when its client leaves).
QUICK_JOINTS = 64
EXAMPLE_SUFFIXES = (".yaml", ".yml", ".json")


# --------------------------------------------------------------------------- examples
def _examples_dir() -> Path | None:
    """The examples shipped with mechsyn (package data when present, else the checkout's)."""
    try:  # the library-first step moves examples into the package
        from mechsyn import examples as _ex  # type: ignore[attr-defined]

        d = Path(_ex.__file__).parent
        if any(d.rglob("*.yaml")):
            return d
    except ImportError:
        pass
    d = Path(__file__).resolve().parents[3] / "examples"
    return d if d.is_dir() else None


def examples() -> list[dict[str, str]]:
    """Planar mechanism examples: ``[{"name", "title", "group"}]`` sorted by group and name."""
    return [dict(e) for e in _examples(_examples_dir())]


@functools.lru_cache(maxsize=4)
def _examples(root: Path | None) -> tuple[dict[str, str], ...]:
    if root is None:
        return ()
    out = []
    for p in sorted(root.rglob("*")):
        if p.suffix not in EXAMPLE_SUFFIXES or not p.is_file():
            continue
        try:
            from mechsyn.io import load_mechanism

            mech = load_mechanism(p)
        except Exception:  # case files and arms are not mechanisms: not listed
            continue
        if mech.kind != "planar" or not all(j.point is not None for j in mech.joints):
            continue
        out.append({"name": p.stem, "title": mech.name, "group": p.parent.name})
    return tuple(out)


def example_path(name: str) -> Path:
    """The file of example ``name`` (its file stem, e.g. ``fourbar``: letters, digits, ``_``
    and ``-`` only, so that a name is never a glob pattern such as ``*``)."""
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_-]{1,80}", name):
        raise MechsynInputError(f"no example named {name[:80]!r}", field="example",
                                hint="an example's name has letters, digits, _ and - only, e.g. fourbar")
    root = _examples_dir()
    hits = [p for p in root.rglob(f"{name}.*") if p.suffix in EXAMPLE_SUFFIXES] if root else []
    if not hits:
        known = ", ".join(e["name"] for e in examples())
        raise MechsynInputError(f"no example named {name!r}", field="example", hint=f"one of: {known}")
    return sorted(hits)[0]


# --------------------------------------------------------------------------- mechanism files
def read_mechanism(path: Path) -> dict[str, Any]:
    """A mechanism file read, validated and returned in the file format (dict)."""
    from mechsyn.io import load_mechanism, mechanism_to_dict

    if path.suffix.lower() == ".pyslvs":
        from mechsyn.io.files import read_text

        return parse_mechanism_text(read_text(path, "Pyslvs file"), path.name)
    return mechanism_to_dict(load_mechanism(path))


def parse_mechanism_text(text: str, filename: str) -> dict[str, Any]:
    """An uploaded file's text → file-format dict: a mechanism file (YAML or JSON) or a
    Pyslvs expression (``.pyslvs``, :mod:`mechsyn.io.pyslvs`)."""
    from mechsyn.io import mechanism_from_dict, mechanism_from_text, mechanism_to_dict

    if filename.lower().endswith(".pyslvs"):
        from mechsyn.io.pyslvs import read_pyslvs

        data, _notes = read_pyslvs(text, filename)
        return mechanism_to_dict(mechanism_from_dict(data, source=filename))
    return mechanism_to_dict(mechanism_from_text(text, source=filename))


def mechanism_text(data: dict[str, Any], suffix: str) -> str:
    """The mechanism as YAML or JSON text (validated first)."""
    from mechsyn.io import mechanism_from_dict, mechanism_to_dict

    d = mechanism_to_dict(mechanism_from_dict(data, source="mechanism"))
    if suffix == ".json":
        import json

        return json.dumps(d, indent=2) + "\n"
    import yaml

    return yaml.safe_dump(d, sort_keys=False, allow_unicode=True)


# --------------------------------------------------------------------------- validation
def _element_of(data: Any, field: str | None) -> dict[str, str] | None:
    """``joints[2].links`` → ``{"kind": "joint", "id": <id of joints[2]>}``."""
    if not field:
        return None
    head = field.split(".")[0]
    for kind, key in (("joint", "joints"), ("link", "links")):
        if head.startswith(key + "["):
            try:
                k = int(head[len(key) + 1:].split("]")[0])
                item = data[key][k]
            except (ValueError, IndexError, KeyError, TypeError):
                return {"kind": kind, "id": ""}
            ident = item.get("id", item.get("name", "")) if isinstance(item, dict) else item
            return {"kind": kind, "id": str(ident)}
    if head.startswith("points"):
        name = field.split(".")[1] if "." in field else ""
        return {"kind": "point", "id": name}
    return None


def error_dict(err: MechsynInputError, data: Any = None) -> dict[str, Any]:
    """One input error as ``{"message", "field", "hint", "element"}``."""
    return {"message": err.message, "field": err.field, "hint": err.hint, "element": _element_of(data, err.field)}


def build(data: Any):
    """Validate a mechanism dict: the :class:`~mechsyn.model.mechanism.Mechanism`."""
    from mechsyn.io import mechanism_from_dict

    if not isinstance(data, dict):
        raise MechsynInputError("the mechanism must be a JSON object", field="mechanism")
    try:
        return mechanism_from_dict(data, source="mechanism")
    except MechsynInputError as err:
        err.element = _element_of(data, err.field)  # type: ignore[attr-defined]
        raise


def validate(data: Any) -> dict[str, Any]:
    """``{"ok", "errors": [...], "mechanism": normalised dict or None}``."""
    from mechsyn.io import mechanism_to_dict

    try:
        mech = build(data)
    except MechsynInputError as err:
        return {"ok": False, "errors": [error_dict(err, data)], "mechanism": None}
    return {"ok": True, "errors": [], "mechanism": mechanism_to_dict(mech)}


# --------------------------------------------------------------------------- simulation
def _xy(a: np.ndarray) -> list:
    """The points as [x, y] lists, None where a coordinate is not finite (not assembled)."""
    return rows(a)


def _driver_start(mech, jid: str) -> float:
    """The file's value of driven joint ``jid``: crank angle (deg) of an R, 0 for a P."""
    from mechsyn.kinematics.analysis import cached_plan

    S = cached_plan(mech, inputs=(jid,)).system  # the plan simulate() then uses
    for d in S.drivers:
        if d.joint == jid:
            return float(np.degrees(d.assembled)) if d.type == "R" else float(d.assembled)
    raise MechsynInputError(f"joint {jid} is not driven", field="input", hint="mark it as a drive")


def _sweep(mech, steps: int, span: float | None) -> tuple[Any, np.ndarray]:
    """The first drive and its input values, starting at the drawn configuration: the grid
    of :func:`~mechsyn.kinematics.simulation.input_grid` (``mechsyn simulate --input
    A=START:STOP:STEP`` gives the same numbers)."""
    from mechsyn.kinematics.simulation import input_grid

    drives = [j for j in mech.joints if j.actuated]
    if not drives:
        raise MechsynInputError("no drive: nothing moves", field="joints",
                                hint="mark a joint to the frame as a drive")
    if not 2 <= int(steps) <= MAX_STEPS:
        raise MechsynInputError(f"steps must be within 2..{MAX_STEPS}", field="steps")
    drive = drives[0]
    start = _driver_start(mech, drive.id)
    n = int(steps)
    if drive.type == "P":
        span = _scale(mech) if span is None else span
        return drive, input_grid(start - span / 2, start + span / 2, span / (n - 1))[:n]
    if span is None or abs(span - 360.0) < 1e-12:
        return drive, input_grid(start, start + 360.0 - 360.0 / n, 360.0 / n)[:n]
    return drive, input_grid(start, start + span, span / (n - 1))[:n]


def sweep_inputs(data: Any, steps: int = 180, span: float | None = None) -> dict[str, np.ndarray]:
    """The studio's sweep of a planar mechanism dict: ``{first drive: values}`` from the
    drawn configuration over ``span`` (360 deg for an R drive, the length scale around the
    drawn slide for a P drive) in ``steps``."""
    drive, values = _sweep(build(data), steps, span)
    return {drive.id: values}


def simulate(data: Any, steps: int = 180, span: float | None = None, rates: bool = True) -> dict[str, Any]:
    """The simulation of a planar mechanism dict over the studio's sweep of its first drive
    (:func:`sweep_inputs`; index 0 is the file's pose), reporting every joint and named
    point: :meth:`SimulationReport.to_dict <mechsyn.kinematics.report.SimulationReport.to_dict>`,
    the :class:`~mechsyn.kinematics.simulation.Motion`'s dict with its derived quantities,
    exactly what ``mechsyn simulate --json`` prints for the same inputs and points.
    ``rates=False`` leaves out the velocities, accelerations and what is made of them (a
    smaller answer for the drag loop).

    Examples
    --------
    >>> from mechsyn.io import load_mechanism, mechanism_to_dict
    >>> d = simulate(mechanism_to_dict(load_mechanism(example_path("fourbar"))), 36)
    >>> d["input"]["joint"], len(d["assembled"]), sorted(d["points"])
    ('A', 36, ['A', 'B', 'C', 'D', 'M'])
    """
    return _simulated(build(data), steps, span, rates)


def _simulated(mech, steps: int, span: float | None, rates: bool) -> dict[str, Any]:
    from mechsyn.kinematics.report import simulation_report

    drive, values = _sweep(mech, steps, span)
    return simulation_report(mech, {drive.id: values}, points=_reported(mech), rates=rates).to_dict()


def _reported(mech) -> list[str]:
    """The points the studio reports: every joint, then the named points."""
    return [j.id for j in mech.joints if j.id not in mech.points] + list(mech.points)


#: Templates of the mechanisms parsed from the studio's requests, by the request's
#: structure (:func:`mechsyn.synthesis.templates.structure_key`): a drag sends the same
#: structure with other numbers, filled into the parsed mechanism without parsing again.
_PARSED: "OrderedDict[str, Any]" = OrderedDict()
_QUICK_LOCK = threading.Lock()


def quick_simulate(data: Any, steps: int = 180, span: float | None = None,
                   rates: bool = True) -> dict[str, Any] | None:
    """:func:`simulate` of a mechanism of drivers and dyads, fast enough to run in the
    server's own process (a drag's repaint); None where a worker process must run it
    (any input error, so that it is reported as by :func:`simulate`; a mechanism that
    needs the Newton continuation, a cam, a gear or a belt; more than
    :data:`QUICK_JOINTS` joints; a topology whose numbers the reader changes, e.g. units).

    A request whose structure was parsed before is not parsed again: its numbers are put
    into the parsed mechanism (:class:`mechsyn.synthesis.templates.DictTemplate`, with the
    reader's geometry checks) and the simulation reuses the plan compiled for the topology.
    The answer is :func:`simulate`'s.

    Examples
    --------
    >>> from mechsyn.io import load_mechanism, mechanism_to_dict
    >>> d = mechanism_to_dict(load_mechanism("examples/textbook/fourbar.yaml"))
    >>> quick_simulate(d, 36) == simulate(d, 36)
    True
    """
    from mechsyn.synthesis.templates import structure_key

    if not isinstance(data, dict) or not isinstance(data.get("joints"), list) or len(data["joints"]) > QUICK_JOINTS:
        return None
    key = structure_key(data)
    if key is None:
        return None
    with _QUICK_LOCK:  # one at a time: the plan caches and their shared programs are not for threads
        return _quick(data, steps, span, rates, key)


def _quick(data: dict, steps: int, span: float | None, rates: bool, key: str) -> dict[str, Any] | None:
    """:func:`quick_simulate`'s body (under its lock)."""
    from mechsyn.kinematics.analysis import cached_plan
    from mechsyn.synthesis.templates import DictTemplate

    try:
        template = _PARSED.get(key)
        if template is None:
            template = DictTemplate(data, "mechanism")
            _PARSED[key] = template
            while len(_PARSED) > 16:
                _PARSED.popitem(last=False)
        mech = template.mechanism(data, key)
        if mech is None:
            return None  # the reader changes or refuses a number: a worker parses it
        drives = [j for j in mech.joints if j.actuated]
        kp = cached_plan(mech, inputs=(drives[0].id,)) if drives and mech.kind == "planar" else None
        if kp is None or kp.groups is None:
            return None
        return _simulated(mech, steps, span, rates)
    except (MechsynInputError, TypeError, ValueError, KeyError):
        return None  # reported by the worker's simulate, as without this path


def _scale(mech) -> float:
    pts = np.array([j.point[:2] for j in mech.joints if j.point is not None], float)
    return float(np.ptp(pts, axis=0).max()) if len(pts) > 1 else 1.0


def simulation_csv(data: Any, steps: int = 180) -> str:
    """The simulation as CSV (``mechsyn simulate --csv``:
    :meth:`mechsyn.kinematics.simulation.Motion.csv`) over the studio's sweep."""
    from mechsyn.kinematics.analysis import simulate as _simulate

    mech = build(data)
    drive, values = _sweep(mech, steps, None)
    return _simulate(mech, {drive.id: values}, points=_reported(mech)).csv()


def animation_gif(data: Any, frames: int = 72) -> bytes:
    """The mechanism moving over its sweep as a GIF (``mechsyn.plot.animate_simulation``,
    drawn by :mod:`mechsyn.plot` and written by :mod:`mechsyn.export.movie`)."""
    import tempfile

    from mechsyn.export.movie import write_gif
    from mechsyn.kinematics.analysis import simulate as _simulate
    from mechsyn.plot.frames import figure_frames
    from mechsyn.plot.kinematics import animate_simulation

    mech = build(data)
    drive, values = _sweep(mech, 180, None)
    sim = _simulate(mech, {drive.id: values})
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "animation.gif"
        write_gif(figure_frames(animate_simulation, sim, dpi=80, max_frames=frames), path, fps=15)
        return path.read_bytes()


# --------------------------------------------------------------------------- structure
def analyze(data: Any) -> dict[str, Any]:
    """The structure report (``mechsyn analyze --json``: formulas with their numbers, the rank
    result), its rank summary lines, the Assur groups and, for a four-bar, Grashof."""
    from mechsyn.kinematics import derived
    from mechsyn.structure.assur import assur_decomposition
    from mechsyn.structure.rank import rank_summary_lines
    from mechsyn.structure.report import analyze as structure_report

    mech = build(data)
    report = structure_report(mech)
    out: dict[str, Any] = {"structure": report.to_dict()}
    out["rank"] = out["structure"]["rank"]
    if report.rank is not None:
        out["rank_summary"] = rank_summary_lines(report.rank)
    else:
        out["rank_unavailable"] = out["structure"].get("rank_unavailable", "the joints' geometry is incomplete")
    try:
        out["assur"] = to_jsonable(assur_decomposition(mech))
    except MechsynInputError as err:
        out["assur"], out["assur_unavailable"] = None, err.message
    out["grashof"] = to_jsonable(derived.grashof(mech)) if derived.is_fourbar(mech) else None
    return out


# --------------------------------------------------------------------------- atlas
def atlas(n_links: int, mobility: int) -> list[dict[str, Any]]:
    """The non-isomorphic chains with ``n_links`` links and ``mobility``, with a drawing layout."""
    from mechsyn.synthesis.chains import synthesize_chains
    from mechsyn.synthesis.curves.topologies import chain_name, six_bar_name
    from mechsyn.synthesis.mechanisms import chain_layout, distinct_mechanisms

    if not (4 <= n_links <= 10):
        raise MechsynInputError("the atlas browser lists 4 to 10 links", field="links")
    out = []
    for k, chain in enumerate(synthesize_chains(n_links, mobility)):
        link_xy, joint_xy = chain_layout(chain)
        name = chain_name(chain)  # Watt, Stephenson (issue 40)
        out.append({"index": k, "label": chain.assortment_label() + (f", {name}" if name else ""), "name": name,
                    "chain": chain.to_dict(), "link_xy": link_xy.tolist(), "joint_xy": joint_xy.tolist(),
                    "mechanisms": [{"frame": c.frame, "input": c.input, "name": six_bar_name(chain, c.frame)}
                                   for c in distinct_mechanisms(chain)]})
    return out


def atlas_mechanism(chain: dict[str, Any], frame: int | None = None, input_link: int | None = None) -> dict:
    """A chain of the atlas as a mechanism file dict (frame and input chosen).

    The chain is checked before any work (:func:`mechsyn.synthesis.chains.check_chain_dict`),
    the frame must be one of its links and the input a link jointed to the frame.
    """
    from mechsyn.synthesis.chains import KinematicChain
    from mechsyn.synthesis.mechanisms import mechanism_dict

    kc = KinematicChain.from_dict(chain, field="chain")
    if frame is not None and not 0 <= frame < kc.n_links:
        raise MechsynInputError(f"link {frame} is not one of the chain's links 0..{kc.n_links - 1}", field="frame")
    if input_link is not None:
        beside = sorted({b if a == frame else a for a, b in kc.edges if frame in (a, b)}) if frame is not None else None
        if not 0 <= input_link < kc.n_links or (beside is not None and input_link not in beside):
            raise MechsynInputError(f"link {input_link} is not jointed to the frame", field="input",
                                    hint=f"one of {beside}" if beside else None)
    return mechanism_dict(kc, frame=frame, input_link=input_link)


# --------------------------------------------------------------------------- synthesis
#: The studio's size bound of a four-bar path run [target diagonals] (the library's default;
#: a run's ``max_size`` replaces it, 0: none).
PATH_MAX_SIZE = 1.5


class Cancelled(Exception):
    """Raised inside a progress callback to stop a synthesis run."""


def fourbar_path_case(targets: list, time_limit: float, max_size: float = PATH_MAX_SIZE) -> Any:
    """A four-bar path case through clicked ``targets`` (free timing, bounds from their extent),
    its size bound ``options.max_size`` ``max_size`` target diagonals (0: none; as ``synth path --max-size``)."""
    from mechsyn.synthesis.path import PathCase

    T = np.asarray(targets, float)
    if T.ndim != 2 or T.shape[1] != 2 or not 3 <= len(T) <= 12 or not np.isfinite(T).all():
        raise MechsynInputError("give 3 to 12 target points [x, y]", field="targets")
    c = T.mean(axis=0)
    size = float(max(np.ptp(T, axis=0).max(), 1e-6))
    L = 3.0 * size
    var = [{"name": "x0", "lower": c[0] - L, "upper": c[0] + L}, {"name": "y0", "lower": c[1] - L, "upper": c[1] + L},
           {"name": "theta0", "lower": -math.pi, "upper": math.pi}]
    var += [{"name": r, "lower": 0.05 * size, "upper": L} for r in ("r1", "r2", "r3", "r4")]
    var += [{"name": r, "lower": -L, "upper": L} for r in ("rcx", "rcy")]
    var += [{"name": f"theta2_{i + 1}", "lower": 0.0, "upper": 2 * math.pi} for i in range(len(T))]
    return PathCase.from_dict({"id": "studio", "targets": T.tolist(), "timing": {"type": "free"},
                               # the bounds above are the studio's, not the user's: the size bound applies
                               "variables": var, "options": {"grashof": "crank-rocker", "max_size": max_size}},
                              source="targets")


def synthesize_fourbar_path(params: dict[str, Any], progress: ProgressCallback) -> dict[str, Any]:
    """Four-bar path synthesis through ``params["targets"]``: ranked results (both branches),
    each with its report's ``reason`` (:class:`~mechsyn.synthesis.optimize.PathSynthesisResult`).

    ``progress`` receives a :class:`mechsyn.progress.Progress` (restarts of both branches)
    and may raise :class:`Cancelled`.
    """
    from mechsyn.synthesis.export import fourbar_mechanism_dict
    from mechsyn.synthesis.optimize import synthesize_path

    time_limit = float(params.get("time_limit", 10.0))
    if not 0.5 <= time_limit <= 600:
        raise MechsynInputError("time limit must be within 0.5..600 s", field="time_limit")
    restarts = int(params.get("restarts", 4))
    if not 1 <= restarts <= 50:
        raise MechsynInputError("restarts must be within 1..50", field="restarts")
    case = fourbar_path_case(params.get("targets"), time_limit, float(params.get("max_size", PATH_MAX_SIZE)))
    results = []
    branches = (-1, 1)
    for b, branch in enumerate(branches):
        bcase = _with_branch(case, branch)

        def report(state: Progress, b=b) -> None:  # the restarts of both branches, one after the other
            best = min((e for e in (state.best, *(r["error"] for r in results if r["feasible"])) if e is not None),
                       default=None)
            progress(replace(state, done=b * state.total + state.done, total=len(branches) * state.total,
                             stage=f"{state.stage}, branch {branches[b]:+d}", best=best))

        res = synthesize_path(bcase, seed=b, time_limit=time_limit / len(branches), restarts=restarts,
                              progress=report)
        d = {**bcase.fixed, **res.design}
        # reason: the report's own (as `synth path` shows it): why it is infeasible, or the
        # bound the design sits on that decides it and how to lift it ("" when none)
        item = {"error": float(res.error), "feasible": bool(res.feasible), "branch": branch,
                "reason": res.to_dict()["reason"],
                "label": f"error {res.error:.4g} (sum of squared distances), branch {branch:+d}, "
                         f"{'feasible' if res.feasible else 'infeasible'}",
                "design": {k: float(v) for k, v in d.items() if not k.startswith("theta2")},
                "path": _xy(res.path), "curve": _fourbar_curve(d, branch), "seconds": float(res.seconds),
                "quality": _fourbar_quality(d, res)}
        if res.feasible:
            item["mechanism"] = fourbar_mechanism_dict(
                d["r1"], d["r2"], d["r3"], d["r4"], float(res.theta2[0]), branch=branch, rcx=d["rcx"],
                rcy=d["rcy"], x0=d["x0"], y0=d["y0"], theta0=d["theta0"], name="Four-bar through clicked points")
        results.append(item)
    results.sort(key=lambda r: (not r["feasible"], r["error"]))
    return {"kind": "fourbar_path", "targets": case.targets.tolist(), "results": results}


def _fourbar_curve(d: dict[str, float], branch: int) -> list:
    """The coupler point's whole curve over a crank turn (360 positions, None where the
    four-bar does not assemble): the candidate previewed on hover."""
    from mechsyn.synthesis.fourbar import fourbar_position

    th = np.linspace(0.0, 2 * np.pi, 361)
    pose = fourbar_position(d["r1"], d["r2"], d["r3"], d["r4"], th, branch=branch, rcx=d["rcx"], rcy=d["rcy"],
                            x0=d["x0"], y0=d["y0"], theta0=d["theta0"])
    return _xy(np.where(np.asarray(pose.assembled)[:, None], np.asarray(pose.C).reshape(-1, 2), np.nan))


def _fourbar_quality(d: dict[str, float], res: Any) -> dict[str, Any]:
    """Size, link ratio and worst transmission angle of a path-synthesis four-bar (frame
    r1, crank r2, coupler r3, rocker r4): the crank-rocker's transmission angle is extreme
    where the crank lies along the frame, cos μ = (r3² + r4² - (r2 ∓ r1)²) / (2 r3 r4)."""
    r1, r2, r3, r4 = (abs(float(d[k])) for k in ("r1", "r2", "r3", "r4"))
    worst = 90.0
    for s in (r2 - r1, r2 + r1):
        c = (r3 * r3 + r4 * r4 - s * s) / (2 * r3 * r4) if r3 * r4 > 0 else 1.0
        mu = math.degrees(math.acos(min(1.0, max(-1.0, c))))
        worst = min(worst, mu, 180.0 - mu)
    lengths = (r1, r2, r3, r4)
    grashof = min(lengths) + max(lengths) <= sum(lengths) - min(lengths) - max(lengths)
    return {"size": res.size, "size_ratio": res.size_ratio,
            "link_ratio": max(lengths) / min(lengths) if min(lengths) > 0 else None,
            "min_transmission_angle": worst, "full_turn": bool(grashof and min(lengths) in (r1, r2))}


def _with_branch(case, branch: int):
    return replace(case, branch=branch)


def synthesize_curve_points(params: dict[str, Any], progress: ProgressCallback) -> dict[str, Any]:
    """Curve to mechanism (:mod:`mechsyn.synthesis.curves`): ranked 4- to ``max_links``-bar
    linkages whose tracing point follows the clicked or drawn curve ``params["targets"]``.

    The local curve database is built on first use (a few minutes; its progress is reported).
    """
    from mechsyn.synthesis.curves.synthesis import synthesize_curve
    from mechsyn.synthesis.curves.target import target_from_points

    T = np.asarray(params.get("targets"), float)
    if T.ndim != 2 or T.shape[1:] != (2,) or len(T) < 6 or not np.isfinite(T).all():
        raise MechsynInputError("give at least 6 points [x, y] along the curve", field="targets",
                                hint="click more points, or draw the curve")
    time_limit = float(params.get("time_limit", 20.0))
    if not 1 <= time_limit <= 600:
        raise MechsynInputError("time limit must be within 1..600 s", field="time_limit")
    max_links = int(params.get("max_links", 8))   # the CLI's default: the same target and limit, the same answer
    if max_links not in (4, 6, 8):
        raise MechsynInputError("max_links must be 4, 6 or 8", field="max_links")
    closed = params.get("closed")
    target = target_from_points(T, closed=None if closed is None else bool(closed), source="clicked curve")

    res = synthesize_curve(target, max_links=max_links, time_limit=time_limit, top=5, progress=progress)
    results = []
    for c in res.candidates:
        d = c.to_dict()
        results.append({"error": float(c.chamfer), "feasible": bool(c.verified), "mechanism": d["mechanism"],
                        "path": _xy(c.path),
                        "label": f"{d['topology'] or d['topology_key']} ({d['links']} links): error "
                                 f"{100 * c.chamfer:.2f} % of the diagonal, min μ {c.min_transmission_angle:.0f}°"
                                 + (f" [{c.role}]" if c.role else "") + ("" if c.refined else " (not refined)")
                                 + ("" if c.verified else f", not verified: {c.verification}"),
                        "quality": d.get("quality")})
    notes = list(res.notes)
    if not results and res.reason:  # nothing inside the bounds: say why, with the nearest miss
        notes.insert(0, str(res.reason))
    return {"kind": "curve", "targets": T.tolist(), "results": results, "notes": notes}


# Synthesis kinds the studio offers: name -> (title, function(params, progress) -> result dict).
# Each result dict: {"kind", "targets", "results": [{"label", "error", "feasible", "mechanism", "path"}]};
# a result may carry its report's "reason" and the dict "notes" (shown as text under it).
SYNTHESIS_KINDS: dict[str, tuple[str, Callable[[dict, ProgressCallback], dict]]] = {
    "fourbar_path": ("Four-bar path through the clicked points", synthesize_fourbar_path),
    "curve": ("Curve to mechanism over the atlas (4- to 8-bars)", synthesize_curve_points),
}
