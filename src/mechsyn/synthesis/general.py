"""Dimensional synthesis of any planar mechanism file (path and motion generation).

The design is the file's drawn (assembled) configuration; the user picks which of its
coordinates move (:class:`DesignVariable`): a joint point's x or y, a named point's x or
y, or a variable-length link's (VLL's) length. Moving a joint point changes the lengths of
the links it joins (the drawing stays an assembled configuration, since a joint point is
shared by its two links).

Objective, evaluated by the kinematics engine (:mod:`mechsyn.kinematics`):

* path generation: ``f = sum_i |P(u_i) - Pd_i|^2`` (sum of squared distances of the
  named point ``P`` at the input values ``u_i`` to the targets ``Pd_i``);
* motion generation: ``f = sum_i |O(u_i) - Od_i|^2 + (w (phi(u_i) - phid_i))^2`` with
  ``O`` the link's reference point (its first joint, file order, or ``point:``), ``phi``
  the absolute angle of the link's reference line (as ``mechsyn simulate`` reports it),
  the angle difference wrapped to (-pi, pi], and ``w`` = ``angle_weight`` (length per
  radian; default 1).

Constraints that hold (feasibility first, never a real-part trick): the mechanism
assembles at every point of a dense input sweep (steps of at most ``step_deg``) from the
drawn input value through every target input in order, so it moves continuously on the
branch of the drawn assembly between consecutive targets; the closed-form dyads keep the
assembly mode (sign) of the starting design's drawing; free timing keeps the input angles
monotonic in the order given; variable bounds. An infeasible design scores
``U + violation`` (``violation >= 1``), where ``U`` caps the score of every feasible
design, so it is never rewarded.

Evaluation: mechanisms that decompose into a driver and Assur dyads (RRR, RRP, RPR, ...)
use the engine's vectorised closed form (:func:`mechsyn.kinematics.dyads.solve_positions`)
for the whole sweep at once; others the engine's Newton continuation
(:func:`mechsyn.kinematics.solve.sweep`). Optimiser: :mod:`mechsyn.synthesis.optimize`
(its pluggable ``OPTIMIZERS``, reproducible restart seeds and least-squares ``polish``).

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from collections import OrderedDict
from dataclasses import dataclass, field, fields, replace
from typing import Any

import numpy as np

from mechsyn.checkpoint import open_search_checkpoint
from mechsyn.errors import MechsynInputError
from mechsyn.interrupt import BestSoFar
from mechsyn.io import mechanism_from_dict
from mechsyn.io.checks import check_geometry
from mechsyn.kinematics import dyads
from mechsyn.kinematics.analysis import KinematicPlan, compile_plan, resolve_points
from mechsyn.kinematics.solve import sweep
from mechsyn.kinematics.system import build_system
from mechsyn.model.mechanism import Mechanism
from mechsyn.parallel import run_tasks
from mechsyn.synthesis.cases import DesignVariable, MechanismCase, mechanism_case_from_dict, load_mechanism_case
from mechsyn.synthesis.designs import (MechanismEvaluation, apply_mechanism_design, design_numbers, infeasibility,
                                      start_vector)
from mechsyn.synthesis.finger.vll import locked_model, vll_ends
from mechsyn.synthesis.general_batch import batch_evaluator
from mechsyn.synthesis.optimize import OPTIMIZERS, check_optimizer, polish, restart_seeds
from mechsyn.synthesis.problem import Progress, ProgressCallback, SeedLike, SynthesisResult, resolve_seed

__all__ = ["DesignVariable", "MechanismCase", "MechanismEvaluation", "MechanismProblem",
           "MechanismSynthesisResult", "load_mechanism_case", "mechanism_case_from_dict", "apply_mechanism_design",
           "evaluate_mechanism_design",
           "synthesize_mechanism", "start_vector", "reference_branch"]


def _sweep_grid(u0_deg: float, values: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Dense input grid from the drawn value ``u0_deg`` (shifted by whole turns to the one
    nearest ``values[0]``) through every value in order, each segment evenly divided in
    steps of at most ``step`` (as :func:`numpy.linspace`); returns (grid, target indices)."""
    u0 = u0_deg + 360.0 * np.round((values[0] - u0_deg) / 360.0)
    a = np.concatenate([[u0], values[:-1]])
    b = np.asarray(values, float)
    m = np.maximum(1, np.ceil(np.abs(b - a) / step).astype(int))
    idx = np.cumsum(m)
    seg = np.repeat(np.arange(len(m)), m)
    k = np.arange(1, idx[-1] + 1) - (idx - m)[seg]  # 1..m within each segment
    grid = np.empty(idx[-1] + 1)
    grid[0] = u0
    grid[1:] = k * ((b - a) / m)[seg] + a[seg]
    grid[idx] = b  # each segment ends exactly on its value
    return grid, idx


