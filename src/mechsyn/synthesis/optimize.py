"""Global optimisation for dimensional synthesis: multi-start, polishing, pluggable back ends.

Pipeline of :func:`synthesize_path` for one seed ``S``:

1. ``restarts`` child seeds are drawn from ``numpy.random.SeedSequence(S)`` (reproducible:
   the same ``S`` and ``restarts`` give the same result, whatever ``workers`` is, unless
   the time limit cuts runs short);
2. each restart runs the global optimiser (default: SciPy's ``differential_evolution``
   with ``vectorized=True``, so the whole population is one NumPy evaluation) on the
   problem's feasibility-first fitness. For free timing the global search sees only the
   linkage variables; each candidate's crank angles come from a vectorised nearest-point
   projection onto its coupler curve (:meth:`PathProblem.project_timing`);
3. the best few distinct members are polished by ``scipy.optimize.least_squares`` on all
   variables (the residuals ``C_i - Cd_i``); a polished design is kept only if it is
   feasible and better;
4. the best restart wins (ties: lowest restart index).

Pluggable optimisers
--------------------
An optimiser is a callable registered in :data:`OPTIMIZERS`::

    def my_optimizer(fitness, lower, upper, *, seed, should_stop, options) -> GlobalResult

``fitness(X)`` takes an array ``(P, d)`` and returns ``(P,)`` scores (lower is better;
infeasible designs already score worse than every feasible one); ``lower``/``upper`` are
the bounds ``(d,)``; ``seed`` an ``int``; ``should_stop(best_score)`` returns true when the
run must end (time limit); ``options`` a dict of optimiser settings. It returns a
:class:`GlobalResult` (best vector, its score, evaluations, optionally the final population
for polishing). ``register_optimizer("name", fn)`` makes it available as ``--optimizer name``.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import differential_evolution, least_squares

from mechsyn.errors import MechsynInputError
from mechsyn.interrupt import BestSoFar
from mechsyn.synthesis.path import PathCase, PathProblem, evaluate_design
from mechsyn.synthesis.problem import Progress, ProgressCallback, SeedLike, SynthesisResult, as_generator, resolve_seed


@dataclass
class GlobalResult:
    """Outcome of one global optimiser run."""

    x: np.ndarray
    fun: float
    nfev: int
    population: np.ndarray | None = None
    population_fun: np.ndarray | None = None


OptimizerFn = Callable[..., GlobalResult]


def scipy_de(fitness, lower, upper, *, seed: int, should_stop, options: dict[str, Any]) -> GlobalResult:
    """SciPy ``differential_evolution``, vectorised, no built-in polish, stall stopping.

    Options (defaults): ``strategy`` ("randtobest1bin"), ``popsize`` (10),
    ``maxiter`` (700), ``mutation`` ((0.5, 1.0)), ``recombination`` (0.9), ``stall``
    (generations without a relative improvement of 1e-6 before stopping; 300),
    ``init_oversample`` (20: the initial population is the best ``popsize * d`` of
    ``20 popsize d`` uniform samples, ranked by the feasibility-first fitness).
    """
    stall = int(options.get("stall", 300))
    state = {"best": np.inf, "since": 0}

    def callback(intermediate_result):
        fun = float(intermediate_result.fun)
        if fun < state["best"] - 1e-6 * abs(state["best"]) or not np.isfinite(state["best"]):
            state["best"], state["since"] = fun, 0
        else:
            state["since"] += 1
        return bool(state["since"] >= stall or should_stop(fun))

    init = options.get("init", "latinhypercube")
    npop = int(options.get("popsize", 10)) * len(lower)
    oversample = int(options.get("init_oversample", 20))
    if oversample > 1 and isinstance(init, str):
        # start from the best of many uniform samples (feasible ones first): the same
        # feasibility-first fitness ranks them, so DE starts inside the feasible region
        rng = np.random.default_rng(seed)
        X = rng.uniform(lower, upper, size=(oversample * npop, len(lower)))
        f = np.concatenate([fitness(chunk) for chunk in np.array_split(X, oversample)])
        init = X[np.argsort(f, kind="stable")[:npop]]
    res = differential_evolution(
        lambda X: fitness(X.T), list(zip(lower, upper)), vectorized=True, updating="deferred",
        strategy=options.get("strategy", "randtobest1bin"), popsize=int(options.get("popsize", 10)),
        maxiter=int(options.get("maxiter", 700)), mutation=options.get("mutation", (0.5, 1.0)),
        recombination=float(options.get("recombination", 0.9)), init=init,
        tol=0.0, atol=0.0, seed=seed, polish=False, callback=callback,
    )
    return GlobalResult(x=np.asarray(res.x), fun=float(res.fun), nfev=int(res.nfev),
                        population=getattr(res, "population", None),
                        population_fun=getattr(res, "population_energies", None))


def random_search(fitness, lower, upper, *, seed: int, should_stop, options: dict[str, Any]) -> GlobalResult:
    """Uniform random sampling (a baseline showing the interface; not for real use)."""
    rng = as_generator(seed)
    batch, rounds = int(options.get("popsize", 10)) * len(lower) * 10, int(options.get("maxiter", 100))
    best_x, best_f, nfev = None, np.inf, 0
    for _ in range(rounds):
        X = rng.uniform(lower, upper, size=(batch, len(lower)))
        f = fitness(X)
        nfev += batch
        i = int(np.argmin(f))
        if f[i] < best_f:
            best_x, best_f = X[i], float(f[i])
        if should_stop(best_f):
            break
    return GlobalResult(x=best_x, fun=best_f, nfev=nfev)


OPTIMIZERS: dict[str, OptimizerFn] = {"de": scipy_de, "random": random_search}


def register_optimizer(name: str, fn: OptimizerFn) -> None:
    """Make ``fn`` (see the module docstring for its signature) available by ``name``."""
    OPTIMIZERS[name] = fn


def polish(problem: PathProblem, z: np.ndarray, max_nfev: int = 400) -> np.ndarray:
    """Least-squares polish of a full internal vector; returns it unchanged unless the
    polished design is feasible and strictly better (feasibility first). The finite
    differences of each Jacobian are one batch evaluation where the problem offers it
    (:meth:`PathProblem.residual_jacobian`), else SciPy's ``2-point`` scheme."""
    z = np.clip(np.asarray(z, float), problem.lower, problem.upper)
    f0 = problem.fitness(z[None, :])[0]
    try:
        res = least_squares(problem.residuals, z, jac=getattr(problem, "residual_jacobian", "2-point"),
                            bounds=(problem.lower, problem.upper), x_scale="jac",
                            method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=max_nfev)
    except (ValueError, np.linalg.LinAlgError):
        return z
    f1 = problem.fitness(res.x[None, :])[0]
    ev = problem.evaluate(res.x[None, :])
    if bool(ev.feasible[0]) and f1 < f0:
        return res.x
    return z


