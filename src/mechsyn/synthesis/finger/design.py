"""Paper 000's parametric synthesis of an adaptive finger with variable-length links (VLL).

Steps 8-13 of paper 000 (spec ``structural.md`` section 4), for every VLL combination:

1. **Stage 1 (step 8)**: fix the combination's VLL at their minimum constructible length
   ``l_min`` (the joint's ``limits[0]``) and optimise the design variables (joint
   coordinates of the drawn configuration, point positions, the VLL's direction) in the
   fully actuated mode (VLL locked) on discrete positions: at crank rotations
   ``dtheta_i`` from the drawn configuration the output links must have turned by
   ``dphi_i``. Objective: the RMS angle error (deg) over positions and links.
2. **VLL range (step 9)**: with the design fixed, each VLL of the combination is freed
   (underactuated mode, its length prescribed as a second input) and its length swept
   from ``l_min`` upwards over the whole crank range; ``l_max`` is the largest length
   such that every output point's path for every length in ``[l_min, l_max]`` stays in
   the working region (a polygon) and the finger stays assembled.
3. **Force stage (steps 10-12)**: static force analysis (gravity, the file's loads) in
   both modes; a second optimisation (seeded with the stage-1 design) minimises
   ``peak |R| + w * peak |M_in|`` (largest joint reaction and balancing moment over the
   crank range) of both modes (the VLL held at stage 1's ``l_max``) subject to the
   accuracy ``max(tolerance_deg, stage-1 RMS error)``, the region and the stage-1 VLL
   range (see :func:`~mechsyn.synthesis.finger.modes.force_objective`); its best few
   distinct designs are then checked in both modes (VLL range found again, forces at
   ``l_min`` and ``l_max``) and one replaces the stage-1 design only if its peak reaction
   is not higher and its criterion lower.
4. **Best variant (step 13)**: the combination with the smallest force criterion.

**Objective interface** (``scipy.optimize.differential_evolution``, seeded): a design
is a vector ``x`` of the case's variables; ``objective(x) -> float``. Feasible designs
get their criterion (``>= 0``, below ``INFEASIBLE``); a design that cannot be built, is
not assembled on one branch over the whole crank range (closed-form Assur dyads with the
drawn configuration's assembly modes, checked on a dense grid: no dead point between
targets) or leaves the region gets ``INFEASIBLE + violation``: never rewarded.

Fast evaluation: with its VLL locked, a cylinder-piston pair is one rigid binary link;
the locked model merges the two (masses and centres of mass combined), which makes the
finger a chain of driver + RRR dyads solved in closed form by ``kinematics.dyads``. The
VLL range and the final checks use the full file in the kinematics engine's passive
mode (Newton continuation), an independent method.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, fields, replace
from typing import Any, Callable

import numpy as np

from mechsyn.checkpoint import open_search_checkpoint
from mechsyn.errors import MechsynInputError
from mechsyn.interrupt import BestSoFar
from mechsyn.progress import Progress, ProgressCallback
from mechsyn.synthesis.finger.cases import FingerCase
from mechsyn.synthesis.finger.evaluation import INFEASIBLE, FingerEvaluation, Objective, apply_design, evaluate_locked
from mechsyn.synthesis.finger.modes import force_objective, mode_forces, underactuated_paths, vll_range
from mechsyn.synthesis.finger.population import locked_population
from mechsyn.synthesis.problem import SynthesisResult

__all__ = ["stage1_objective", "stage1_population", "force_population", "design_finger", "FingerDesign",
           "VariantResult"]


# --------------------------------------------------------------------------- objectives
def stage1_objective(case: FingerCase, combo: tuple[str, ...]) -> Objective:
    """RMS target error (deg) of a feasible design; ``INFEASIBLE + violation`` otherwise."""
    def f(x: np.ndarray) -> float:
        ev = evaluate_locked(case, x, combo)
        return ev.error_rms if ev.feasible else INFEASIBLE + ev.violation
    return f


def stage1_population(case: FingerCase, combo: tuple[str, ...]) -> Callable[[np.ndarray], np.ndarray]:
    """:func:`stage1_objective` of a population ``X`` (K, n) at once: through the
    compiled locked model (:mod:`~mechsyn.synthesis.finger.population`) where the case
    allows it, else design by design.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.finger import cases
    >>> case = cases.load_case(ms.examples.path("finger_design_case"))
    >>> designs = [[14, 6, 8, 48, 123.69006753], [20, 12, 3, 42, 150]]   # reference; not assembled
    >>> one = stage1_objective(case, ("S",))
    >>> [round(v, 9) for v in stage1_population(case, ("S",))(designs)] == [round(one(x), 9) for x in designs]
    True
    """
    pop = locked_population(case, combo)
    if pop is None:
        return _each(stage1_objective(case, combo))

    def f(X: np.ndarray) -> np.ndarray:
        ev = pop.evaluate(X)
        return np.where(ev.feasible, ev.error_rms, INFEASIBLE + ev.violation)
    return f


def force_population(case: FingerCase, combo: tuple[str, ...], tol: float,
                     hold: dict[str, float] | None = None, bound: float = np.inf
                     ) -> Callable[[np.ndarray], np.ndarray]:
    """:func:`force_objective` of a population ``X`` (K, n): the compiled locked model
    sorts out the designs that do not assemble, leave the region or miss the accuracy
    ``tol`` (their values as the one-design objective's); the others get the force
    analysis design by design."""
    one = force_objective(case, combo, tol, hold, bound)
    pop = locked_population(case, combo)
    if pop is None:
        return _each(one)

    def f(X: np.ndarray) -> np.ndarray:
        ev = pop.evaluate(X)
        with np.errstate(invalid="ignore"):
            out = np.where(ev.feasible, INFEASIBLE + (ev.error_rms - tol), INFEASIBLE + ev.violation)
            for k in np.flatnonzero(ev.feasible & (ev.error_rms <= tol)):
                out[k] = one(X[k])
        return out
    return f


def _each(f: Objective) -> Callable[[np.ndarray], np.ndarray]:
    """A population objective from a one-design objective."""
    return lambda X: np.array([f(x) for x in np.atleast_2d(X)])


# --------------------------------------------------------------------------- driver
@dataclass
class VariantResult:
    """One VLL combination's design: stage 1 (targets), VLL ranges, forces, final design."""

    combination: tuple[str, ...]
    stage1_design: dict[str, float]
    stage1_error_rms: float
    stage1_error_max: float
    design: dict[str, float]
    error_rms: float
    error_max: float
    achieved: dict[str, list[float]]
    vll_ranges: dict[str, tuple[float, float]]
    stage1_forces: dict[str, Any]
    forces: dict[str, Any]
    force_stage_improved: bool
    assembled_at_all_targets: bool = False
    mechanism: dict = field(repr=False, default_factory=dict)
    underactuated: dict[str, Any] = field(repr=False, default_factory=dict)
    evaluations: int = 0

    @property
    def adaptive(self) -> bool:
        """Every VLL of the combination has a length range (``l_max > l_min``)."""
        return all(r[1] > r[0] for r in self.vll_ranges.values())

    def to_dict(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in (
            "combination", "stage1_design", "stage1_error_rms", "stage1_error_max", "design", "error_rms",
            "error_max", "achieved", "vll_ranges", "stage1_forces", "forces", "force_stage_improved",
            "assembled_at_all_targets", "evaluations")}


@dataclass(repr=False)
class FingerDesign(SynthesisResult):
    """Result of :func:`design_finger`: every searched VLL combination, the best one.

    A :class:`~mechsyn.synthesis.problem.SynthesisResult`: the common fields describe the
    best variant: ``x`` (its design vector, in the case's variable order), ``design``
    (name -> value), ``error`` (RMS target error, deg), ``feasible`` (assembled at every
    target and adaptive: a VLL range ``l_max > l_min``), ``reason`` (why not, else
    ``""``), ``nfev`` (objective evaluations of every variant), ``seconds``, ``seed`` and
    ``interrupted`` (Ctrl-C ended the search: the best design so far).
    """

    case: str
    variants: list[VariantResult]
    best: int
    targets: dict[str, Any]
    tolerance_deg: float
    stopped_by_time_limit: bool = False
    notes: list[str] = field(default_factory=list)

    @property
    def best_variant(self) -> VariantResult:
        return self.variants[self.best]

    def to_dict(self) -> dict[str, Any]:
        b = self.best_variant
        return {"case": self.case, "seed": self.seed, "x": self.x.tolist(), "design": self.design,
                "error": self.error, "feasible": self.feasible, "reason": self.reason, "nfev": self.nfev,
                "best": {
                    "combination": b.combination, "design": b.design, "error_rms_deg": b.error_rms,
                    "error_max_deg": b.error_max, "vll_ranges": b.vll_ranges,
                    "peak_reaction": b.forces["peak_reaction"], "peak_input_moment": b.forces["peak_input_moment"],
                    "assembled_at_all_targets": b.assembled_at_all_targets},
                "targets": self.targets, "tolerance_deg": self.tolerance_deg,
                "variants": [v.to_dict() for v in self.variants], "seconds": self.seconds,
                "stopped_by_time_limit": self.stopped_by_time_limit, "interrupted": self.interrupted,
                "notes": self.notes,
                "units": {"angles": "deg", "lengths": "file unit", "forces": "file force unit",
                          "moments": "force x length"}}


@dataclass
class _Run:
    """State of one :func:`design_finger` run shared by its variants."""

    case: FingerCase
    seed: int
    deadline: float
    progress: ProgressCallback | None
    notes: list[str] = field(default_factory=list)
    stopped: bool = False
    state: dict = field(default_factory=lambda: {"interrupted": False})

    def say(self, msg: str, done: int = 0, total: int | None = None, best: float | None = None) -> None:
        if self.progress:
            self.progress(Progress(done, total, "finger design", best, msg))

    def reporter(self, label: str, stage: str, maxiter: int, what: str) -> Callable[[int, float], None] | None:
        """``report(generation, best)`` for :func:`_de`: the generations done of the stage
        ``VLL label: stage`` (counted within it), ``what`` formats the best."""
        progress = self.progress
        if not progress:
            return None

        def report(g: int, best: float) -> None:
            ok = best < INFEASIBLE
            progress(Progress(g, maxiter, f"VLL {label}: {stage}", best if ok else None,
                              f"generation {g}/{maxiter}, best " + (what.format(best) if ok else
                                                                    "design still infeasible")))
        return report


def _de(f: Callable[[np.ndarray], np.ndarray], bounds: list[tuple[float, float]], seed: int, maxiter: int,
        popsize: int, deadline: float, init: Any = "latinhypercube",
        report: Callable[[int, float], None] | None = None,
        state: dict | None = None) -> tuple[np.ndarray, float, int, bool, list]:
    """Seeded differential evolution of a population objective ``f(X (K, n)) -> (K,)``
    (SciPy's ``vectorized``, deferred updating); stops at ``deadline``;
    ``report(generation, best)``.

    Ctrl-C (:class:`KeyboardInterrupt`) ends it with the best design evaluated so far and
    sets ``state["interrupted"]``; it propagates when nothing was evaluated yet.
    """
    from scipy.optimize import differential_evolution

    stopped = [False]
    gen = [0, 0]  # generations, designs evaluated
    best = BestSoFar()

    def tracked(XT: np.ndarray) -> np.ndarray:
        X = np.atleast_2d(XT.T)
        gen[1] += len(X)
        values = np.asarray(f(X), float)
        best.offer(X, values)
        return values

    def cb(intermediate_result: Any) -> bool:
        gen[0] += 1
        if report is not None:
            report(gen[0], float(intermediate_result.fun))
        if time.monotonic() > deadline:
            stopped[0] = True
            return True
        return False

    try:
        r = differential_evolution(tracked, bounds, seed=seed, maxiter=maxiter, popsize=popsize, tol=1e-10,
                                   mutation=(0.5, 1.0), recombination=0.9, polish=False, init=init,
                                   callback=cb, updating="deferred", vectorized=True)
    except KeyboardInterrupt:
        if best.x is None or state is None:
            raise
        state["interrupted"] = True
        return best.x, best.f, gen[1], False, [(best.x, best.f)]
    pop = sorted(zip(np.asarray(r.population), np.asarray(r.population_energies)), key=lambda t: t[1])
    return np.asarray(r.x), float(r.fun), gen[1], stopped[0], pop


def design_finger(case: FingerCase, seed: int = 0, time_limit: float = 60.0,
                  progress: ProgressCallback | None = None, checkpoint: Any = None,
                  resume: bool = False) -> FingerDesign:
    """Run paper 000's steps 8-13 on ``case`` (see the module doc).

    Ctrl-C (:class:`KeyboardInterrupt`, also raised by ``progress``) ends the search: the
    variant being searched keeps its best design so far (its force stage is skipped),
    later variants are not searched, and the result has ``interrupted=True``.

    ``checkpoint`` (a file path): each finished VLL variant (its :class:`VariantResult`)
    is saved there as the run goes (:class:`mechsyn.checkpoint.RestartCheckpoint`);
    ``resume=True`` continues the run saved in it (same case and seed, else
    :class:`MechsynInputError`): finished variants are read back, only the others are
    searched, so the answer is the uninterrupted run's (unless a time limit cut a variant
    short: a variant is kept as its time limit left it).

    Parameters
    ----------
    case : FingerCase
        From :func:`mechsyn.synthesis.finger.cases.load_case`.
    seed : int
        Seed of the differential evolution (same seed, same design).
    time_limit : float
        Seconds for the optimisation stages; the final checks still run.
    progress : callable, optional
        ``progress(state)`` (:class:`mechsyn.progress.Progress`): the generations done of
        the stage's (``stage`` ``"VLL S: stage 1"``, ``"VLL S: force stage"``: counted within
        it), the best value so far; steps between them in words (stage ``"finger design"``).
    checkpoint : path-like, optional
        Checkpoint file, written whole after each finished variant.
    resume : bool
        Continue the run saved in ``checkpoint``.

    Returns
    -------
    FingerDesign

    Raises
    ------
    MechsynInputError
        When no VLL combination has a feasible design.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.finger.cases import load_case
    >>> res = ms.design_finger(load_case(ms.examples.path("finger_design_case")), seed=1, time_limit=20)
    >>> res.best_variant.error_rms < 1.0       # degrees, on the case's target positions
    True
    """
    import scipy.linalg  # noqa: F401 - SciPy's own BLAS: loaded before the limit, which applies to loaded ones
    from threadpoolctl import threadpool_limits

    # every linear solve of the search is of a few tens of unknowns: BLAS threads only cost
    # (on a loaded machine an 18 x 18 LU solve took 20 ms with them, 0.16 ms without)
    with threadpool_limits(limits=1, user_api="blas"):
        return _design(case, seed, time_limit, progress, checkpoint, resume)


def _finger_checkpoint(path: Any, resume: bool, case: FingerCase, seed: int) -> Any:
    """The run's checkpoint (``None`` without ``path``); its key: the case (its content,
    not its file name) and the seed."""
    return open_search_checkpoint(path, "synth finger-design", replace(case, source=""), resume=resume,
                                  seed=seed)


def _variant_record(v: VariantResult | None, notes: list[str], stopped: bool) -> dict[str, Any]:
    """A finished variant as checkpoint data: its result (every field), its notes and
    whether the time limit cut it short."""
    data = None if v is None else {f.name: getattr(v, f.name) for f in fields(v)}
    return {"variant": data, "notes": notes, "stopped": stopped}


def _restored_variant(run: _Run, combo: tuple[str, ...], rec: Any, source: str) -> VariantResult | None:
    """A finished variant read back from a checkpoint: only its two design vectors are
    taken, within the case's bounds, and everything else is computed again from them
    (:func:`_variant`), so a damaged record is one error naming it and a forged one
    (an error or a feasibility it does not have) cannot pass (issue 27)."""
    label = "+".join(combo)
    names = [v.name for v in run.case.variables]
    try:
        notes, stopped, data = list(map(str, rec["notes"])), rec["stopped"], rec["variant"]
        if not isinstance(stopped, bool):
            raise TypeError("stopped")
        if data is not None:
            x1 = np.array([float(data["stage1_design"][n]) for n in names])
            chosen = np.array([float(data["design"][n]) for n in names])
            nfev = int(data["evaluations"])
    except (TypeError, KeyError, ValueError, AttributeError, OverflowError):
        raise MechsynInputError(f"damaged record of VLL {label}", source=source, field=f"done.{label}",
                                hint="start afresh with --checkpoint (the file is not usable)") from None
    if data is not None:
        lo, hi = np.array([v.bounds for v in run.case.variables], float).T
        if not all(np.isfinite(x).all() and (x >= lo).all() and (x <= hi).all() for x in (x1, chosen)):
            raise MechsynInputError(f"the record of VLL {label} holds a design outside the case's bounds",
                                    source=source, field=f"done.{label}.design",
                                    hint="start afresh with --checkpoint (the file is not usable)")
    run.notes.extend(notes)
    run.stopped = run.stopped or stopped
    if data is None:
        return None
    d1, d = apply_design(run.case, x1, combo), apply_design(run.case, chosen, combo)
    ranges1 = {j: vll_range(run.case, d1, j)[:2] for j in combo}
    ranges = {j: vll_range(run.case, d, j)[:2] for j in combo}
    forces1 = mode_forces(run.case, d1, combo, ranges1)
    same = bool(np.array_equal(x1, chosen))
    forces_ = forces1 if same else mode_forces(run.case, d, combo, ranges)
    return _variant(run.case, combo, x1, evaluate_locked(run.case, x1, combo), chosen, ranges, forces1,
                    forces_, not same, nfev)


def _run_variant(run: _Run, combo: tuple[str, ...], ck: Any) -> VariantResult | None:
    """One variant: read back from the checkpoint when it holds it finished, else searched
    (and saved to the checkpoint unless Ctrl-C cut it short)."""
    label = "+".join(combo)
    if ck is not None and label in ck.done:
        return _restored_variant(run, combo, ck.done[label], str(ck.path))
    n0, st0 = len(run.notes), run.stopped
    run.stopped = False
    v = _design_variant(run, combo)
    if ck is not None and not run.state["interrupted"]:
        ck.finish_stage(label, _variant_record(v, run.notes[n0:], run.stopped))
    run.stopped = run.stopped or st0
    return v


def _design(case: FingerCase, seed: int, time_limit: float, progress: ProgressCallback | None,
            checkpoint: Any = None, resume: bool = False) -> FingerDesign:
    ck = _finger_checkpoint(checkpoint, resume, case, seed)
    t0 = time.monotonic()
    run = _Run(case, seed, t0 + time_limit, progress)
    variants = []
    for combo in case.combinations:
        if run.state["interrupted"]:
            run.notes.append(f"VLL {'+'.join(combo)}: not searched (interrupted)")
            continue
        try:
            v = _run_variant(run, combo, ck)
        except KeyboardInterrupt:  # before the variant evaluated anything: the earlier ones are kept
            if not variants:
                raise
            run.state["interrupted"] = True
            run.notes.append(f"VLL {'+'.join(combo)}: not searched (interrupted)")
            continue
        if v is not None:
            variants.append(v)
    if ck is not None and run.state["interrupted"]:
        ck.save()  # the finished variants (maybe none): --resume runs the others
    if not variants and run.state["interrupted"]:
        raise KeyboardInterrupt  # nothing feasible to keep
    if not variants:
        raise MechsynInputError(
            "no feasible design: " + "; ".join(run.notes), source=case.source, field="variables",
            hint="widen the bounds or the region, or move the targets")
    best = int(np.argmin([v.forces["criterion"] if v.adaptive else np.inf for v in variants]))
    b = variants[best]
    reason = "" if b.adaptive and b.assembled_at_all_targets else (
        "not assembled at every target" if not b.assembled_at_all_targets
        else "no VLL length range keeps the paths in the region (l_max = l_min)")
    return FingerDesign(case.source, variants, best,
                        {"inputs": case.target_inputs.tolist(),
                         "rotations": {k: v.tolist() for k, v in case.target_angles.items()}},
                        case.tolerance_deg, run.stopped, run.notes, seed=seed,
                        seconds=time.monotonic() - t0,
                        interrupted=run.state["interrupted"], x=np.array(list(b.design.values())),
                        design=dict(b.design), error=b.error_rms, feasible=not reason, reason=reason,
                        nfev=sum(v.evaluations for v in variants))


def _design_variant(run: _Run, combo: tuple[str, ...]) -> VariantResult | None:
    """Stage 1, the stage-1 design's VLL ranges and forces, the force stage, the checks."""
    case, label = run.case, "+".join(combo)
    bounds = [v.bounds for v in case.variables]
    run.say(f"VLL {label}: stage 1 (targets, VLL locked at l_min)")
    x1, f1, n1, st1, _ = _de(stage1_population(case, combo), bounds, run.seed, case.maxiter, case.popsize,
                             run.deadline, report=run.reporter(label, "stage 1", case.maxiter, "RMS error {:.4g} deg"),
                             state=run.state)
    run.stopped = run.stopped or st1
    if f1 >= INFEASIBLE:
        run.notes.append(f"VLL {label}: no feasible design (every tried design fails to assemble over "
                         "the crank range or leaves the region)")
        return None
    ev1 = evaluate_locked(case, x1, combo)
    known: dict[str, Any] = {}
    try:
        run.say("VLL ranges and forces of the stage-1 design")
        ranges1, forces1 = _stage1_checks(case, x1, combo, known)
        pop, n2 = _force_stage(run, combo, x1, f1, max(case.tolerance_deg, ev1.error_rms), ranges1, forces1)
        chosen, ranges, forces_, improved = _pick(run, combo, x1, pop, ranges1, forces1)
        return _variant(case, combo, x1, ev1, chosen, ranges, forces1, forces_, improved, n1 + n2)
    except KeyboardInterrupt:  # Ctrl-C/SIGTERM in the checks: the stage-1 design is the best known
        run.state["interrupted"] = True
        run.notes.append(f"VLL {label}: interrupted during the checks after the search: the stage-1 design kept "
                         "(the force stage's candidates not checked)")
        ranges1, forces1 = _stage1_checks(case, x1, combo, known)  # a second signal ends the command
        return _variant(case, combo, x1, ev1, x1, ranges1, forces1, forces1, False, n1)


def _stage1_checks(case: FingerCase, x1: np.ndarray, combo: tuple[str, ...], known: dict[str, Any]
                   ) -> tuple[dict, dict]:
    """VLL ranges and forces of the stage-1 design, each kept in ``known`` once computed
    (computed again after Ctrl-C only where the signal cut it short)."""
    d1 = apply_design(case, x1, combo)
    if "ranges" not in known:
        known["ranges"] = {j: vll_range(case, d1, j)[:2] for j in combo}
    if "forces" not in known:
        known["forces"] = mode_forces(case, d1, combo, known["ranges"])
    return known["ranges"], known["forces"]


def _force_stage(run: _Run, combo: tuple[str, ...], x1: np.ndarray, f1: float, tol: float,
                 ranges1: dict, forces1: dict) -> tuple[list, int]:
    """Stage 2 (forces, both modes) from a population holding the stage-1 design: its
    final population, best first, and its number of evaluations."""
    case = run.case
    if run.state["interrupted"]:
        return [], 0
    bounds = [v.bounds for v in case.variables]
    rng = np.random.default_rng(run.seed)
    npop = max(5, case.popsize * len(bounds))
    lo, hi = np.array(bounds).T
    init = lo + rng.random((npop, len(bounds))) * (hi - lo)
    init[0] = x1
    for k in range(1, min(npop, 1 + npop // 3)):  # a third of it near the stage-1 design
        init[k] = np.clip(x1 + 0.05 * (hi - lo) * rng.standard_normal(len(bounds)), lo, hi)
    run.say("stage 2: forces (both modes)")
    f = force_population(case, combo, tol, {j: r[1] for j, r in ranges1.items()}, forces1["criterion"])
    _x2, _f2, n2, st2, pop = _de(f, bounds, run.seed, case.force_maxiter, case.popsize, run.deadline,
                                 init=init, state=run.state,
                                 report=run.reporter("+".join(combo), "force stage", case.force_maxiter,
                                                     "criterion {:.4g}"))
    run.stopped = run.stopped or st2
    return pop, n2


def _pick(run: _Run, combo: tuple[str, ...], x1: np.ndarray, pop: list, ranges1: dict, forces1: dict
          ) -> tuple[np.ndarray, dict, dict, bool]:
    """The locked-mode criterion steers the force stage; its best few distinct members
    are checked in both modes (VLL range and forces) and one is accepted only if the
    peak reaction does not rise and the criterion falls."""
    case = run.case
    chosen, ranges, forces_, improved = x1, ranges1, forces1, False
    uniq: list[np.ndarray] = []
    for x, e in pop:
        if e < INFEASIBLE and not np.allclose(x, x1) and not any(
                np.allclose(x, u, rtol=0, atol=1e-6) for u in uniq):
            uniq.append(x)
    for x in uniq[:case.candidates]:
        if time.monotonic() > run.deadline:
            run.stopped = True
            break
        d2 = apply_design(case, x, combo)
        try:
            ranges2 = {j: vll_range(case, d2, j)[:2] for j in combo}
            forces2 = mode_forces(case, d2, combo, ranges2)
        except MechsynInputError:
            continue
        if all(r[1] > r[0] for r in ranges2.values()) and forces2["peak_reaction"] <= forces_["peak_reaction"] \
                and forces2["criterion"] < forces_["criterion"]:
            chosen, ranges, forces_, improved = x, ranges2, forces2, True
    return chosen, ranges, forces_, improved


def _variant(case: FingerCase, combo: tuple[str, ...], x1: np.ndarray, ev1: FingerEvaluation, chosen: np.ndarray,
             ranges: dict, forces1: dict, forces_: dict, improved: bool, nfev: int) -> VariantResult:
    """The variant's result: the chosen design drawn with its VLL ranges as limits, and
    its output paths at five lengths across each range."""
    names = [v.name for v in case.variables]
    ev = evaluate_locked(case, chosen, combo)
    d = apply_design(case, chosen, combo)
    for j in d["joints"]:
        if j["id"] in ranges:
            j["limits"] = list(ranges[j["id"]])
    under = {}
    for jid in combo:
        lens = np.linspace(ranges[jid][0], ranges[jid][1], 5)
        under[jid] = {"lengths": lens, "paths": underactuated_paths(case, d, jid, lens)}
    return VariantResult(
        combination=combo, stage1_design=dict(zip(names, x1.tolist())), stage1_error_rms=ev1.error_rms,
        stage1_error_max=ev1.error_max, design=dict(zip(names, chosen.tolist())), error_rms=ev.error_rms,
        error_max=ev.error_max, achieved={k: v.tolist() for k, v in ev.achieved.items()},
        vll_ranges=ranges, stage1_forces=forces1, forces=forces_, force_stage_improved=improved,
        assembled_at_all_targets=bool(ev.q is not None and np.isfinite(ev.q).all()),
        mechanism=d, underactuated=under, evaluations=nfev)