def _build(case: MechanismCase, x: np.ndarray, fast: bool = True) -> tuple[Any, Any, Any]:
    """(mechanism, constraint system, decomposition) of design ``x``: on the case's
    template (:func:`_template`, the topology-keyed fast path) when it has one and
    ``fast``, else parsed and built from the design's dict (the general path)."""
    tpl = _template(case) if fast else None
    if tpl is not None:
        mech = tpl.mechanism(case, x)
        if mech is not None:
            kp = tpl.plan.refilled(mech)
            return mech, kp.system, kp.groups
    d = apply_mechanism_design(case, x)
    if any(j.get("vll") == "locked" for j in d["joints"]):
        d = locked_model(d, [j["id"] for j in d["joints"] if j.get("vll") == "locked"], case.source)
    mech = mechanism_from_dict(d, source=case.source)
    S = build_system(mech)
    return mech, S, dyads.decompose(S)


class _Template:
    """A case's mechanism parsed once (the file's design, locked VLLs merged) and its
    compiled plan: every design is the same topology
    (:func:`~mechsyn.kinematics.topology.topology_key`) with other numbers, so its
    mechanism is the template's with the design's joint points, P axes and named points
    (:func:`~mechsyn.synthesis.designs.design_numbers`), checked by the reader's geometry
    checks (:func:`~mechsyn.io.checks.check_geometry`), and its plan the template's
    refilled (:meth:`~mechsyn.kinematics.analysis.KinematicPlan.refilled`): no parsing,
    no pydantic, no graph work per design."""

    def __init__(self, mech: Mechanism, plan: KinematicPlan) -> None:
        self.mech = mech
        self.plan = plan
        self.index = {j.id: k for k, j in enumerate(mech.joints)}

    def mechanism(self, case: MechanismCase, x: np.ndarray) -> Mechanism | None:
        """The mechanism of design ``x``; None where a number is not finite or a direction
        is zero (the general path's reader names the field)."""
        pts, axes, named = design_numbers(case, x)
        if not all(np.isfinite(v).all() for v in (*pts.values(), *axes.values(), *named.values())):
            return None
        mech = self.mech.with_joint_points({jid: p for jid, p in pts.items() if jid in self.index})
        if axes:  # a VLL's cylinder direction (its P joint is merged away when locked)
            joints = list(mech.joints)
            for jid, u in axes.items():
                k = self.index.get(jid)
                if k is not None:
                    a = np.asarray(u, float)
                    norm = float(np.linalg.norm(a))
                    if norm < 1e-12:
                        return None
                    joints[k] = replace(joints[k], axis=a / norm)  # a unit vector, as the reader stores it
            mech = replace(mech, joints=tuple(joints))
        if named:
            mech = replace(mech, points={n: replace(q, at=np.asarray(named[n], float)) if n in named else q
                                         for n, q in mech.points.items()})
        return check_geometry(mech, case.source)


#: The template of each of the last eight cases evaluated, kept with the case object, its
#: mechanism dict and its variables (a case given a new dict or new variables gets a new
#: template; cases are not changed in place).
_TEMPLATES: "OrderedDict[int, tuple[MechanismCase, dict, list, _Template | None]]" = OrderedDict()