@dataclass
class RestartResult:
    index: int
    seed: int
    z: np.ndarray
    fitness: float
    nfev: int
    seconds: float


def _run_restart(case: PathCase, index: int, seed: int, optimizer: str, options: dict[str, Any],
                 deadline: float, n_polish: int, report=None, polish_reserve: float = 0.0,
                 target_error: float | None = None,
                 tracker: BestSoFar | None = None) -> RestartResult:
    t0 = time.monotonic()
    problem = PathProblem(case)
    m = problem.reduced_dim
    lower, upper = problem.lower[:m], problem.upper[:m]
    fn = OPTIMIZERS[optimizer]
    fitness = problem.reduced_fitness if tracker is None else tracker.wrap(problem.reduced_fitness)

    # leave a little of the budget for polishing, so the whole run keeps its time limit
    search_deadline = deadline - polish_reserve

    def should_stop(best):
        if report is not None:
            report(index, best)
        if target_error is not None and best <= target_error:
            return True  # feasible (infeasible scores exceed every error) and good enough
        return time.time() >= search_deadline

    g = fn(fitness, lower, upper, seed=seed, should_stop=should_stop, options=options)
    nfev = g.nfev
    # candidates to polish: the best, then the best distinct population members
    cands = [np.asarray(g.x, float)]
    if g.population is not None and g.population_fun is not None and n_polish > 1:
        order = np.argsort(g.population_fun)
        for i in order:
            x = g.population[i]
            if all(np.linalg.norm((x - c) / (upper - lower + 1e-300)) > 1e-3 for c in cands):
                cands.append(x)
            if len(cands) >= n_polish:
                break
    best_z, best_f = None, np.inf
    last = 0.5  # estimated seconds per polish; a polish starts only if it should end in time
    for c in cands:
        z = problem.expand(c)[0]
        if time.time() + 1.5 * last < deadline:
            tp = time.time()
            z = polish(problem, z)
            last = time.time() - tp
        f = float(problem.fitness(z[None, :])[0])
        if f < best_f:
            best_z, best_f = z, f
    return RestartResult(index=index, seed=seed, z=best_z, fitness=best_f, nfev=nfev,
                         seconds=time.monotonic() - t0)


