"""Curve to mechanism: retrieval from the curve database, then least-squares refinement.

:func:`synthesize_curve` takes a drawn curve and returns ranked 4-, 6- and 8-bar
linkages whose tracing point follows it:

1. **Normalise** the target: ``M`` points equally spaced in arc length (an open curve
   there and back), its Fourier descriptor (:mod:`.descriptors`).
2. **Retrieve**: nearest descriptors in the database (:mod:`.database`, Faiss through
   :mod:`.index`), for both senses of traversal; the candidates' curves are recomputed by
   the batch engine and re-ranked by the exact closed-form similarity alignment (best
   rotation, scale, translation, start point, sense and mirror image at once).
3. **Map** each retained design into the target's frame by its similarity (a linkage
   whose joints are rotated, scaled, translated or mirrored traces the curve so
   transformed, on the same assembly branch, mirrored with its input reversed).
4. **Refine** the best few dozen by ``scipy.optimize.least_squares`` on the joint and
   tracer coordinates: residuals are the symmetric chamfer distances in order (each
   target point to the traced polyline, each traced point to the target polyline, each
   to the stretch beside the samples the error's correspondence in order matches it to:
   :meth:`~mechsyn.synthesis.curves.fitting.FitProblem.matched`), so the refinement
   minimises the measure the candidates are ranked by; the Jacobian is one batch
   evaluation of all perturbed designs, the matched segments held fixed. A design must stay assembled on its
   branch over the whole input range (no dead point, no stepped-over dead point);
   leaving it is penalised, never accepted. Options: a crank (fully rotating input),
   a ground region for the frame pivots, a largest link-length ratio.
5. **Check** each final candidate by re-simulating its mechanism file through the
   ordinary :func:`mechsyn.kinematics.simulate` and comparing the tracer's path.

**The error** shown and ranked by is :func:`~mechsyn.synthesis.curves.fitting.chamfer_error`:
the symmetric chamfer distance along the curves in order, each curve's points (equally
spaced in arc length) to the other curve's polyline where a correspondence running along
both in order puts them, over the target's diagonal along its principal axes: a loop that
cuts across a letter loses to one that goes round it. ``nearest`` (the order-free chamfer,
each point to the nearest point of the other curve anywhere) is reported beside it. ``ordered``
(RMS distance between points equally spaced in arc length, best start and sense) is
reported as a diagnostic of the timing only.

**Anytime.** The time limit covers every phase (loading the database, retrieval,
refinement and the final checks, whose cost is measured on the first candidate and
reserved). The best retrieved designs are evaluated as they are first (an answer at any
limit, labelled "not refined"), before the checks by ``simulate`` load (Numba and the
compiled kernels: the largest cost of a short run); a check that cannot load by the limit
is not begun and the answer is given unchecked, labelled so; then a deterministic sequence of refinements runs: the
first round of retrieved seeds (the four-bars every third), then rounds that refine the best
design of each of the three leading topologies longer, restart about it (every joint
and the tracer, the coupler point free on its plane, moved at random by a wide and a
narrow step in turn, seeded by the round) and widen to further retrieved seeds, eight-bars
among them; a topology far behind the best drops out of the race (no further seeds, no
restarts: :meth:`_Run.tasks`). An evaluation past
the deadline stops the refinement under way with the best design it has evaluated. The
search ends at the limit, at ``target_error``, after ``refinements`` or on Ctrl-C.

The approach follows the retrieve-then-refine scheme of LInK (A. Nobari, A. Srivastava,
D. Gutfreund, K. Xu and F. Ahmed, "LInK: Learning joint representations of design and
performance spaces through contrastive learning for mechanism synthesis",
*Transactions on Machine Learning Research*, 2024), with exact enumeration of the
topologies (the atlas) instead of a learned embedding, and closed-form invariant
descriptors instead of a neural encoder.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.batch import simulate_batch
from mechsyn.synthesis.curves.database import CurveDatabase, load_database
from mechsyn.synthesis.curves.descriptors import align, fourier_descriptor, resample, swap_direction
from mechsyn.synthesis.curves.candidates import (UNCHECKED, CurveCandidate, CurveSynthesisResult, miss_reason,
                                                  nearest_miss, ranked)
from mechsyn.synthesis.curves.fitting import (DEFAULT_MAX_LINK_RATIO, DEFAULT_MAX_SIZE, DEFAULT_MIN_TRANSMISSION,
                                               DEFAULT_TOLERANCE, N_FINAL, Bounds, FitProblem, OutOfTime,
                                               curve_errors, departure, full_plan, input_offsets, link_pairs, now,
                                               link_ratio, path_sizes)
from mechsyn.synthesis.curves.frame import Frame
from mechsyn.synthesis.curves.target import SPARSE_POINTS, TargetCurve, smooth_samples, target_from_points
from mechsyn.synthesis.curves.topologies import TRACER, CurveTopology
from mechsyn.progress import Progress, ProgressCallback

__all__ = ["CurveCandidate", "CurveSynthesisResult", "synthesize_curve", "curve_errors"]

# ------------------------------------------------------------------------------ retrieval


@dataclass
class _Seed:
    row: int
    topo: CurveTopology
    params: np.ndarray      # in the working frame
    start: float
    stop: float
    closed: bool
    score: float            # alignment RMS / diagonal
    excess: float = 0.0     # summed relative bound violations of the mapped design

    @property
    def rank(self) -> float:
        """Retrieval order: the alignment error, worse the further outside the bounds."""
        return self.score * (1.0 + 4.0 * self.excess)


def _transform_design(params: np.ndarray, c: complex, t: complex, mirror: bool) -> np.ndarray:
    z = params[0::2] + 1j * params[1::2]
    if mirror:
        z = np.conj(z)
    w = c * z + t
    out = np.empty_like(params)
    out[0::2], out[1::2] = w.real, w.imag
    return out


def _retrieve(db: CurveDatabase, target: TargetCurve, k: int, max_links: int, crank: bool,
              bounds: Bounds, deadline: float = float("inf")) -> tuple[list[_Seed], str]:
    """The ``k`` nearest descriptors per link count and sense, aligned and mapped into
    the target's frame (:func:`_topology_seeds`), best first; topologies are taken by
    link count, then by their nearest descriptor, and none is begun past ``deadline``
    (the note returned says how many were left; "" when none)."""
    w = resample(target.points, 64, closed=target.closed)
    d = fourier_descriptor(w)
    first: dict[int, int] = {}      # row -> its best place in a retrieval list
    for n in range(4, max_links + 1, 2):   # each link count its own share of the retrieval
        index, sub = db.index(n)
        if index is None:
            continue
        ii = index.search(np.stack([d, swap_direction(d)]), k)
        for place, r in sorted((p, int(sub[i])) for row in ii for p, i in enumerate(row) if i >= 0):
            first.setdefault(r, place)
    rows_a = np.array(sorted(first), int)
    if crank:
        rows_a = rows_a[db.closed[rows_a]]
    if not target.closed:
        rows_a = rows_a[~db.closed[rows_a]]
    by_topo: dict[int, list[int]] = {}
    for r in rows_a.tolist():
        by_topo.setdefault(int(db.topology[r]), []).append(r)
    order = sorted(by_topo, key=lambda ti: (db.topologies[ti].n_links, min(first[r] for r in by_topo[ti]), ti))
    seeds: list[_Seed] = []
    for j, ti in enumerate(order):
        if j and now() > deadline:   # the first topology whatever the time: an answer
            seeds.sort(key=lambda s: (s.rank, s.row))
            return seeds, f"retrieval: {len(order) - j} of {len(order)} topologies left out at the time limit"
        seeds += _topology_seeds(db, db.topologies[ti], by_topo[ti], w, bounds.unit, bounds)
    seeds.sort(key=lambda s: (s.rank, s.row))
    return seeds, ""


def _topology_seeds(db: CurveDatabase, topo: CurveTopology, rs: list[int], w: np.ndarray, diag: float,
                    bounds: Bounds) -> list[_Seed]:
    """The retrieved rows of one topology aligned onto the target ``w`` and mapped into
    its frame, each with its alignment error and bound violations."""
    rs_a = np.array(rs)
    offs = np.array([input_offsets(*db.ranges[r], bool(db.closed[r])) for r in rs])
    X = np.array([db.design(r) for r in rs])
    P = simulate_batch(topo.plan, X, offs, flags=False).paths[TRACER]
    fine = np.all(np.isfinite(P), axis=(1, 2))
    if not fine.any():
        return []
    ok = np.flatnonzero(fine)
    closed_rows = db.closed[rs_a[ok]]
    curves = [resample(P[i], 64, closed=bool(c)) for i, c in zip(ok, closed_rows)]
    al = align(np.array(curves), w)
    out: list[_Seed] = []
    for j, i in enumerate(ok):
        r = rs[i]
        a, b = (float(v) for v in db.ranges[r])
        if not db.closed[r]:  # keep clear of the dead points that end the range
            a, b = a + 0.04 * (b - a), b - 0.04 * (b - a)
        mir = bool(al.mirror[j])
        if mir:  # a mirrored linkage runs its input the other way
            a, b = -b, -a
        params = _transform_design(db.design(r), complex(al.c[j]), complex(al.t[j]), mir)
        out.append(_Seed(r, topo, params, a, b, bool(db.closed[r]), float(al.rms[j]) / diag))
    if out:  # the mapped designs' size, link ratio and transmission angle over their range
        Xs = np.array([s.params for s in out])
        res = simulate_batch(full_plan(topo), Xs, np.array([input_offsets(s.start, s.stop, s.closed, 48) for s in out]),
                             transmission=bounds.transmission > 0, flags=False)
        mu = res.min_transmission_angle if res.min_transmission_angle is not None else np.full(len(out), 90.0)
        exc = bounds.excess(path_sizes(res.paths, bounds.centre), link_ratio(Xs, link_pairs(topo)), mu).sum(axis=1)
        for s, e in zip(out, exc):
            s.excess = float(e)
    return out


# ----------------------------------------------------------------------------- refinement


def _refine(seed: _Seed, target: TargetCurve, bounds: Bounds, max_nfev: int,
            deadline: float = float("inf")) -> CurveCandidate | None:
    """The seed refined in the working frame (None when it does not assemble); at the
    ``deadline`` (``now()``) the best design evaluated so far."""
    from scipy.optimize import least_squares   # here: a run out of time before refining never loads it

    prob = FitProblem(seed.topo, target, seed.closed, seed.start, seed.stop, bounds)
    prob.deadline = deadline
    x0 = seed.params
    try:
        prob.fun(x0)
    except OutOfTime:
        return None
    if prob.last_bad[0]:  # does not assemble over the range after the mapping
        return None
    try:
        x = least_squares(prob.fun, x0, jac=prob.jac, method="trf", x_scale=1.0,
                          max_nfev=max_nfev, xtol=1e-10, ftol=1e-10).x
    except (np.linalg.LinAlgError, OutOfTime):  # a singular step, or out of time: the best so far
        x = prob.best[1] if prob.best[1] is not None else x0
    return _candidate(seed.topo, x, seed.start, seed.stop, seed.closed, target, prob.nfev, bounds)


def _candidate(topo: CurveTopology, x: np.ndarray, start: float, stop: float, closed: bool,
               target: TargetCurve, nfev: int, bounds: Bounds, refined: bool = True) -> CurveCandidate | None:
    """The design's candidate in the working frame, with its errors, quality and worst
    departure over :data:`N_FINAL` input samples (lengths in ``bounds.unit``); None when
    it is not assembled."""
    off = input_offsets(start, stop, closed, N_FINAL)
    res = simulate_batch(full_plan(topo), x[None], off, transmission=True)
    if not res.assembled.all() or res.branch_jump[0]:
        return None
    path = res.paths[TRACER][0]
    ch, near, od = curve_errors(path, target, closed, bounds.unit)
    size = float(path_sizes(res.paths, bounds.centre)[0])
    at, far = departure(path, target, closed)
    return CurveCandidate(topo, x, start, stop if not closed else start + 360.0, ch, od,
                          float(res.min_transmission_angle[0]), float(link_ratio(x, link_pairs(topo))[0]),
                          path, nfev=nfev, size=size, size_ratio=size / bounds.unit, refined=refined,
                          departs_at=at, departure=far / bounds.unit, nearest=near)


def _verify(c: CurveCandidate) -> None:
    """Re-simulate through the ordinary ``simulate`` and compare the tracer's path."""
    from mechsyn.io.load import mechanism_from_dict
    from mechsyn.kinematics import simulate

    t = c.topology
    off = input_offsets(c.start, c.stop, c.full_turn, N_FINAL)
    try:
        mech = mechanism_from_dict(c.mechanism())
        # the reference configuration first: simulate takes the assembly mode from it
        vals = c.reference_input + np.concatenate([[0.0], off])
        sim = simulate(mech, {t.plan.input_joint: vals}, points=[TRACER])
    except MechsynInputError as exc:
        c.verified, c.verification = False, f"simulate refused the mechanism: {exc.message}"
        return
    P = sim.points[TRACER].position[1:]
    if not sim.assembled.all():
        c.verified, c.verification = False, "simulate finds it not assembled over the input range"
        return
    err = float(np.max(np.abs(P - c.path)))
    scale = float(np.abs(c.path).max()) + 1.0
    c.verified = err <= 1e-7 * scale
    c.verification = f"simulate reproduces the path to {err / c.size:.1e} of its size" if c.verified else \
        f"simulate differs from the batch path by {err:.3g}"