def _template(case: MechanismCase) -> _Template | None:
    """The case's :class:`_Template`, made on first use; None where a design cannot be a
    refill of the file's: the file does not build, the reader changes its numbers, or a
    variable moves a VLL's P joint or piston pivot (their coincidence, which the VLL
    needs, is then a property of the design, checked by the general path)."""
    entry = _TEMPLATES.get(id(case))
    if entry is not None and entry[0] is case and entry[1] is case.mech_dict and entry[2] is case.variables:
        return entry[3]
    tpl = _new_template(case)
    _TEMPLATES[id(case)] = (case, case.mech_dict, case.variables, tpl)
    while len(_TEMPLATES) > 8:
        _TEMPLATES.popitem(last=False)
    return tpl


def _new_template(case: MechanismCase) -> _Template | None:
    md = case.mech_dict
    if any(j.get("type") not in ("R", "P") for j in md["joints"]):
        return None  # cams, gears, belts: the reader derives numbers from the points
    vlls = [j["id"] for j in md["joints"] if j.get("vll") == "locked"]
    vlls += [v.target for v in case.variables if v.kind == "length"]
    moved = {v.target for v in case.variables if v.kind == "joint"}
    try:
        if any(jid in moved or vll_ends(md, jid, case.source)[1] in moved for jid in vlls):
            return None
        x0 = start_vector(case)[:case.n_design]
        mech, _S, _plan = _build(case, x0, fast=False)
        tpl = _Template(mech, compile_plan(mech))
        filled = tpl.mechanism(case, x0)
    except (MechsynInputError, ValueError, KeyError, ZeroDivisionError, np.linalg.LinAlgError):
        return None

    def same(a: Any, b: Any) -> bool:
        return (a is None and b is None) or (a is not None and b is not None and np.array_equal(a, b))

    # the fill gives the reader's numbers (no units, no transforms of the file's numbers)
    if filled is None or not all(same(j.point, f.point) and same(j.axis, f.axis)
                                 for j, f in zip(mech.joints, filled.joints)) \
            or not all(same(p.at, filled.points[n].at) for n, p in mech.points.items()):
        return None
    return tpl


def reference_branch(case: MechanismCase) -> list[float] | None:
    """Assembly modes (one sign per closed-form dyad) of the file's own drawing: the branch
    every design must keep. Found on first use and kept in ``case.reference`` (loading a
    case runs no solver); None when the mechanism does not decompose into closed-form dyads.

    Examples
    --------
    >>> import mechsyn as ms
    >>> case = load_mechanism_case(ms.examples.path("slider_crank_path_case"))
    >>> case.reference is None
    True
    >>> reference_branch(case) == case.reference, len(case.reference)  # two dyads
    (True, 2)
    """
    if case.reference is None:
        case.reference = _drawing_branch(case)
    return case.reference


def _drawing_branch(case: MechanismCase) -> list[float] | None:
    _m, S, plan = _build(case, start_vector(case), fast=False)  # once per case
    if plan is None:
        return None
    k = S.driver_index(case.input_joint)
    U = np.array([[dr.assembled for dr in S.drivers]], float)
    U[0, k] = S.drivers[k].assembled
    with np.errstate(invalid="ignore", divide="ignore"):
        _q, sig = dyads.solve_positions(S, plan, U)
    return [float(s) for s in sig]