@dataclass(repr=False)
class PathSynthesisResult(SynthesisResult):
    """Outcome of :func:`synthesize_path` (serialisable; ``to_dict`` gives the CLI JSON).

    A :class:`~mechsyn.synthesis.problem.SynthesisResult`: ``error`` is the sum of squared
    distances to the targets, ``design`` the case's variables, ``x`` the optimiser's vector
    of the winning restart, ``seed`` the integer that repeats the run.
    """

    case_id: str = ""
    assembled_at_all_targets: bool = False
    restarts: int = 0
    optimizer: str = "de"
    branch: int = 1
    targets: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    path: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    theta2: np.ndarray = field(default_factory=lambda: np.zeros(0))
    restart_errors: list[float] = field(default_factory=list)
    best_known: float | None = None
    target_error: float | None = None
    worst_transmission_angle_deg: float | None = None
    fold_distance_deg: float | None = None
    transmission_angle_min_deg: float | None = None
    fold_margin_deg: float | None = None
    resumed: int = 0
    size: float | None = None          # radius of the disc about the targets' centroid holding the linkage
    size_ratio: float | None = None    # size / the targets' diagonal (principal axes)
    max_size: float | None = None      # the bound on size_ratio (None: lifted)
    limited_by: str = ""               # the bounds the design sits on and how to lift them ("" when none)

    @property
    def target_reached(self) -> bool:
        return self.target_error is not None and self.feasible and self.error <= self.target_error

    def to_dict(self) -> dict[str, Any]:
        return {
            "case": self.case_id, "interrupted": self.interrupted, "error": self.error, "design": self.design,
            "assembled_at_all_targets": self.assembled_at_all_targets, "feasible": self.feasible,
            "worst_transmission_angle_deg": self.worst_transmission_angle_deg,
            "transmission_angle_min_deg": self.transmission_angle_min_deg,
            "fold_distance_deg": self.fold_distance_deg, "fold_margin_deg": self.fold_margin_deg,
            "size": self.size, "size_ratio": self.size_ratio, "max_size": self.max_size,
            "limited_by": self.limited_by,
            "target_error": self.target_error, "target_reached": self.target_reached,
            "seconds": self.seconds, "seed": self.seed, "restarts": self.restarts, "nfev": self.nfev,
            "optimizer": self.optimizer, "branch": self.branch, "best_known": self.best_known,
            "ratio_to_best_known": (self.error / self.best_known) if self.best_known else None,
            "restart_errors": self.restart_errors, "resumed_restarts": self.resumed, "theta2": self.theta2,
            "path": self.path, "targets": self.targets, **self.common(),
        }


def with_size_bound(case: PathCase, max_size: float | None = None) -> PathCase:
    """The case with the size bound the search keeps: ``max_size`` when given (0: none),
    else the case's own ``options.max_size``, else none: the bounds a case states on its
    variables (every length and pivot a case leaves free has them) are its design space,
    and no default overrides them.

    >>> import dataclasses, mechsyn as ms
    >>> from mechsyn.synthesis.path import load_cases
    >>> case = load_cases(ms.examples.path("path_cases_public"))[0]
    >>> with_size_bound(case).max_size, with_size_bound(case, 2.0).max_size, with_size_bound(case, 0).max_size
    (None, 2.0, None)
    """
    import dataclasses

    if max_size is not None and not max_size >= 0:
        raise MechsynInputError("must be >= 0 target diagonals (0: no bound)", field="max_size")
    if max_size is None:
        max_size = case.max_size
    return dataclasses.replace(case, max_size=max_size or None)


