"""The synthesis workflows of the command line as library calls: a path-generation case
with its margins and stopping error, Burmester motion generation ranked and counted,
mechanism files for the designs found.

``mechsyn synth path|motion --json`` prints the ``to_dict()`` of what these return.

References
----------
F. Freudenstein, "Approximate synthesis of four-bar linkages", *Trans. ASME* 77 (1955)
853-861; R. L. Norton, *Design of Machinery*, 5th ed., McGraw-Hill, 2012, ch. 5
(Burmester theory); J. M. McCarthy, G. S. Soh, *Geometric Design of Linkages*, 2nd ed.,
Springer, 2011, ch. 4-5.
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Sequence, TypeVar

import numpy as np

from mechsyn._result import Result
from mechsyn.errors import MechsynInputError
from mechsyn.progress import ProgressCallback
from mechsyn.structure.analysis import analyze_structure
from mechsyn.synthesis.curves.database import build_database, load_database
from mechsyn.synthesis.exact import motion_synthesis, to_jsonable_motion
from mechsyn.synthesis.export import fourbar_mechanism_dict
from mechsyn.synthesis.finger.groups import group_table
from mechsyn.synthesis.general import synthesize_mechanism
from mechsyn.synthesis.optimize import default_target_error, synthesize_path

__all__ = ["select_case", "path_synthesis", "mechanism_synthesis", "path_mechanism_dict", "MotionReport", "motion_report",
           "motion_mechanism_dict", "finger_groups", "curve_candidate_files", "CurveDatabaseReport", "curve_database"]

C = TypeVar("C")


def select_case(cases: Sequence[C], case_id: str | None, source: str | None = None) -> C:
    """The case ``case_id`` of ``cases`` (the only one when ``case_id`` is None); ``source``
    names the file in the message.

    Examples
    --------
    >>> from types import SimpleNamespace as Case
    >>> select_case([Case(id="a"), Case(id="b")], "b").id
    'b'
    >>> select_case([Case(id="a"), Case(id="b")], None, "cases.json")
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: case_id: cases.json holds 2 cases (fix: choose one: a | b)
    """
    ids = [c.id for c in cases]  # type: ignore[attr-defined]
    if case_id is None:
        if len(cases) == 1:
            return cases[0]
        raise MechsynInputError(f"{source or 'the file'} holds {len(cases)} cases", field="case_id",
                                hint="choose one: " + " | ".join(ids))
    if case_id not in ids:
        raise MechsynInputError(f"no case {case_id!r}", field="case_id", hint="one of " + ", ".join(ids))
    return cases[ids.index(case_id)]


def _with_margins(case: Any, min_transmission: float | None, fold_margin: float | None) -> Any:
    for value, name in ((min_transmission, "min_transmission"), (fold_margin, "fold_margin")):
        if value is not None and not 0.0 <= value < 90.0:
            raise MechsynInputError("must be an angle in degrees in [0, 90)", field=name)
    if min_transmission is not None:
        case = replace(case, transmission_angle_min_deg=min_transmission)
    if fold_margin is not None:
        case = replace(case, fold_margin_deg=fold_margin)
    return case


def path_synthesis(case: Any, *, seed: int = 0, time_limit: float = 60.0, restarts: int = 10,
                   workers: int = 1, scheduler: Any = None, optimizer: str = "de",
                   target_error: float | None = None, min_transmission: float | None = None,
                   fold_margin: float | None = None, progress: ProgressCallback | None = None,
                   max_size: float | None = None, **search: Any) -> Any:
    """Path generation of ``case`` with the designer's margins (see
    :func:`mechsyn.synthesis.optimize.synthesize_path`).

    Parameters
    ----------
    case : PathCase
    seed, time_limit, restarts, workers, scheduler, optimizer, progress
        As for :func:`~mechsyn.synthesis.optimize.synthesize_path`.
    target_error : float, optional
        Stop once a design reaches this error; None: the case's best known error + 1 %
        (:func:`~mechsyn.synthesis.optimize.default_target_error`); 0: use the whole budget.
    min_transmission, fold_margin : float, optional
        Smallest transmission angle over the motion and the least distance from folding
        flat [deg], replacing the case's.
    max_size : float, optional
        Size bound in target diagonals replacing the case's (default: the case's, else
        1.5 except for literature cases; 0 lifts it): frame pivots and the crank and
        rocker pins' circles within this many diagonals of the targets' bounding-box
        centre (:func:`~mechsyn.synthesis.optimize.with_size_bound`).
    **search
        Passed on (``checkpoint=``, ``resume=``).

    Returns
    -------
    PathSynthesisResult

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.path import load_cases
    >>> from mechsyn.synthesis.reports import path_synthesis, select_case
    >>> case = select_case(load_cases(ms.examples.path("path_cases_public")), "P2_kk5_timing")
    >>> res = path_synthesis(case, time_limit=20, restarts=1, min_transmission=10.0)
    >>> res.feasible, res.transmission_angle_min_deg
    (True, 10.0)
    """
    _check_budget(time_limit, restarts)
    if target_error is not None and not target_error >= 0:
        raise MechsynInputError("must be >= 0 (0: use the whole budget)", field="target_error")
    case = _with_margins(case, min_transmission, fold_margin)
    stop_at = default_target_error(case) if target_error is None else (target_error or None)
    return synthesize_path(case, seed=seed, time_limit=time_limit, restarts=restarts, workers=workers,
                           optimizer=optimizer, progress=progress, scheduler=scheduler, target_error=stop_at,
                           max_size=max_size, **search)


def _check_budget(time_limit: float, restarts: int) -> None:
    if not time_limit > 0:
        raise MechsynInputError("must be positive", field="time_limit")
    if restarts < 1:
        raise MechsynInputError("must be at least 1", field="restarts")


def mechanism_synthesis(case: Any, *, seed: int = 0, time_limit: float = 30.0, restarts: int = 3,
                        optimizer: str = "de", workers: int = 1, scheduler: Any = None,
                        progress: ProgressCallback | None = None, **search: Any) -> Any:
    """Synthesis of any planar mechanism file (see
    :func:`mechsyn.synthesis.general.synthesize_mechanism`), its budget checked first.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.general import load_mechanism_case
    >>> from mechsyn.synthesis.reports import mechanism_synthesis
    >>> mechanism_synthesis(load_mechanism_case(ms.examples.path("slider_crank_path_case")), time_limit=0)
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: time_limit: must be positive
    """
    _check_budget(time_limit, restarts)
    return synthesize_mechanism(case, seed=seed, time_limit=time_limit, restarts=restarts, optimizer=optimizer,
                                progress=progress, workers=workers, scheduler=scheduler, **search)


def _fourbar_dict(design: dict[str, float], theta2: float, branch: int, name: str) -> dict[str, Any]:
    d = design
    return fourbar_mechanism_dict(d["r1"], d["r2"], d["r3"], d["r4"], theta2, branch=branch, rcx=d["rcx"],
                                  rcy=d["rcy"], x0=d["x0"], y0=d["y0"], theta0=d["theta0"], name=name)


def path_mechanism_dict(case: Any, res: Any) -> tuple[dict[str, Any], str]:
    """The four-bar found for path ``case`` as a mechanism-file dict (joints at target 1)
    and the comment header saying how it was found.

    Raises :class:`~mechsyn.errors.MechsynInputError` when no feasible design was found.
    """
    if not res.feasible:
        raise MechsynInputError("no feasible design found; nothing written",
                                hint="raise --time-limit or --restarts, or widen the bounds")
    mech = _fourbar_dict({**case.fixed, **res.design}, float(res.theta2[0]), case.branch,
                         f"Four-bar for path case {case.id}")
    header = (("INTERRUPTED (Ctrl-C): the best design found before the interrupt\n" if res.interrupted else "")
              + f"mechsyn synth path {case.id}: error {res.error:.6g} (sum of squared distances), seed {res.seed}\n"
              f"joint points at target 1 (crank angle {np.degrees(res.theta2[0]):.4f} deg), branch {case.branch}")
    return mech, header


@dataclass(repr=False)
class MotionReport(Result):
    """Burmester motion generation: the ``top`` best linkages of ``count`` found,
    ``verified_count`` of which simulation confirms (see
    :func:`mechsyn.synthesis.exact.motion_synthesis`)."""

    poses: np.ndarray = field(metadata={"json": False})
    all_solutions: list[Any] = field(metadata={"json": False})
    top: int = 5

    @property
    def count(self) -> int:
        return len(self.all_solutions)

    @property
    def verified_count(self) -> int:
        return sum(s.ok for s in self.all_solutions)

    @property
    def solutions(self) -> list[Any]:
        """The ``top`` best solutions."""
        return self.all_solutions[: self.top]

    def to_dict(self) -> dict[str, Any]:
        return {"solutions": [to_jsonable_motion(s) for s in self.solutions], "count": self.count,
                "verified_count": self.verified_count}

    def plot(self, ax: Any = None) -> Any:
        """Centre-point curve and solutions (see :func:`mechsyn.plot.synthesis.plot_motion_synthesis`)."""
        from mechsyn.plot.synthesis import plot_motion_synthesis

        return plot_motion_synthesis(self.poses, self.all_solutions, ax=ax)


def motion_report(poses: np.ndarray, *, circle_points: np.ndarray | None = None,
                  center_points: np.ndarray | None = None, top: int = 5) -> MotionReport:
    """Four-bars guiding a body through 3, 4 or 5 ``poses`` (rows x, y, angle in radians),
    ranked, each verified by simulation.

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.synthesis.reports import motion_report
    >>> poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, np.radians(20)], [2.0, 0.7, np.radians(45)]])
    >>> r = motion_report(poses, top=2)
    >>> r.count, r.verified_count, r.to_dict()["count"]
    (1, 1, 1)
    """
    poses = np.asarray(poses, float)
    if (circle_points is not None or center_points is not None) and len(poses) != 3:
        raise MechsynInputError("circle/centre points are chosen only for 3 poses", field="circle_points")
    sols = motion_synthesis(poses, circle_points=circle_points, center_points=center_points)
    if not sols:
        raise MechsynInputError("no linkage found for these poses", field="poses")
    return MotionReport(poses, sols, top)


def motion_mechanism_dict(report: MotionReport) -> tuple[dict[str, Any], str]:
    """The best linkage of ``report`` as a mechanism-file dict (joints at pose 1) and its header."""
    best = report.all_solutions[0]
    return (_fourbar_dict(best.design(), float(best.theta2[0]), best.branch, "Four-bar motion generator (Burmester)"),
            "coupler point P = origin of the guided body's frame; joints at pose 1")


def curve_candidate_files(res: Any) -> list[tuple[str, dict[str, Any], str]]:
    """``(file name, mechanism dict, header)`` for each candidate of a curve synthesis."""
    out = []
    for i, c in enumerate(res.candidates, 1):
        d = c.to_dict()
        out.append((f"candidate_{i}.yaml", d["mechanism"], (
            f"mechsyn synth curve: candidate {i}, {d['topology'] or c.topology.key}, tracer T"
            + (f" ({c.role})" if c.role else "") + ("" if c.refined else " (retrieved, not refined)") + "\n"
            f"input {d['input']['joint']} from {d['input']['start']:.3f} to {d['input']['stop']:.3f} deg; "
            f"error {100 * c.chamfer:.3f} % of the target's diagonal (symmetric chamfer)")))
    return out


@dataclass(repr=False)
class CurveDatabaseReport(Result):
    """What a curve database holds: its directory, topologies, curves (closed curves and
    open arcs) and size on disk."""

    database: str
    topologies: int
    curves: int
    closed: int
    open: int
    bytes: int


def curve_database(directory: Any = None, *, max_links: int = 8, per_topology: int = 3000, seed: int = 0,
                   scheduler: Any = None, progress: ProgressCallback | None = None) -> CurveDatabaseReport:
    """Build or extend the curve database of :func:`mechsyn.synthesis.curves.synthesis.synthesize_curve`
    (see :func:`mechsyn.synthesis.curves.database.build_database`) and say what it holds.

    Examples
    --------
    >>> import tempfile
    >>> from mechsyn.synthesis.reports import curve_database
    >>> r = curve_database(tempfile.mkdtemp(), max_links=4, per_topology=20)
    >>> r.topologies, r.curves, r.closed + r.open
    (1, 20, 20)
    """
    from pathlib import Path

    if max_links not in (4, 6, 8):
        raise MechsynInputError(f"{max_links} links: choose 4, 6 or 8", field="max_links")
    if per_topology < 1:
        raise MechsynInputError("must be at least 1", field="per_topology")
    path = build_database(directory, max_links=max_links, per_topology=per_topology, seed=seed,
                          progress=progress, scheduler=scheduler)
    db = load_database(path, max_links=max_links, build_if_missing=False)
    return CurveDatabaseReport(str(path), len(db.topologies), len(db), int(db.closed.sum()),
                               int((~db.closed).sum()), sum(f.stat().st_size for f in Path(path).glob("*.npz")))


def finger_groups(actuators: int = 1, max_links: int = 5, *, base_mobility: int | None = None,
                  base: Any = None) -> Any:
    """Paper 000's table of groups to attach to a finger whose base has mobility
    ``base_mobility`` (or that of the planar mechanism ``base``, by Chebyshev's formula) to
    make it fully actuated by ``actuators`` drives (see :func:`mechsyn.synthesis.finger.groups.group_table`).

    Examples
    --------
    >>> from mechsyn.synthesis.reports import finger_groups
    >>> [(r.n_f, r.P_f, r.m_f) for r in finger_groups(1, 3, base_mobility=2).rows]
    [(1, 2, 2), (3, 5, 3)]
    >>> finger_groups(2, base_mobility=2)
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: base_mobility: W0 = 2 is not larger than the 2 drive(s): the finger is already fully actuated, nothing to attach
    """

    if (base_mobility is None) == (base is None):
        raise MechsynInputError("give exactly one of base_mobility and base", field="base_mobility",
                                hint="e.g. base_mobility = 2")
    w0 = base_mobility
    if base is not None:
        if base.kind != "planar":
            raise MechsynInputError("paper 000's count is for planar fingers", field="base")
        w0 = int(analyze_structure(base).formulas["chebyshev"].value)
    if w0 <= actuators:
        raise MechsynInputError(f"W0 = {w0} is not larger than the {actuators} drive(s): the finger is "
                                "already fully actuated, nothing to attach", field="base_mobility")
    return group_table(w0, actuators, max_links)