def evaluate_mechanism_design(case: MechanismCase, x: np.ndarray, fast: bool = True) -> MechanismEvaluation:
    """Sweep design ``x`` with the engine and compute the case's objective. ``fast``: the
    design's numbers filled into the case's parsed mechanism and compiled plan (the
    topology-keyed fast path, see :func:`_template`); false: the design's dict parsed and
    its constraint system built anew (the general path). Both give the same evaluation.

    Examples
    --------
    >>> import mechsyn as ms
    >>> case = load_mechanism_case(ms.examples.path("slider_crank_path_case"))
    >>> x = start_vector(case) + 0.05
    >>> a, b = evaluate_mechanism_design(case, x), evaluate_mechanism_design(case, x, fast=False)
    >>> a.feasible, a.error == b.error, a.method
    (True, True, 'assur')
    """
    x = np.asarray(x, float)
    nd = case.n_design
    values = x[nd:] if case.free else case.values_deg
    viol_order = 0.0
    if case.free and len(values) > 1:
        dv = np.diff(values)
        sgn = 1.0 if values[-1] >= values[0] else -1.0
        viol_order = float(np.sum(np.maximum(0.0, -sgn * dv)))
    try:
        mech, S, plan = _build(case, x[:nd], fast)
    except (MechsynInputError, ValueError, KeyError, ZeroDivisionError, np.linalg.LinAlgError) as exc:
        return MechanismEvaluation(False, f"cannot build: {exc}", violation=1e3)
    k = S.driver_index(case.input_joint)
    grid, idx = _sweep_grid(float(np.degrees(S.drivers[k].assembled)), values, case.step_deg)
    U = np.tile([dr.assembled for dr in S.drivers], (len(grid), 1)).astype(float)
    U[:, k] = np.radians(grid)
    if plan is not None and case.method != "newton":
        ref = reference_branch(case)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            q, sig = dyads.solve_positions(S, plan, U)
        ok = np.all(np.isfinite(q), axis=1)
        method = "assur"
        branch_viol = 0.0 if ref is None or len(ref) != len(sig) else \
            float(sum(1 for a, b in zip(sig, ref) if np.sign(a) != np.sign(b)))
    else:
        try:
            with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
                sw = sweep(S, U, refine_limits=False)
        except (MechsynInputError, ValueError, np.linalg.LinAlgError) as exc:
            return MechanismEvaluation(False, f"cannot sweep: {exc}", violation=1e3)
        q, ok, method, sig = sw.q, sw.assembled, "newton", None
        branch_viol = float(sum(1 for e in sw.events if e.kind in ("branch point", "singular")))
    bad = infeasibility(int((~ok).sum()), len(grid), branch_viol, viol_order, method)
    if bad is not None:
        return bad
    qt = q[idx]
    if case.problem == "path":
        link, at = resolve_points(mech, [case.point])[case.point]
        s = S.to_local(link, at)
        i = S.index(link)
        P = S.point(qt, i, s)
        path = S.point(q, i, s)
        err = float(np.sum((P - case.targets) ** 2))
        return MechanismEvaluation(True, "", err, achieved=P, path=path, inputs_deg=np.asarray(values, float),
                                   method=method, sigmas=sig)
    i = S.index(case.link)
    s = S.to_local(case.link, S.origin0[i])
    P = S.point(qt, i, s)
    phi = S.link_angle(qt, case.link)
    dphi = np.angle(np.exp(1j * (phi - np.radians(case.angles_deg))))
    err = float(np.sum((P - case.targets) ** 2) + np.sum((case.angle_weight * dphi) ** 2))
    return MechanismEvaluation(True, "", err, achieved=P, achieved_angles_deg=np.degrees(phi),
                               path=S.point(q, i, s), inputs_deg=np.asarray(values, float), method=method,
                               sigmas=sig)


class MechanismProblem:
    """Feasibility-first fitness over populations, and least-squares residuals, in the
    interface :func:`mechsyn.synthesis.optimize.polish` expects."""

    def __init__(self, case: MechanismCase, batch: bool = True, fast: bool = True) -> None:
        self.case = case
        self.fast = fast  # designs evaluated on the topology-keyed fast path
        self.lower, self.upper = case.lower, case.upper
        pts = [case.targets]
        for j in case.mech_dict["joints"]:
            if j.get("point") is not None:
                pts.append(np.atleast_2d(j["point"]))
        span = np.ptp(np.vstack(pts), axis=0)
        ext = float(np.hypot(*span)) + float(np.max(np.abs(self.upper - self.lower)))
        w = case.angle_weight * 2 * np.pi if case.problem == "motion" else 0.0
        # U: feasible scores are capped at U, infeasible ones are U + violation (>= 1)
        self.penalty_base = 1e6 * case.n_targets * (max(1.0, ext) ** 2 + w ** 2)
        self.n_evaluations = 0   # designs swept
        self.batch = batch_evaluator(case) if batch else None  # whole populations at once

    def evaluate(self, Z: np.ndarray) -> list[MechanismEvaluation]:
        self.n_evaluations += len(np.atleast_2d(Z))
        if self.batch is not None:
            return _EvalList(self.batch.evaluate(Z))
        return _EvalList([evaluate_mechanism_design(self.case, z, self.fast) for z in np.atleast_2d(Z)])

    def score(self, ev: MechanismEvaluation) -> float:
        if ev.feasible and np.isfinite(ev.error):
            return min(ev.error, self.penalty_base)
        return self.penalty_base + max(1.0, ev.violation)

    def fitness(self, Z: np.ndarray) -> np.ndarray:
        return np.array([self.score(e) for e in self.evaluate(Z)])

    def residuals(self, z: np.ndarray) -> np.ndarray:
        c = self.case
        self.n_evaluations += 1
        ev = self.batch.evaluate(z)[0] if self.batch is not None else evaluate_mechanism_design(c, z, self.fast)
        n = 2 * c.n_targets + (c.n_targets if c.problem == "motion" else 0)
        if not ev.feasible:
            return np.full(n, np.sqrt(self.penalty_base / n) * (1.0 + ev.violation))
        r = [(ev.achieved - c.targets).ravel()]
        if c.problem == "motion":
            dphi = np.angle(np.exp(1j * np.radians(ev.achieved_angles_deg - c.angles_deg)))
            r.append(c.angle_weight * dphi)
        return np.concatenate(r)