def bounds_deciding(case: PathCase, design: dict[str, Any], size_ratio: float | None,
                    check: dict[str, Any] | None = None) -> str:
    """The bounds a design sits on (within 1e-6 of their span: a variable's bounds, the size
    bound, and with ``check`` (:func:`~mechsyn.synthesis.path.evaluate_design`'s) the
    smallest transmission angle and the fold margin, of 90 degrees), each with how to lift
    it; "" when none decides the result.

    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.path import load_cases
    >>> case = load_cases(ms.examples.path("path_cases_public"))[0]
    >>> lo, hi = case.bounds()["r2"]
    >>> d = {v.name: 0.5 * (v.lower + v.upper) for v in case.variables}
    >>> bounds_deciding(case, d, None)
    ''
    >>> bounds_deciding(case, {**d, "r2": hi}, None).startswith(f"r2 = {hi:g} sits on its upper bound")
    True
    """
    out = []
    if case.max_size and size_ratio is not None and size_ratio >= case.max_size * (1 - 1e-6):
        out.append(f"size {size_ratio:.4g} diagonals sits on the size bound {case.max_size:g} "
                   "(--max-size or options.max_size; --max-size 0 lifts it)")
    out += _angles_deciding(case, check or {})
    for name, (lo, hi) in case.bounds().items():
        if name.startswith("theta2_") or name not in design or hi - lo <= 0:
            continue
        tol = 1e-6 * (hi - lo)
        for side, b in (("lower", lo), ("upper", hi)):
            if abs(float(design[name]) - b) <= tol:
                out.append(f"{name} = {b:g} sits on its {side} bound (the case's variables; widen it there)")
    return "; ".join(out)


def _angles_deciding(case: PathCase, check: dict[str, Any]) -> list[str]:
    """The transmission-angle limit and the fold margin where the design's angle sits on them."""
    out = []
    mu, fold = check.get("worst_transmission_angle_deg"), check.get("fold_distance_deg")
    if case.transmission_angle_min_deg and mu is not None and mu <= case.transmission_angle_min_deg + 9e-5:
        out.append(f"the worst transmission angle {mu:.4g} deg sits on its limit {case.transmission_angle_min_deg:g} "
                   "(--min-transmission-angle or options.transmission_angle_min_deg; 0 lifts it)")
    if case.grashof and case.fold_margin_deg and fold is not None and fold <= case.fold_margin_deg + 9e-5:
        out.append(f"the nearest approach to folding flat {fold:.4g} deg sits on the fold margin "
                   f"{case.fold_margin_deg:g} (--fold-margin or options.fold_margin_deg; 0 lifts it)")
    return out


def _path_reason(check: dict[str, Any], case: PathCase) -> str:
    """Why a path design is infeasible ("" when it is feasible)."""
    if check["feasible"]:
        return ""
    if not check["assembled_at_all_targets"]:
        return "the linkage cannot be assembled at every target"
    return (f"a constraint is violated (transmission angle >= {case.transmission_angle_min_deg}°, "
            f"fold margin {case.fold_margin_deg}°, "
            + (f"size <= {case.max_size} diagonals (--max-size), " if case.max_size else "")
            + "bounds or timing order)")


def restart_seeds(seed: SeedLike, restarts: int) -> list[int]:
    """Reproducible child seeds of ``seed`` (``numpy.random.SeedSequence.spawn`` of
    :func:`~mechsyn.synthesis.problem.resolve_seed`)."""
    return [int(s.generate_state(1)[0]) for s in np.random.SeedSequence(resolve_seed(seed)).spawn(restarts)]


def default_target_error(case: PathCase) -> float | None:
    """The error at which a run may stop: the case's best known error plus 1 % (so
    reaching the published best ends the run), ``None`` when the case has none."""
    return None if not case.best_known else 1.01 * float(case.best_known)