def synthesize_curve(
    target: TargetCurve | np.ndarray,
    *,
    max_links: int = 8,
    time_limit: float = 60.0,
    top: int = 5,
    n_refine: int = 32,
    retrieve: int = 300,
    crank: bool = False,
    ground_region: tuple[float, float, float, float] | None = None,
    max_size: float | None = DEFAULT_MAX_SIZE,
    max_link_ratio: float | None = DEFAULT_MAX_LINK_RATIO,
    min_transmission: float = DEFAULT_MIN_TRANSMISSION,
    prefer: str = "simple",
    database: CurveDatabase | str | os.PathLike[str] | None = None,
    progress: ProgressCallback | None = None,
    max_nfev: int = 60,
    tolerance: float = DEFAULT_TOLERANCE,
    refinements: int | None = None,
    target_error: float | None = None,
    started: float | None = None,
) -> CurveSynthesisResult:
    """Ranked linkages (4 to ``max_links`` links) a designer can build whose tracing
    point follows a curve.

    Parameters
    ----------
    target : TargetCurve or (n, 2) array
        The curve (arrays: closed when the ends nearly meet). Fewer than
        :data:`~mechsyn.synthesis.curves.target.SPARSE_POINTS` points are read as samples
        of a smooth curve (:func:`~mechsyn.synthesis.curves.target.smooth_samples`).
    max_links : {4, 6, 8}
        Largest linkage.
    time_limit : float
        Seconds for the whole call, every phase included (see the module doc, "Anytime"),
        from ``started`` (a ``time.perf_counter()``; default: the call); building a
        missing database first is not counted (a note says so).
    top : int
        Candidates returned (see ``prefer``; the first three of distinct topologies).
    n_refine, retrieve : int
        Designs refined in the first round (every third a four-bar with ``prefer="simple"``),
        and nearest descriptors retrieved per query and link count.
    refinements : int, optional
        A fixed number of refinements (the start of the sequence a timed run follows).
    target_error : float, optional
        Stop once the best error is within it (default: once three topologies, or
        ``top``, have a candidate within ``tolerance``).
    crank : bool
        Only fully rotating inputs (without it a full turn is preferred, not required).
    ground_region : (x0, y0, x1, y1), optional
        Box (target coordinates) the frame pivots must stay in.
    max_size : float or None
        Every joint and the tracer stay over the whole motion within this many target
        diagonals (:attr:`TargetCurve.diagonal`) of the target's centroid (default
        1.5); None lifts it. Both are the curve's own: the bound turns with the drawing.
    max_link_ratio, min_transmission : float or None
        Largest longest / shortest link length (default 10; None lifts it); smallest
        transmission angle of every RRR dyad over the motion (degrees, default 30; 0).
    prefer : {"simple", "accuracy"}
        ``"simple"``: within ``tolerance`` fewer links, a full turn, the larger
        transmission angle (5° steps), then the error; the rest by error. Or by error.
    database : CurveDatabase or directory, optional
        Default: the local one (built on first use).
    tolerance : float
        Error (fraction of the diagonal, default 0.5 %) within which a candidate counts
        as tracing the curve (fewest links first among those).
    progress : callable, optional
        ``progress(state)``: a :class:`mechsyn.progress.Progress` (stage, done of total,
        the best error so far; the database build's stage ``"build"`` when it builds).

    Returns
    -------
    CurveSynthesisResult
        Candidates best first, within the bounds, checked by ``simulate``, the simplest
        within the tolerance and the most accurate labelled (``role``; the latter always
        listed); with none, ``nearest_miss`` the design closest to the bounds (named in
        ``reason``). Ctrl-C returns the best so far (``interrupted``).

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.synthesis.curves.database import build_database, load_database
    >>> import tempfile
    >>> d = tempfile.mkdtemp()
    >>> _ = build_database(d, max_links=4, per_topology=400)
    >>> t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    >>> ellipse = np.c_[3 * np.cos(t), np.sin(t)]
    >>> res = synthesize_curve(ellipse, max_links=4, top=1, refinements=3, database=load_database(d))
    >>> c = res.candidates[0]
    >>> c.topology.label, c.verified, c.chamfer < 0.02, c.size_ratio <= 1.5, c.role.endswith("most accurate")
    ('four-bar', True, True, True, True)
    """
    t0 = now() if started is None else min(started, now())
    o = dict(max_links=max_links, time_limit=time_limit, top=top, n_refine=n_refine, retrieve=retrieve, crank=crank,
             ground_region=ground_region, max_size=max_size, max_link_ratio=max_link_ratio,
             min_transmission=min_transmission, prefer=prefer, max_nfev=max_nfev, tolerance=tolerance,
             refinements=refinements, target_error=target_error)
    return _loaded_and_searched(target, database, t0, o, progress)