class _EvalList(list):
    @property
    def feasible(self) -> np.ndarray:
        return np.array([e.feasible for e in self])


@dataclass(repr=False)
class MechanismSynthesisResult(SynthesisResult):
    """Outcome of :func:`synthesize_mechanism`; ``to_dict`` gives the CLI JSON.

    A :class:`~mechsyn.synthesis.problem.SynthesisResult`: ``design`` names the case's
    variables, ``x`` is the same vector, ``reason`` says why the best design is
    infeasible ("" when feasible), ``seed`` the integer that repeats the run.
    """

    case: str
    problem: str
    start_design: dict[str, float]
    start_error: float | None
    assembled_at_all_targets: bool
    method: str
    restarts: int
    inputs_deg: np.ndarray
    targets: np.ndarray
    achieved: np.ndarray
    achieved_angles_deg: np.ndarray | None
    target_angles_deg: np.ndarray | None
    path: np.ndarray
    mechanism: dict = field(repr=False, default_factory=dict)
    restart_errors: list[float] = field(default_factory=list)
    stopped_by_time_limit: bool = False

    def to_dict(self) -> dict[str, Any]:
        out = {k: getattr(self, k) for k in (
            "case", "problem", "error", "design", "start_design", "start_error", "feasible",
            "assembled_at_all_targets", "method", "seconds", "seed", "restarts", "nfev", "inputs_deg",
            "targets", "achieved", "restart_errors", "stopped_by_time_limit", "reason", "interrupted")}
        if self.problem == "motion":
            out["achieved_angles_deg"] = self.achieved_angles_deg
            out["target_angles_deg"] = self.target_angles_deg
        return {**out, **self.common()}


def _mechanism_restart(case: MechanismCase, r: int, seed: int, optimizer: str, opts: dict[str, Any],
                       n_polish: int, search_end: float, deadline: float, f_atol: float,
                       report: Callable[[int, float], None] | None = None, batch: bool = True,
                       tracker: BestSoFar | None = None, fast: bool = True) -> tuple[np.ndarray, float, int]:
    """One restart of :func:`synthesize_mechanism` (a task of :func:`mechsyn.parallel.run_tasks`):
    the global search until ``search_end`` (``time.time()``), then the polish of the best few
    members. Returns the best vector, its fitness and the number of evaluations. ``tracker``
    (in this process only) records the best design evaluated, for Ctrl-C."""
    prob = MechanismProblem(case, batch=batch, fast=fast)
    width = prob.upper - prob.lower

    def should_stop(f: float) -> bool:
        if report is not None:
            report(r, f)
        return time.time() >= search_end or f <= f_atol

    fitness = prob.fitness if tracker is None else tracker.wrap(prob.fitness)
    g = OPTIMIZERS[optimizer](fitness, prob.lower, prob.upper, seed=seed, should_stop=should_stop,
                              options=opts)
    cands = [np.asarray(g.x, float)]
    if g.population is not None and g.population_fun is not None:
        for i in np.argsort(g.population_fun):
            z = np.asarray(g.population[i], float)
            if len(cands) >= n_polish:
                break
            if all(np.linalg.norm((z - c) / width) > 1e-3 for c in cands):
                cands.append(z)
    best_z, best_f = cands[0], np.inf
    for c in cands:
        if time.time() < deadline:
            c = polish(prob, c)
        f = float(prob.fitness(c[None, :])[0])
        if f < best_f:
            best_z, best_f = c, f
    return best_z, best_f, prob.n_evaluations