def synthesize_path(
    case: PathCase, *, seed: SeedLike = 0, time_limit: float = 60.0, restarts: int = 10, workers: int = 1,
    optimizer: str = "de", options: dict[str, Any] | None = None, n_polish: int = 5,
    progress: ProgressCallback | None = None, scheduler: Any = None,
    target_error: float | None = None, checkpoint: Any = None, resume: bool = False, max_size: float | None = None,
) -> PathSynthesisResult:
    """Optimise a path-generation case (see the module docstring for the pipeline).

    ``seed``: an int, ``None`` or a ``numpy.random.Generator``; the result's ``seed`` is
    the int that repeats the run. ``progress(state)`` is called as the run goes, with a
    :class:`~mechsyn.synthesis.problem.Progress` (restarts done of ``restarts``, the best
    feasible error so far).
    With ``workers > 1`` restarts run in that many local processes, with ``scheduler``
    (a ``dask.distributed`` scheduler address, or a ``Client``) on a Dask cluster
    (:func:`mechsyn.parallel.run_tasks`); the result equals the single-process one (same
    seeds, same deterministic choice of the best), unless the time limit cuts runs short.

    ``target_error`` (e.g. :func:`default_target_error`): a restart's global search ends
    as soon as its best feasible error is at most this, and the run ends after the first
    restart (in seed order) whose result reaches it; with workers, a later restart that had
    already finished is left out too, so the result is the single-process one.

    Ctrl-C (:class:`KeyboardInterrupt`, also when raised by ``progress``) ends the search
    and returns the best design evaluated so far with ``interrupted=True`` (serial runs;
    with workers, the restarts finished so far); it propagates only when nothing was
    evaluated yet.

    ``checkpoint`` (a file path): the finished restarts and the running one's best are saved
    there as the run goes (:class:`mechsyn.checkpoint.RestartCheckpoint`); ``resume=True``
    reads it and runs only the restarts not finished (same seeds: the result is the one
    an uninterrupted run gives, unless the time limit cut a restart short). The time
    limit counts from the resumed start.

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> from mechsyn.synthesis.fourbar import fourbar_position
    >>> from mechsyn.synthesis.path import PathCase
    >>> th = [0.0, 0.4, 0.8, 1.2, 1.6]              # targets traced by a known four-bar
    >>> C = fourbar_position(3.0, 1.0, 3.0, 2.5, np.array(th), branch=-1, rcx=1.0, rcy=1.0).C
    >>> case = PathCase.from_dict({
    ...     "id": "known", "targets": C.tolist(), "timing": {"type": "prescribed", "theta2": th},
    ...     "fixed": {"x0": 0.0, "y0": 0.0, "theta0": 0.0},
    ...     "variables": [{"name": n, "lower": lo, "upper": 6.0} for n, lo in
    ...                   (("r1", 0.1), ("r2", 0.1), ("r3", 0.1), ("r4", 0.1), ("rcx", -6.0), ("rcy", -6.0))]})
    >>> res = ms.synthesize_path(case, seed=0, time_limit=20, restarts=2, max_size=0)  # no size bound
    >>> res.feasible, bool(res.error < 1e-6), bool(res.size_ratio > 1.5)  # error: sum of squared distances
    (True, True, True)
    """
    from mechsyn.parallel import run_tasks

    check_optimizer(optimizer)
    case, options = with_size_bound(case, max_size), dict(options or {})
    t0 = time.time()
    seed = resolve_seed(seed)
    deadline, reserve = t0 + time_limit, min(4.0, 0.07 * time_limit)
    seeds = restart_seeds(seed, restarts)
    best, problem = [np.inf], PathProblem(case)
    ck = _path_checkpoint(checkpoint, resume, case, len(problem.lower), seed, restarts, optimizer, options, target_error)
    results = _finished_restarts(ck, problem, seeds)
    pending, loaded = _pending(results, restarts, target_error), len(results)

    def note(done, f):
        best[0] = min(best[0], f) if f < problem.penalty_base else best[0]  # feasible scores only
        if progress is not None:
            progress(Progress(done=done, total=restarts, stage="restarts", best=best[0]))

    local = workers <= 1 and scheduler is None
    done = [len(results)]

    def report(index, f):  # within a restart: only where it runs in this process
        note(done[0], f)
        t = trackers[index]
        if ck is not None and t is not None and t.x is not None and ck.due():
            ck.offer(index, seeds[index], problem.expand(t.x[None, :])[0], t.f, force=True)

    def finished(index, r):
        done[0] = len(results) + 1
        results.append(r)
        if ck is not None:  # saved before the progress callback, which may raise Ctrl-C
            ck.finish(r.index, seed=r.seed, x=r.z, fitness=r.fitness, nfev=r.nfev, seconds=r.seconds)
        note(done[0], r.fitness)

    trackers = [BestSoFar() if local else None for _ in seeds]  # in this process: kept if Ctrl-C cuts it short
    jobs = [(case, i, s, optimizer, options, deadline, n_polish, report if local else None,
             reserve, target_error, trackers[i]) for i, s in enumerate(seeds) if i in pending]
    interrupted = False
    try:
        if results and progress is not None:
            note(len(results), min(r.fitness for r in results))
        run_tasks(_run_restart, jobs, workers=workers, scheduler=scheduler,
                  on_result=finished, deadline=deadline - reserve,
                  stop=None if target_error is None else (lambda i, r: r.fitness <= target_error))
    except KeyboardInterrupt:
        interrupted = True
        results = _keep_best_so_far(problem, trackers, seeds, results, ck)
        if not results:
            raise
    return _path_result(case, problem, results, t0=t0, seed=seed, optimizer=optimizer,
                        interrupted=interrupted, target_error=target_error, resumed=loaded)