def _loaded_and_searched(target, database, t0: float, o: dict[str, Any],
                         progress: ProgressCallback | None) -> CurveSynthesisResult:
    """The options checked, the database loaded (a first build not counted in the time),
    the search run."""
    user = _checked_target(target, o["max_links"], o["time_limit"], o["top"], o["max_link_ratio"], o["crank"])
    _checked_bounds(o["max_size"], o["min_transmission"], o["prefer"], o["tolerance"], o["refinements"],
                    o["target_error"])
    built: list[float] = []
    if database is None or isinstance(database, (str, os.PathLike)):
        database = load_database(database, max_links=o["max_links"], progress=_build_timer(progress, built))
    if built:  # a first build is not part of the search's time
        t0 += built[-1] - built[0]
    res = _search(user, database, t0, o, progress)
    if built:
        res.notes.insert(0, f"the curve database was built first ({built[-1] - built[0]:.0f} s, once; "
                            "not counted in the time limit)")
    return res


def _build_timer(progress: ProgressCallback | None, built: list[float]) -> ProgressCallback:
    """The progress callback passed to the database loader: it notes when a build starts and ends."""
    def cb(state):
        if state.stage == "build":
            built.append(now())
        if progress is not None:
            progress(state)
    return cb


def _search(user: TargetCurve, database: CurveDatabase, t0: float, o: dict[str, Any],
            progress: ProgressCallback | None) -> CurveSynthesisResult:
    """The search of :func:`synthesize_curve` (options ``o`` checked): sparse targets
    smoothed, the working frame, retrieval, the anytime refinement, ranking and the
    checks by ``simulate``, mapping back."""
    notes: list[str] = []
    if len(user.points) < SPARSE_POINTS:
        notes.append(f"{len(user.points)} points read as samples of a smooth curve (a "
                     f"{'periodic ' if user.closed else ''}spline through them), not a polygon")
        user = smooth_samples(user)
    frame = Frame.of(user, rotate=o["ground_region"] is None)
    if o["max_size"] is not None and o["max_size"] < frame.circumradius(user):
        raise MechsynInputError(f"{o['max_size']:g}: the disc about the target's centroid must hold the target "
                                f"itself ({frame.circumradius(user):.3f} diagonals)", field="max_size",
                                hint="give a larger value, or lift it")
    work = frame.inward(user)
    bounds = frame.bounds(user, o["max_size"], o["max_link_ratio"], o["min_transmission"], o["ground_region"])
    end = t0 + o["time_limit"]

    def report(stage, done, total, best, nfev):
        if progress is not None:
            progress(Progress(done=done, total=total, stage=stage, best=best))

    report("retrieve", 0, 1, float("nan"), 0)
    loaded = now() - t0     # what the start cost this process: the measure of its pace
    # retrieval may use at most a third of what is left (the rest: the first evaluations and
    # check, which load compiled kernels, refinement and the final checks)
    seeds, note = _retrieve(database, work, o["retrieve"], o["max_links"], o["crank"], bounds,
                            deadline=now() + (end - now()) / 3)
    report("retrieve", 1, 1, seeds[0].score if seeds else float("nan"), 0)
    if note:
        notes.append(note)
    run = _Run(work, bounds, o, report, end, notes=notes,
               load_cost=0.0 if _CHECKS_LOADED else max(MIN_LOAD_COST, LOAD_FACTOR * loaded))
    if not seeds:
        run.notes.append("no database design matched the options (crank, links, open/closed)")
    run.search(seeds)
    out = ranked(run.cands, o["top"], o["tolerance"], o["prefer"], run.verify, run.notes)
    miss = nearest_miss(run.misses, bounds, run.verify, run.notes) if not out else None
    if not out and not miss:
        run.notes.append(f"{len(seeds)} retrieved designs, {run.assembled} of them assembled over their range "
                         f"within the time; none traced the target within the bounds")
    report("done", 1, 1, out[0].chamfer if out else float("nan"), run.nfev)
    res = _result(user, [frame.outward(c) for c in out], now() - (end - o["time_limit"]),
                  len(seeds), run.done, run.nfev, run.interrupted, run.notes)
    res.time_limit = o["time_limit"]
    res.bounds = {"max_size": o["max_size"], "max_link_ratio": o["max_link_ratio"], "tolerance": o["tolerance"],
                  "min_transmission_angle": o["min_transmission"], "prefer": o["prefer"],
                  "target_error": o["target_error"], "refinements": o["refinements"]}
    res.nearest_miss = frame.outward(miss) if miss is not None else None
    if miss is not None:
        res.reason = miss_reason(miss, bounds)
    return res