def _mechanism_checkpoint(path, resume, case, dim, seed, restarts, optimizer, opts, f_atol, batch):
    content = {f.name: getattr(case, f.name) for f in fields(case) if f.name not in ("source", "mechanism_path")}
    return open_search_checkpoint(path, "synth mechanism", content, resume=resume, dim=dim, seed=seed, restarts=restarts,
                                  optimizer=optimizer, options=opts, f_atol=f_atol, batch=batch)


def synthesize_mechanism(case: MechanismCase, *, seed: SeedLike = 0, time_limit: float = 60.0, restarts: int = 3,
                         optimizer: str = "de", options: dict[str, Any] | None = None, n_polish: int = 3,
                         progress: ProgressCallback | None = None,
                         workers: int = 1, scheduler: Any = None,
                         batch: bool = True, checkpoint: Any = None, resume: bool = False,
                         fast: bool = True) -> MechanismSynthesisResult:
    """Optimise the case: per restart (child seeds of ``seed``, as in
    :func:`mechsyn.synthesis.optimize.restart_seeds`) the registered global optimiser on
    the feasibility-first fitness, then a least-squares polish of the best few members
    (:func:`mechsyn.synthesis.optimize.polish`); the file's own design competes too.
    ``workers`` (local processes) or ``scheduler`` (a Dask cluster) run the restarts in
    parallel (:func:`mechsyn.parallel.run_tasks`); restart ``r``'s search has the same time
    budget either way (until ``0.85 (r + 1) / restarts`` of the limit), so the result is
    the single-process one unless the time limit cuts the searches short.
    ``batch``: evaluate populations through the batch engine where the case allows
    (:mod:`mechsyn.synthesis.general_batch`); false: one engine sweep per design, on the
    case's compiled plan with the design's numbers filled in (``fast``, see
    :func:`evaluate_mechanism_design`) or parsed and built anew: the same result.

    ``seed``: an int, ``None`` or a ``numpy.random.Generator`` (the result's ``seed`` is
    the int that repeats the run). ``progress(state)`` gets a
    :class:`~mechsyn.synthesis.problem.Progress` (restarts done, the best fitness so far).
    Ctrl-C (:class:`KeyboardInterrupt`, also raised by ``progress``) ends the search and
    returns the best design evaluated so far with ``interrupted=True``. ``checkpoint``
    (a file) saves the finished restarts as the run goes; ``resume=True`` runs only the
    others (as :func:`mechsyn.synthesis.optimize.synthesize_path`).

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.general import load_mechanism_case
    >>> case = load_mechanism_case(ms.examples.path("slider_crank_path_case"))
    >>> res = ms.synthesize_mechanism(case, seed=0, time_limit=20, restarts=1)
    >>> res.feasible, res.error < res.start_error
    (True, True)
    """
    check_optimizer(optimizer)
    t0 = time.time()
    seed = resolve_seed(seed)
    deadline = t0 + time_limit
    opts = {"popsize": 8, "maxiter": 300, "stall": 60, "init_oversample": 5}
    opts.update(options or {})
    reference_branch(case)  # once here, not in every worker
    prob = MechanismProblem(case, batch=batch, fast=fast)
    x0 = np.clip(start_vector(case), prob.lower, prob.upper)
    best_z, best_f = x0, float(prob.fitness(x0[None, :])[0])
    start_f = best_f
    # a near-exact fit (f <= 1e-12 N L^2, L the case's length scale) ends the global search;
    # the least-squares polish then finishes it
    f_atol = float(opts.pop("f_atol", 1e-18 * prob.penalty_base))
    local = workers <= 1 and scheduler is None
    best = [best_f]
    ck = _mechanism_checkpoint(checkpoint, resume, case, len(prob.lower), seed, restarts, optimizer, opts, f_atol,
                               batch)
    outs: dict[int, tuple] = {} if ck is None else {i: (r["x"], r["fitness"], r["nfev"]) for i, r in ck.finished.items()}

    def report(r: int, f: float) -> None:
        if progress is not None:
            progress(Progress(done=r, total=restarts, stage="restarts", best=min(best[0], f)))

    def finished(index: int, out) -> None:
        r = tasks[index][1]
        outs[r] = out
        best[0] = min(best[0], out[1])
        if ck is not None:  # saved before the progress callback, which may raise Ctrl-C
            ck.finish(r, seed=seeds[r], x=out[0], fitness=out[1], nfev=out[2])
        if progress is not None:
            progress(Progress(done=len(outs), total=restarts, stage="restarts", best=best[0]))

    seeds = restart_seeds(seed, restarts)
    trackers = [BestSoFar() if local else None for _ in seeds]
    tasks = [(case, r, s, optimizer, opts, n_polish, t0 + time_limit * (0.85 * (r + 1) / restarts),
              deadline, f_atol, report if local else None, batch, trackers[r], fast)
             for r, s in enumerate(seeds) if r not in outs]
    interrupted = False
    try:
        run_tasks(_mechanism_restart, tasks, workers=workers, scheduler=scheduler,
                  on_result=finished, deadline=deadline - 0.1 * time_limit)
    except KeyboardInterrupt:  # Ctrl-C: keep the best design evaluated so far
        interrupted = True
        for r, t in enumerate(trackers):
            if t is not None and t.x is not None and t.f < best_f:
                best_z, best_f = t.x, t.f
            if ck is not None and t is not None and t.x is not None and r not in outs:
                ck.offer(r, seeds[r], t.x, t.f)
        if ck is not None:  # the checkpoint's partial best (this run's or an earlier one's)
            if ck.partial is not None and ck.partial["fitness"] < best_f:
                best_z, best_f = ck.partial["x"], ck.partial["fitness"]
            ck.save()
    errs, done, nfev = [], 0, prob.n_evaluations
    for r in sorted(outs):
        z, f, n = outs[r]
        errs.append(f if f < prob.penalty_base else float("inf"))
        done += 1
        nfev += n
        if f < best_f:
            best_z, best_f = z, f
    return _mechanism_result(case, best_z, start_f, prob.penalty_base, t0=t0, seed=seed, restarts=done, nfev=nfev,
                             errs=errs, stopped=done < restarts and not interrupted, interrupted=interrupted,
                             fast=fast)