def check_optimizer(optimizer: str) -> None:
    """Refuse an optimiser name that is not registered in :data:`OPTIMIZERS`."""
    if optimizer not in OPTIMIZERS:
        from mechsyn.errors import MechsynInputError

        raise MechsynInputError(f"unknown optimiser {optimizer!r}", field="optimizer",
                                hint="one of " + ", ".join(sorted(OPTIMIZERS)))


def _finished_restarts(ck: Any, problem: PathProblem, seeds: list[int]) -> list[RestartResult]:
    """The restarts a checkpoint holds as finished (none without a checkpoint), each checked
    (:func:`_checked_record`) and re-evaluated: a stored fitness is never believed (nor is
    that of the partial restart, which competes after a second Ctrl-C)."""
    if ck is not None and ck.partial is not None:
        ck.partial["fitness"] = _checked_record(ck, problem, seeds, ck.partial["index"], ck.partial, "partial")
    return [] if ck is None else [
        RestartResult(index=i, seed=r["seed"], z=r["x"], fitness=_checked_record(ck, problem, seeds, i, r, "finished"),
                      nfev=r["nfev"], seconds=r["seconds"])
        for i, r in sorted(ck.finished.items())]


def _checked_record(ck: Any, problem: PathProblem, seeds: list[int], index: int, rec: dict[str, Any],
                    where: str) -> float:
    """The fitness of a restart read from a checkpoint, evaluated again; the record is
    refused (:class:`MechsynInputError` naming the field) when its seed is not the one its
    index draws or its design lies outside the case's bounds (crank angles of a free timing
    may wrap once around)."""
    field = f"{where}[{index}]" if where == "finished" else where
    if rec["seed"] != seeds[index]:
        raise MechsynInputError(f"restart {index} has the seed {rec['seed']}, not {seeds[index]}", source=str(ck.path),
                                field=f"{field}.seed", hint="start afresh with --checkpoint (the file is not usable)")
    z, lo, hi = np.asarray(rec["x"], float), problem.lower, problem.upper.copy()
    m = len(problem.linkage_vars)
    hi[m:] = np.maximum(hi[m:], lo[m:] + 2.0 * np.pi)
    tol = 1e-9 * (hi - lo + np.abs(lo) + np.abs(hi) + 1.0)
    bad = np.flatnonzero((z < lo - tol) | (z > hi + tol))
    if bad.size:
        k = int(bad[0])
        raise MechsynInputError(f"{problem.names[k]} = {z[k]:.6g} is outside the case's bounds "
                                f"[{problem.lower[k]:.6g}, {problem.upper[k]:.6g}]", source=str(ck.path),
                                field=f"{field}.x", hint="start afresh with --checkpoint (the file is not usable)")
    return float(problem.fitness(z[None, :])[0])