def _checked_target(target: TargetCurve | np.ndarray, max_links: int, time_limit: float, top: int,
                    max_link_ratio: float | None, crank: bool) -> TargetCurve:
    """The target as a :class:`TargetCurve`; options no search can meet are refused."""
    if not isinstance(target, TargetCurve):
        target = target_from_points(target)
    if max_links not in (4, 6, 8):
        raise MechsynInputError(f"max links {max_links}: choose 4, 6 or 8", field="max_links")
    if not time_limit > 0:
        raise MechsynInputError("must be positive", field="time_limit")
    if top < 1:
        raise MechsynInputError("must be at least 1", field="top")
    if max_link_ratio is not None and not max_link_ratio > 1:
        raise MechsynInputError("must be greater than 1", field="max_link_ratio")
    if crank and not target.closed:
        raise MechsynInputError("a crank (full turn) traces a closed curve; the target is open",
                                field="crank", hint="drop --crank or close the target")
    return target


def _checked_bounds(max_size: float | None, min_transmission: float, prefer: str, tolerance: float,
                    refinements: int | None, target_error: float | None) -> None:
    if max_size is not None and not max_size > 0:
        raise MechsynInputError(f"{max_size}: the disc must hold the target itself", field="max_size",
                                hint="give a positive number of target diagonals, or lift it")
    if not 0 <= min_transmission < 90:
        raise MechsynInputError("must be an angle in degrees in [0, 90)", field="min_transmission")
    if prefer not in ("simple", "accuracy"):
        raise MechsynInputError(f"{prefer!r}: choose simple or accuracy", field="prefer")
    if not 0 < tolerance < 1:
        raise MechsynInputError("must be a fraction of the diagonal in (0, 1)", field="tolerance")
    if refinements is not None and not refinements >= 0:
        raise MechsynInputError("must be a number of refinements >= 0", field="refinements")
    if target_error is not None and not 0 < target_error < 1:
        raise MechsynInputError("must be a fraction of the diagonal in (0, 1)", field="target_error")