def _mechanism_result(case: MechanismCase, best_z: np.ndarray, start_f: float, penalty_base: float, *,
                      t0: float, seed: int, restarts: int, nfev: int, errs: list[float], stopped: bool,
                      interrupted: bool, fast: bool = True) -> MechanismSynthesisResult:
    """The result of the best design ``best_z``, evaluated again (the file's own design
    scored ``start_f``; scores from ``penalty_base`` up are infeasible)."""
    ev = evaluate_mechanism_design(case, best_z, fast)
    names = case.names
    design = {n: float(v) for n, v in zip(names, best_z)}
    d = apply_mechanism_design(case, best_z[:case.n_design])
    d["name"] = (f"{d.get('name', 'mechanism')} (synthesised, seed {seed}"
                 + (", interrupted: best so far)" if interrupted else ")"))
    ok = bool(ev.feasible)
    N = case.n_targets
    return MechanismSynthesisResult(
        case=case.name, problem=case.problem, error=ev.error if ok else float("inf"), design=design,
        x=np.asarray(best_z, float),
        start_design={n: float(v) for n, v in zip(names, start_vector(case))},
        start_error=start_f if start_f < penalty_base else None, feasible=ok,
        assembled_at_all_targets=ok, method=ev.method, seconds=time.time() - t0, seed=seed,
        restarts=restarts, nfev=nfev, inputs_deg=ev.inputs_deg if ok else case.values_deg, targets=case.targets,
        achieved=ev.achieved if ok else np.full((N, 2), np.nan),
        achieved_angles_deg=ev.achieved_angles_deg, target_angles_deg=case.angles_deg,
        path=ev.path if ok else np.zeros((0, 2)), mechanism=d, restart_errors=errs,
        stopped_by_time_limit=stopped, reason=ev.reason, interrupted=interrupted)