def _keep_best_so_far(problem: PathProblem, trackers: list, seeds: list[int], results: list[RestartResult],
                      ck: Any = None) -> list[RestartResult]:
    """After Ctrl-C: the best design of the first restart cut short joins ``results``; with
    a checkpoint, the running restart's best (or an earlier interrupted run's) competes and
    the checkpoint is saved."""
    have = {r.index for r in results}
    for i, t in enumerate(trackers):
        if t is not None and t.x is not None and i not in have:
            results.append(RestartResult(index=i, seed=seeds[i], z=problem.expand(t.x[None, :])[0],
                                         fitness=t.f, nfev=0, seconds=0.0))
            if ck is not None:
                ck.offer(i, seeds[i], results[-1].z, t.f)
            break
    if ck is not None:
        p = ck.partial
        if p is not None and p["index"] not in have:
            results = [r for r in results if r.index != p["index"]] + [RestartResult(
                index=p["index"], seed=p["seed"], z=p["x"], fitness=p["fitness"], nfev=0, seconds=0.0)]
        ck.save()
    return results


def _path_result(case: PathCase, problem: PathProblem, results: list[RestartResult], *, t0: float,
                 seed: int, optimizer: str, interrupted: bool,
                 target_error: float | None, resumed: int = 0) -> PathSynthesisResult:
    """The best restart (lowest fitness, then first in seed order), checked by
    :func:`~mechsyn.synthesis.path.evaluate_design`."""
    results.sort(key=lambda r: r.index)
    reached = [r.index for r in results if target_error is not None and r.fitness <= target_error]
    if reached and not interrupted:  # the restarts one process runs: up to the first that reached
        results = [r for r in results if r.index <= reached[0]]  # (a later one may have finished first)
    win = min(results, key=lambda r: (r.fitness, r.index))
    design = problem.design(win.z)
    check = evaluate_design(case, design)
    size = float(problem.size(problem.unpack(np.asarray(win.z, float)[None])[0])[0])
    diag = problem.frame[1]
    deciding = bounds_deciding(case, design, size / diag if diag > 0 else None, check)
    return PathSynthesisResult(
        case_id=case.id, error=check["error"], design=design, x=np.asarray(win.z, float),
        reason=_path_reason(check, case) or (f"a bound decides this result: {deciding}" if deciding else ""),
        assembled_at_all_targets=check["assembled_at_all_targets"], feasible=check["feasible"],
        seconds=time.time() - t0, seed=seed, restarts=len(results), nfev=sum(r.nfev for r in results),
        optimizer=optimizer, branch=case.branch, targets=case.targets, path=check["path"],
        theta2=check["theta2"],
        restart_errors=[r.fitness if r.fitness < problem.penalty_base else float("inf") for r in results],
        best_known=case.best_known, interrupted=interrupted, target_error=target_error,
        worst_transmission_angle_deg=check["worst_transmission_angle_deg"],
        fold_distance_deg=check["fold_distance_deg"],
        transmission_angle_min_deg=case.transmission_angle_min_deg,
        fold_margin_deg=case.fold_margin_deg if case.grashof else None,
        resumed=resumed, size=size, size_ratio=size / diag if diag > 0 else None, max_size=case.max_size,
        limited_by=deciding,
    )


def _path_checkpoint(path, resume, case, dim, seed, restarts, optimizer, options, target_error):
    from mechsyn.checkpoint import open_search_checkpoint

    return open_search_checkpoint(path, "synth path", case, resume=resume, dim=dim, seed=seed, restarts=restarts,
                                  optimizer=optimizer, options=options, target_error=target_error)


def _pending(results: list[RestartResult], restarts: int, target_error: float | None) -> set[int]:
    """Restarts still to run: not finished, and (with a target error) not after the first
    finished one that reached it (the uninterrupted run ends there)."""
    have = {r.index for r in results}
    reached = [r.index for r in results if target_error is not None and r.fitness <= target_error]
    end = min(reached, default=restarts)
    return {i for i in range(restarts) if i not in have and i < end}