def _diverse(seeds: list[_Seed], n_refine: int, simple: bool = False) -> list[_Seed]:
    """The seeds to refine: at most a third from one topology, then filled up by rank;
    with ``simple`` the best four-bars (a third of ``n_refine``) and six-bars (a quarter)
    are picked first, by rank: the simplest linkages are always tried, however well the
    larger ones were retrieved."""
    picked: list[_Seed] = []
    per: dict[str, int] = {}
    cap = max(2, n_refine // 3)
    quota = {4: cap, 6: max(1, n_refine // 4)} if simple else {}
    for group in ([[s for s in seeds if s.topo.n_links == n][:q] for n, q in quota.items()] + [seeds]):
        for s in group:
            if len(picked) >= n_refine:
                break
            if per.get(s.topo.key, 0) < cap and all(s is not p for p in picked):
                picked.append(s)
                per[s.topo.key] = per.get(s.topo.key, 0) + 1
    if len(picked) < n_refine:
        chosen = {id(s) for s in picked}
        picked += [s for s in seeds if id(s) not in chosen][:n_refine - len(picked)]
        picked.sort(key=lambda s: (s.rank, s.row))
    return picked


MIN_LOAD_COST = 0.5  # seconds, at least, expected for loading the checks (simulate's imports and kernels)
LOAD_FACTOR = 1.5    # ... and this many times what the process's start cost it (imports, database):
                     # measured 4.7 s against 3.3 s at a load average of 11 on 2 cores
#: the seconds the checks took to load in this process (empty: not loaded yet)
_CHECKS_LOADED: list[float] = []
UNREFINED = 8        # retrieved designs evaluated as they are, before any refinement (answers at any limit)
MIN_UNREFINED = 3    # of them evaluated whatever the time: an answer at any limit
WIDEN = 8            # new retrieved seeds per round after the first
RESTARTS = 2         # perturbed restarts per leading topology per round (the leader one more)
RESTART_STEPS = (0.12, 0.04)   # their steps in turn, in target diagonals (over the square root of the round)
RACE = 1.25          # a topology whose best is beyond this many times the best of all ...
RACE_TRIES = 3       # ... after this many refinements gets no further retrieved seeds
LEADERS = 3          # topologies restarted and polished per round
EXIT_RESERVE = 0.25  # seconds left at the end for mapping back, output and the exit (measured 0.1 s
                     # after a search at load 10 on 2 cores, the CLI skipping the collector at exit)


@dataclass
class _Run:
    """The anytime refinement: a deterministic sequence of refinements (the first round
    of retrieved seeds, then rounds that polish and restart the best few topologies and
    widen to further retrieved seeds), stopped by the time limit, the target error, the
    number of refinements or Ctrl-C. Candidates inside the bounds are kept, the others
    are misses."""

    target: TargetCurve
    bounds: Bounds
    o: dict[str, Any]
    report: Callable[..., None]
    end: float
    cands: list[CurveCandidate] = field(default_factory=list)
    misses: list[CurveCandidate] = field(default_factory=list)
    done: int = 0
    nfev: int = 0
    assembled: int = 0
    interrupted: bool = False
    notes: list[str] = field(default_factory=list)
    verify_cost: float = 0.05   # seconds of one check by simulate (measured on the first candidate)
    load_cost: float = 0.0      # seconds the checks' first loading is expected to take (0: loaded)
    topologies: int = 3      # topologies among the retrieved designs
    tries: dict[str, int] = field(default_factory=dict)   # refinements begun per topology

    @property
    def best(self) -> float:
        return min((c.chamfer for c in self.cands), default=float("inf"))

    def deadline(self) -> float:
        """The end of refinement: the limit less the time the final checks will take
        (``top + 1`` checks by ``simulate`` at the measured cost, 1.2 times) and
        :data:`EXIT_RESERVE` (at most a tenth of the limit)."""
        return self.end - 1.2 * (self.o["top"] + 1) * self.verify_cost - self.load_cost - self.reserve()

    def verify(self, c: CurveCandidate, measure: bool = False) -> None:
        """The check by ``simulate`` (once per candidate; with ``measure`` run again, timed:
        the first run pays for compiling the mechanism's solver). Before the checks are
        loaded in this process (``simulate``'s imports and compiled kernels), a check that
        cannot load by the limit is not begun: the candidate is answered unchecked,
        labelled :data:`~mechsyn.synthesis.curves.candidates.UNCHECKED`."""
        if c.verification and c.verification != UNCHECKED and not measure:
            return
        if self.load_cost and now() + self.load_cost > self.end - self.reserve():
            c.verified, c.verification = False, UNCHECKED
            if not any(n.startswith("answered before") for n in self.notes):
                self.notes.append("answered before the check by simulate could load within the time limit "
                                  f"(its imports and compiled kernels, about {self.load_cost:.1f} s here)")
            return
        t = now()
        _verify(c)
        if self.load_cost:   # loaded now
            self.load_cost = 0.0
            _CHECKS_LOADED.append(now() - t)
            measure = True
        if measure:
            t = now()
            _verify(c)
            self.verify_cost = now() - t

    def reserve(self) -> float:
        """Seconds kept at the end for mapping back, output and the exit."""
        return min(EXIT_RESERVE, 0.1 * self.o["time_limit"])

    def add(self, c: CurveCandidate | None) -> None:
        if c is None:
            return
        self.assembled += 1
        self.nfev += c.nfev
        if self.keeps(c):
            self.cands.append(c)
        else:
            self.misses.append(c)

    def keeps(self, c: CurveCandidate) -> bool:
        """Within the size, link-ratio and transmission bounds and the ground region."""
        exc = self.bounds.excess(np.array([c.size]), np.array([c.link_length_ratio]),
                                 np.array([c.min_transmission_angle]))
        return bool(exc.max() <= 1e-9) and (self.bounds.region is None or _in_region(c, self.bounds.region))

    def stop(self) -> str | None:
        """Why the search ends now (None: go on)."""
        o = self.o
        if o["refinements"] is not None and self.done >= o["refinements"]:
            return f"{self.done} refinements done (--refinements)"
        if now() >= self.deadline():
            return f"time limit: {self.done} refinements done"
        if o["target_error"] is not None and self.best <= o["target_error"]:
            return f"target error {100 * o['target_error']:g} % reached after {self.done} refinements"
        if o["target_error"] is not None or o["refinements"] is not None:
            return None
        need = min(o["top"], 3, self.topologies)
        if len({c.topology.key for c in self.cands if c.chamfer <= o["tolerance"] and c.refined}) >= need:
            return f"{need} topologies within {100 * o['tolerance']:g} % after {self.done} refinements"
        return None

    def search(self, seeds: list[_Seed]) -> None:
        """Evaluate the best retrieved designs as they are, then refine until :meth:`stop`."""
        self.topologies = len({s.topo.key for s in seeds})
        try:
            for i, s in enumerate(seeds[:UNREFINED]):
                if now() >= self.deadline() and (self.cands or i >= MIN_UNREFINED):
                    break   # out of time: one design within the bounds is an answer
                self.add(_candidate(s.topo, s.params, s.start, s.stop, s.closed, self.target, 0, self.bounds,
                                    refined=False))
            if self.cands:   # the answer first, then the checks loaded (if the time allows) and measured
                self.verify(min(self.cands, key=lambda c: c.chamfer), measure=True)
            for s, nfev in self.tasks(seeds):
                why = self.stop()
                if why:
                    self.notes.append(why)
                    return
                c = _refine(s, self.target, self.bounds, nfev, self.deadline())
                self.done += 1
                self.tries[s.topo.key] = self.tries.get(s.topo.key, 0) + 1
                self.add(c)
                if self.o["refinements"] is not None:
                    self.report("refine", self.done, self.o["refinements"], self.best, self.nfev)
                else:  # a timed run: the bar fills with the time
                    used = now() - (self.end - self.o["time_limit"])
                    self.report("refine", min(used, self.o["time_limit"]), self.o["time_limit"], self.best, self.nfev)
            self.notes.append(f"every retrieved design refined ({self.done} refinements)")
        except KeyboardInterrupt:
            self.interrupted = True
            self.notes.append("interrupted: the best found so far")

    def tasks(self, seeds: list[_Seed]):
        """The sequence of ``(seed, max_nfev)`` refinements (see the class doc); each
        round depends only on the candidates so far, so the sequence is deterministic.

        The topologies race (E. Even-Dar, S. Mannor and Y. Mansour, "Action elimination and
        stopping conditions for the multi-armed bandit and reinforcement learning problems",
        *JMLR* 7, 2006): a topology refined :data:`RACE_TRIES` times whose best is more than
        :data:`RACE` times the best of all gets no further retrieved seeds (in the first round
        either), a leader as far behind is neither polished nor restarted, and the leading
        topology gets one restart more;
        the restarts about a leader alternate a wide and a narrow step
        (:data:`RESTART_STEPS`): the in-order error has many local minima (its
        correspondence changes along the way), a wide step leaves the basin, a narrow one
        searches about it."""
        simple = self.o["prefer"] == "simple"
        first = _diverse(seeds, self.o["n_refine"], simple=simple)
        if simple:  # the four-bars (a third) every third, so they hold a third of any shorter time too
            first = _every_third(first)
        later: list[_Seed] = []
        for s in first:   # a topology out of the race is out of the first round's remainder too
            if self.racing(s.topo):
                yield s, self.o["max_nfev"]
            else:         # ... its seeds kept, should it come back
                later.append(s)
        used = {id(s) for s in first}
        rest = sorted(later, key=lambda s: (s.rank, s.row)) + [s for s in seeds if id(s) not in used]
        polished: set[int] = set()
        rnd = 0
        while True:
            rnd += 1
            leaders = self.leaders()
            for i, c in enumerate(leaders):
                if i and c.chamfer > RACE * self.best and not self.racing(c.topology):   # out of the race
                    continue
                if id(c) not in polished:  # a longer refinement of the best of the topology
                    polished.add(id(c))
                    yield _seed_of(c), 3 * self.o["max_nfev"]
                rng = np.random.default_rng([rnd, i])
                for k in range(RESTARTS + (i == 0)):  # restarts about it: every joint and the tracer moved
                    step = RESTART_STEPS[k % len(RESTART_STEPS)] * self.bounds.unit / np.sqrt(rnd)
                    yield _seed_of(c, _moved(c, step, rng)), self.o["max_nfev"]
            batch = _diverse([s for s in rest if self.racing(s.topo)], WIDEN, simple=False)
            chosen = {id(s) for s in batch}
            rest = [s for s in rest if id(s) not in chosen]
            yield from ((s, self.o["max_nfev"]) for s in batch)
            if not batch and not leaders:
                return

    def racing(self, topo: CurveTopology) -> bool:
        """Whether a topology still gets retrieved seeds: refined fewer than
        :data:`RACE_TRIES` times, or its best within :data:`RACE` times the best of all, or
        (``prefer="simple"``) fewer links than the best design's once that is within the
        tolerance (a simpler linkage within it would be listed first)."""
        if self.tries.get(topo.key, 0) < RACE_TRIES:
            return True
        if self.o.get("prefer") == "simple" and self.cands:
            lead = min(self.cands, key=lambda c: c.chamfer)
            if lead.chamfer <= self.o["tolerance"] and topo.n_links < lead.topology.n_links:
                return True
        mine = min((c.chamfer for c in self.cands if c.topology.key == topo.key), default=float("inf"))
        return mine <= RACE * self.best

    def leaders(self) -> list[CurveCandidate]:
        """The best candidate of each of the :data:`LEADERS` best topologies."""
        best: dict[str, CurveCandidate] = {}
        for c in sorted(self.cands, key=lambda c: (c.chamfer, c.topology.key)):
            best.setdefault(c.topology.key, c)
        return list(best.values())[:LEADERS]


def _every_third(seeds: list[_Seed]) -> list[_Seed]:
    """The four-bars at places 0, 3, 6, ... (by rank), the others between them (by rank).

    >>> from types import SimpleNamespace as S
    >>> s = [S(topo=S(n_links=n), rank=r, row=r) for r, n in enumerate([6, 8, 4, 6, 4, 8, 4, 6])]
    >>> [x.topo.n_links for x in _every_third(s)]
    [4, 6, 8, 4, 6, 8, 4, 6]
    """
    fours = sorted((s for s in seeds if s.topo.n_links == 4), key=lambda s: (s.rank, s.row))
    others = sorted((s for s in seeds if s.topo.n_links != 4), key=lambda s: (s.rank, s.row))
    out: list[_Seed] = []
    while fours or others:
        if fours:
            out.append(fours.pop(0))
        out += others[:2]
        others = others[2:]
    return out


def _moved(c: CurveCandidate, step: float, rng: np.random.Generator) -> np.ndarray:
    """The design moved at random (every joint and the tracer, normal with deviation
    ``step``): the first of the moves by ``step``, ``step / 2`` and ``step / 4`` whose
    mechanism is assembled over the candidate's range (one batch evaluation), else the
    first move (its refinement then finds it unassembled)."""
    scales = np.repeat([1.0, 0.5, 0.25], 2)
    X = c.params + step * scales[:, None] * rng.standard_normal((len(scales), len(c.params)))
    res = simulate_batch(c.topology.plan, X, input_offsets(c.start, c.stop, c.full_turn))
    fine = res.assembled.all(axis=1) & ~res.branch_jump   # as the refinement asks (no stepped-over dead point)
    return X[int(np.argmax(fine))]


def _seed_of(c: CurveCandidate, params: np.ndarray | None = None) -> _Seed:
    """A candidate (or a design beside it) as a seed of a further refinement."""
    return _Seed(-1, c.topology, c.params if params is None else params, c.start, c.stop, c.full_turn, c.chamfer)


def _result(target: TargetCurve, out: list[CurveCandidate], seconds: float, retrieved: int, refined: int,
            nfev: int, interrupted: bool, notes: list[str]) -> CurveSynthesisResult:
    """The result, its common synthesis fields from the first candidate."""
    best = out[0] if out else None
    names = [f"{n}_{xy}" for n in best.topology.plan.names for xy in "xy"] if best is not None else []
    x = np.asarray(best.params, float) if best is not None else np.zeros(0)
    return CurveSynthesisResult(
        target=target, candidates=out, retrieved=retrieved, refined=refined, notes=notes,
        seconds=seconds, interrupted=interrupted, nfev=nfev, x=x,
        design=dict(zip(names, map(float, x))),  # the points' coordinates, target frame
        error=best.chamfer if best is not None else float("nan"), feasible=best is not None,
        reason="" if best is not None else "no verified candidate: " + "; ".join(notes[-2:]))


def _in_region(c: CurveCandidate, box) -> bool:
    x0, y0, x1, y1 = box
    names = c.topology.plan.names
    xy = c.params.reshape(-1, 2)
    for j in c.topology.template["joints"]:
        if f"L{c.topology.frame}" in j["links"]:
            x, y = xy[names.index(j["id"])]
            if not (x0 - 1e-9 <= x <= x1 + 1e-9 and y0 - 1e-9 <= y <= y1 + 1e-9):
                return False
    return True
