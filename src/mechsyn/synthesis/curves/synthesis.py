"""Curve to mechanism: retrieval from the curve database, then least-squares refinement.

:func:`synthesize_curve` takes a drawn curve and returns ranked 4-, 6- and 8-bar
linkages whose tracing point follows it:

1. **Normalise** the target: ``M`` points equally spaced in arc length (an open curve
   there and back), its Fourier descriptor (:mod:`.descriptors`).
2. **Retrieve**: nearest descriptors in the database (:mod:`.database`, a SciPy
   ``cKDTree``), for both senses of traversal; the candidates' curves are recomputed by
   the batch engine and re-ranked by the exact closed-form similarity alignment (best
   rotation, scale, translation, start point, sense and mirror image at once).
3. **Map** each retained design into the target's frame by its similarity (a linkage
   whose joints are rotated, scaled, translated or mirrored traces the curve so
   transformed, on the same assembly branch, mirrored with its input reversed).
4. **Refine** the best few dozen by ``scipy.optimize.least_squares`` on the joint and
   tracer coordinates: residuals are the symmetric chamfer distances (each target
   point to the traced polyline, each traced point to the target polyline), with the
   similarity re-solved in closed form before each refinement; the Jacobian is one
   batch evaluation of all perturbed designs. A design must stay assembled on its
   branch over the whole input range (no dead point, no stepped-over dead point);
   leaving it is penalised, never accepted. Options: a crank (fully rotating input),
   a ground region for the frame pivots, a largest link-length ratio.
5. **Check** each final candidate by re-simulating its mechanism file through the
   ordinary :func:`mechsyn.kinematics.simulate` and comparing the tracer's path.

Errors are reported divided by the target's bounding-box diagonal: ``chamfer`` (mean of
the two mean nearest distances, point to polyline) and ``ordered`` (root mean square
distance between points equally spaced in arc length along both curves, best start
and sense, no re-scaling: the timing of a constant-speed crank against the drawing's
own parametrisation).

The approach follows the retrieve-then-refine scheme of LInK (A. Nobari, A. Srivastava,
D. Gutfreund, K. Xu and F. Ahmed, "LInK: Learning joint representations of design and
performance spaces through contrastive learning for mechanism synthesis",
*Transactions on Machine Learning Research*, 2024), with exact enumeration of the
topologies (the atlas) instead of a learned embedding, and closed-form invariant
descriptors instead of a neural encoder.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.batch import simulate_batch
from mechsyn.synthesis.curves.database import CurveDatabase, load_database
from mechsyn.synthesis.curves.descriptors import align, fourier_descriptor, resample, swap_direction
from mechsyn.synthesis.curves.fitting import (DEFAULT_MAX_LINK_RATIO, DEFAULT_MAX_SIZE, DEFAULT_MIN_TRANSMISSION,
                                               DEFAULT_TOLERANCE, N_FINAL, Bounds, FitProblem, curve_errors,
                                               full_plan, input_offsets, link_pairs, link_ratio, path_sizes)
from mechsyn.synthesis.curves.target import SPARSE_POINTS, TargetCurve, smooth_samples, target_from_points
from mechsyn.synthesis.curves.topologies import TRACER, CurveTopology
from mechsyn.synthesis.problem import Progress, SynthesisResult

__all__ = ["CurveCandidate", "CurveSynthesisResult", "synthesize_curve", "curve_errors"]



@dataclass
class CurveCandidate:
    """One ranked linkage (see :meth:`to_dict` for the reported fields)."""

    topology: CurveTopology
    params: np.ndarray              # design in the target's coordinates
    start: float                    # input offsets from the reference, degrees
    stop: float
    chamfer: float                  # / bbox diagonal
    ordered: float
    min_transmission_angle: float
    link_length_ratio: float
    path: np.ndarray                # (N, 2) traced path
    verified: bool = False
    verification: str = ""
    nfev: int = 0
    reference_input: float = float("nan")   # input angle (deg) of the design's configuration
    size: float = float("nan")              # radius about the target's centre holding every point
    size_ratio: float = float("nan")        # size / target diagonal

    def __post_init__(self) -> None:
        if not np.isfinite(self.reference_input):
            self.reference_input = float(self.topology.plan.reference_inputs(self.params)[0])

    @property
    def full_turn(self) -> bool:
        """The input turns fully (a crank)."""
        return bool(self.stop - self.start >= 360.0 - 1e-9)

    def quality(self) -> dict[str, Any]:
        """The design-quality fields: ``size`` (radius of the disc about the target's
        bounding-box centre that holds every joint and the tracer over the whole motion,
        target units), ``size_ratio`` (that over the target's diagonal), ``link_ratio``
        (longest over shortest link length), ``min_transmission_angle`` (degrees, worst
        RRR dyad over the motion) and ``full_turn``."""
        return {"size": float(self.size), "size_ratio": float(self.size_ratio),
                "link_ratio": float(self.link_length_ratio),
                "min_transmission_angle": float(self.min_transmission_angle), "full_turn": self.full_turn}

    def mechanism(self) -> dict:
        t = self.topology
        name = f"{t.name or f'{t.n_links}-bar'} tracing the target (mechsyn synth curve)"
        return t.mechanism(self.params, name=name)

    def to_dict(self) -> dict[str, Any]:
        t = self.topology
        ref = self.reference_input
        return {
            "mechanism": self.mechanism(),
            "tracer": TRACER,
            "input": {"joint": t.plan.input_joint, "start": ref + self.start, "stop": ref + self.stop},
            "links": t.n_links,
            "topology": t.label,
            "topology_key": t.key,
            "error": {"chamfer": self.chamfer, "ordered": self.ordered},
            "quality": self.quality(),
            "min_transmission_angle": self.min_transmission_angle,
            "link_length_ratio": self.link_length_ratio,
            "crank": self.full_turn,
            "verified": self.verified,
            "verification": self.verification,
        }


@dataclass(repr=False)
class CurveSynthesisResult(SynthesisResult):
    """Ranked candidates, best first (``to_dict()`` is the ``--json`` output).

    A :class:`~mechsyn.synthesis.problem.SynthesisResult` for the best candidate:
    ``error`` its chamfer error (in target diagonals; NaN without a candidate),
    ``design`` and ``x`` its parameters, ``nfev`` the refinements' evaluations, ``seed``
    None (the search is deterministic).
    """

    target: TargetCurve
    candidates: list[CurveCandidate]
    retrieved: int
    refined: int
    notes: list[str] = field(default_factory=list)
    bounds: dict[str, Any] = field(default_factory=dict)
    nearest_miss: CurveCandidate | None = None

    def to_dict(self) -> dict[str, Any]:
        miss = self.nearest_miss.to_dict() if self.nearest_miss is not None else None
        return {"candidates": [c.to_dict() for c in self.candidates],
                "target": {"points": self.target.points, "closed": self.target.closed,
                           "diagonal": self.target.diagonal},
                "bounds": self.bounds, "nearest_miss": miss,
                "seconds": self.seconds, "retrieved": self.retrieved, "refined": self.refined,
                "interrupted": self.interrupted, "notes": self.notes, **self.common()}

    def __str__(self) -> str:
        lines = [f"curve synthesis: {len(self.candidates)} candidates, {self.refined} refined of "
                 f"{self.retrieved} retrieved, {self.seconds:.1f} s" + (" (interrupted)" if self.interrupted else "")]
        for i, c in enumerate(self.candidates, 1):
            lines.append(f"{i}. {c.topology.label} [{c.topology.key}]: "
                         f"chamfer {100 * c.chamfer:.2f} %, ordered {100 * c.ordered:.2f} %, "
                         f"size {c.size_ratio:.2f} diagonals, link ratio {c.link_length_ratio:.1f}, "
                         f"min transmission {c.min_transmission_angle:.0f} deg"
                         + (", full turn" if c.full_turn else "") + ("" if c.verified else "  NOT VERIFIED"))
        if not self.candidates:
            lines.append(self.reason)
        return "\n".join(lines)

    def plot(self, ax=None, top: int = 3):
        """Target and the best candidates' paths (see :func:`mechsyn.plot.curves.plot_curve_result`)."""
        from mechsyn.plot.curves import plot_curve_result

        return plot_curve_result(self, ax=ax, top=top)


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
              bounds: Bounds) -> list[_Seed]:
    w = resample(target.points, 64, closed=target.closed)
    d = fourier_descriptor(w)
    rows: set[int] = set()
    for n in range(4, max_links + 1, 2):   # each link count its own share of the retrieval
        tree, sub = db.tree(n)
        if tree is None:
            continue
        kk = min(k, len(sub))
        for q in (d, swap_direction(d)):
            _, ii = tree.query(q.astype(np.float32), k=kk)
            rows.update(sub[np.atleast_1d(ii)].tolist())
    rows_a = np.array(sorted(rows), int)
    if crank:
        rows_a = rows_a[db.closed[rows_a]]
    if not target.closed:
        rows_a = rows_a[~db.closed[rows_a]]
    seeds: list[_Seed] = []
    by_topo: dict[int, list[int]] = {}
    for r in rows_a.tolist():
        by_topo.setdefault(int(db.topology[r]), []).append(r)
    for ti, rs in by_topo.items():
        seeds += _topology_seeds(db, db.topologies[ti], rs, w, bounds.unit, bounds)
    seeds.sort(key=lambda s: (s.rank, s.row))
    return seeds


def _topology_seeds(db: CurveDatabase, topo: CurveTopology, rs: list[int], w: np.ndarray, diag: float,
                    bounds: Bounds) -> list[_Seed]:
    """The retrieved rows of one topology aligned onto the target ``w`` and mapped into
    its frame, each with its alignment error and bound violations."""
    rs_a = np.array(rs)
    offs = np.array([input_offsets(*db.ranges[r], bool(db.closed[r])) for r in rs])
    X = np.array([db.designs[r] for r in rs])
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
        params = _transform_design(np.asarray(db.designs[r], float), complex(al.c[j]), complex(al.t[j]), mir)
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


def _refine(seed: _Seed, target: TargetCurve, bounds: Bounds, max_nfev: int) -> CurveCandidate | None:
    """The seed refined in the working frame (None when it does not assemble)."""
    prob = FitProblem(seed.topo, target, seed.closed, seed.start, seed.stop, bounds)
    x0 = seed.params
    prob.fun(x0)
    if prob.last_bad[0]:  # does not assemble over the range after the mapping
        return None
    try:
        sol = least_squares(prob.fun, x0, jac=prob.jac, method="trf", x_scale=1.0,
                            max_nfev=max_nfev, xtol=1e-10, ftol=1e-10)
        x = sol.x
    except np.linalg.LinAlgError:  # a singular step: keep the retrieved design
        x = x0
    return _candidate(seed.topo, x, seed.start, seed.stop, seed.closed, target, prob.nfev, bounds)


def _candidate(topo: CurveTopology, x: np.ndarray, start: float, stop: float, closed: bool,
               target: TargetCurve, nfev: int, bounds: Bounds) -> CurveCandidate | None:
    """The design's candidate in the working frame, with its errors and quality over
    :data:`N_FINAL` input samples (lengths in ``bounds.unit``); None when it is not
    assembled."""
    off = input_offsets(start, stop, closed, N_FINAL)
    res = simulate_batch(full_plan(topo), x[None], off, transmission=True)
    if not res.assembled.all() or res.branch_jump[0]:
        return None
    path = res.paths[TRACER][0]
    ch, od = curve_errors(path, target, closed, bounds.unit)
    size = float(path_sizes(res.paths, bounds.centre)[0])
    return CurveCandidate(topo, x, start, stop if not closed else start + 360.0, ch, od,
                          float(res.min_transmission_angle[0]), float(link_ratio(x, link_pairs(topo))[0]),
                          path, nfev=nfev, size=size, size_ratio=size / bounds.unit)


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


@dataclass(frozen=True)
class _Frame:
    """The working frame, a similarity ``w = R((z - c) / r)`` of the target's plane: ``c``
    and ``r`` the centroid and RMS radius of the target (equally spaced in arc length),
    ``R`` the rotation to its principal axes (the long axis along x, its third moment
    positive) followed, when the curve then runs clockwise (closed by its chord if open;
    without enclosed area, when its y skew is negative), by the mirror in the x axis.
    Each part is computed from the curve itself, so a translated, scaled, rotated or
    mirrored target has the same working coordinates (rounded to ``1e-9``: the same
    numbers, not merely close ones) and the search the same course. A linkage mapped by a
    similarity traces the curve so mapped, on the same assembly branch; a mirrored one
    with its input reversed. With a ground region (an axis-parallel box) rotation and
    mirror are left out."""

    centre: complex
    scale: float
    turn: complex          # e^{i phi}: working x axis in target coordinates
    mirror: bool

    @classmethod
    def of(cls, target: TargetCurve, rotate: bool = True) -> _Frame:
        w = resample(target.points, 256, closed=target.closed)
        c = complex(w.mean())
        r = float(np.sqrt(np.mean(np.abs(w - c) ** 2)))
        turn, mirror = 1.0 + 0j, False
        if rotate:
            u = (w - c) / r
            m2 = np.sum(u ** 2)
            turn = complex(np.exp(0.5j * np.angle(m2))) if abs(m2) > 1e-6 * len(u) else 1.0 + 0j
            if np.sum(((u / turn).real) ** 3) < 0:
                turn = -turn
            v = (resample(target.points, 256, closed=True) - c) / (r * turn)   # an open curve: closed by its chord
            area = 0.5 * np.sum(v.real * np.roll(v.imag, -1) - np.roll(v.real, -1) * v.imag)
            # clockwise: mirror; no area to speak of (a figure eight): the side the y skew points to
            mirror = bool(area < 0) if abs(area) > 1e-3 else bool(np.sum(v.imag ** 3) < 0)
        return cls(c, r, turn, mirror)

    def inward_points(self, P: np.ndarray) -> np.ndarray:
        w = (P[..., 0] + 1j * P[..., 1] - self.centre) / (self.scale * self.turn)
        w = np.conj(w) if self.mirror else w
        return np.round(np.stack([w.real, w.imag], axis=-1), 9)

    def outward_points(self, W: np.ndarray) -> np.ndarray:
        w = W[..., 0] + 1j * W[..., 1]
        z = self.centre + self.scale * self.turn * (np.conj(w) if self.mirror else w)
        return np.stack([z.real, z.imag], axis=-1)

    def inward(self, target: TargetCurve) -> TargetCurve:
        return TargetCurve(self.inward_points(target.points), target.closed, target.source)

    def bounds(self, user: TargetCurve, max_size, max_link_ratio, min_transmission, region) -> Bounds:
        """The design bounds in working coordinates (disc about the target's bounding-box
        centre, radius in its diagonals)."""
        P = user.points
        centre = self.inward_points(0.5 * (P.min(axis=0) + P.max(axis=0)))
        unit = user.diagonal / self.scale
        box = None
        if region is not None:
            lo, hi = self.inward_points(np.array(region[:2])), self.inward_points(np.array(region[2:]))
            box = (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))
        return Bounds((float(centre[0]), float(centre[1])), unit, None if max_size is None else max_size * unit,
                       max_link_ratio, float(min_transmission), box)

    def outward(self, c: CurveCandidate) -> CurveCandidate:
        """The candidate in the target's coordinates (errors and ratios unchanged; a
        mirrored design runs its input the other way)."""
        import dataclasses

        x = self.outward_points(c.params.reshape(-1, 2)).reshape(-1)
        path = self.outward_points(c.path)
        start, stop = c.start, c.stop
        if self.mirror:
            start, stop = -stop, -start
            n = len(path)
            path = path[(-np.arange(n)) % n] if c.full_turn else path[::-1]
        ref = float(c.topology.plan.reference_inputs(x)[0])
        return dataclasses.replace(c, params=x, path=path, start=start, stop=stop, size=c.size * self.scale,
                                   reference_input=ref)


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
    callback: Callable[[dict], None] | None = None,
    max_nfev: int = 60,
    tolerance: float = DEFAULT_TOLERANCE,
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
        Seconds for retrieval and refinement (no refinement starts that the longest so
        far says would overrun it).
    top : int
        Candidates returned (see ``prefer``; the first three of distinct topologies).
    n_refine, retrieve : int
        Designs refined, and nearest descriptors retrieved per query.
    crank : bool
        Only fully rotating inputs (without it a full turn is preferred, not required).
    ground_region : (x0, y0, x1, y1), optional
        Box (target coordinates) the frame pivots must stay in.
    max_size : float or None
        Every joint, frame pivots included, and the tracer stay over the whole motion
        within this many target diagonals of the centre of the target's bounding box
        (default 1.5: the linkage fits in a disc three diagonals across); None lifts it.
    max_link_ratio : float or None
        Largest ratio of the longest to the shortest link length (default 10); None lifts it.
    min_transmission : float
        Smallest transmission angle (degrees, of every RRR dyad over the input range;
        default 30); 0 lifts it.
    prefer : {"simple", "accuracy"}
        ``"simple"``: among candidates within ``tolerance`` fewer links first, then a full
        turn, then the larger transmission angle (in 5° steps), then the error; the
        others after them by error. ``"accuracy"``: by error alone.
    database : CurveDatabase or directory, optional
        Default: the local one (built on first use).
    tolerance : float
        Chamfer error (in target diagonals, default 0.5 %) within which a candidate counts
        as tracing the curve; the search ends early once three topologies (or ``top``,
        if fewer) have a candidate within it.
    callback : callable, optional
        ``callback(state)`` with a :class:`~mechsyn.synthesis.problem.Progress` (stage,
        best chamfer error so far, ``nfev``; it reads as the database build's dict too).

    Returns
    -------
    CurveSynthesisResult
        Candidates best first, within the bounds, re-simulated by ``simulate``; with none,
        ``feasible`` false and ``nearest_miss`` the design closest to the bounds (named in
        ``reason``). Ctrl-C returns the best so far (``interrupted``).

    Notes
    -----
    The search runs in a working frame fixed by the curve itself (:class:`_Frame`), so a
    similar target gives the same design transformed; only the size bound, measured on
    the bounding box as drawn, changes with a rotation other than by quarter turns.

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.synthesis.curves.database import build_database, load_database
    >>> import tempfile
    >>> d = tempfile.mkdtemp()
    >>> _ = build_database(d, max_links=4, per_topology=400)
    >>> t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    >>> ellipse = np.c_[3 * np.cos(t), np.sin(t)]
    >>> res = synthesize_curve(ellipse, max_links=4, top=1, n_refine=3, database=load_database(d))
    >>> c = res.candidates[0]
    >>> c.topology.label, c.verified, c.chamfer < 0.02, c.size_ratio <= 1.5
    ('four-bar', True, True, True)
    """
    t0 = time.perf_counter()
    user = _checked_target(target, max_links, time_limit, top, max_link_ratio, crank)
    _checked_bounds(max_size, min_transmission, prefer, tolerance)
    if database is None or isinstance(database, (str, os.PathLike)):
        database = load_database(database, max_links=max_links, callback=callback)
    o = dict(max_links=max_links, time_limit=time_limit, top=top, n_refine=n_refine, retrieve=retrieve, crank=crank,
             ground_region=ground_region, max_size=max_size, max_link_ratio=max_link_ratio,
             min_transmission=min_transmission, prefer=prefer, max_nfev=max_nfev, tolerance=tolerance)
    return _search(user, database, t0, o, callback)


def _search(user: TargetCurve, database: CurveDatabase, t0: float, o: dict[str, Any],
            callback: Callable[[dict], None] | None) -> CurveSynthesisResult:
    """The search of :func:`synthesize_curve` (options ``o`` checked): sparse targets
    smoothed, the working frame, retrieval, refinement in order, ranking, mapping back."""
    notes: list[str] = []
    if len(user.points) < SPARSE_POINTS:
        notes.append(f"{len(user.points)} points read as samples of a smooth curve (a "
                     f"{'periodic ' if user.closed else ''}spline through them), not a polygon")
        user = smooth_samples(user)
    frame = _Frame.of(user, rotate=o["ground_region"] is None)
    work = frame.inward(user)
    bounds = frame.bounds(user, o["max_size"], o["max_link_ratio"], o["min_transmission"], o["ground_region"])

    def report(stage, done, total, best, nfev):
        if callback is not None:
            callback(Progress(done=done, total=total, best_error=best, message=stage, nfev=nfev))

    report("retrieve", 0, 1, float("nan"), 0)
    seeds = _retrieve(database, work, o["retrieve"], o["max_links"], o["crank"], bounds)
    report("retrieve", 1, 1, seeds[0].score if seeds else float("nan"), 0)
    picked = _diverse(seeds, o["n_refine"], simple=o["prefer"] == "simple")
    if o["prefer"] == "simple":  # four-bars first (one within tolerance is never missed), then by rank
        picked.sort(key=lambda s: (s.topo.n_links != 4, s.rank, s.row))
    run = _Refinement(work, bounds, o["max_nfev"], report, notes=notes)
    run.all(picked, t0 + o["time_limit"], min(o["top"], 3), o["tolerance"])
    if not picked:
        run.notes.append("no database design matched the options (crank, links, open/closed)")
    out = _ranked(run.cands, o["top"], o["tolerance"], o["prefer"], run.notes)
    miss = _nearest_miss(run.misses, bounds, run.notes) if not out else None
    report("done", 1, 1, out[0].chamfer if out else float("nan"), run.nfev)
    res = _result(user, [frame.outward(c) for c in out], time.perf_counter() - t0, len(seeds), run.done,
                  run.nfev, run.interrupted, run.notes)
    res.bounds = {"max_size": o["max_size"], "max_link_ratio": o["max_link_ratio"], "tolerance": o["tolerance"],
                  "min_transmission_angle": o["min_transmission"], "prefer": o["prefer"]}
    res.nearest_miss = frame.outward(miss) if miss is not None else None
    if miss is not None:
        res.reason = _miss_reason(miss, bounds)
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


def _checked_bounds(max_size: float | None, min_transmission: float, prefer: str, tolerance: float) -> None:
    if max_size is not None and not max_size >= 0.5:
        raise MechsynInputError(f"{max_size}: the disc must hold the target itself (at least 0.5 diagonals)",
                                field="max_size", hint="give a value of at least 0.5, or lift it")
    if not 0 <= min_transmission < 90:
        raise MechsynInputError("must be an angle in degrees in [0, 90)", field="min_transmission")
    if prefer not in ("simple", "accuracy"):
        raise MechsynInputError(f"{prefer!r}: choose simple or accuracy", field="prefer")
    if not 0 < tolerance < 1:
        raise MechsynInputError("must be a fraction of the diagonal in (0, 1)", field="tolerance")


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


@dataclass
class _Refinement:
    """The refinement stage: candidates kept (within the bounds), misses (outside),
    refinements done, evaluations, notes."""

    target: TargetCurve
    bounds: Bounds
    max_nfev: int
    report: Callable[..., None]
    cands: list[CurveCandidate] = field(default_factory=list)
    misses: list[CurveCandidate] = field(default_factory=list)
    done: int = 0
    nfev: int = 0
    interrupted: bool = False
    notes: list[str] = field(default_factory=list)

    def all(self, picked: list[_Seed], deadline: float, need: int, tolerance: float) -> None:
        """Refine ``picked`` in order until the deadline (a refinement starts only if the
        longest so far still fits), ``need`` topologies with a candidate within
        ``tolerance``, or Ctrl-C."""
        best = float("inf")
        longest = 0.0
        try:
            for i, s in enumerate(picked):
                now = time.perf_counter()
                if now + longest > deadline:
                    self.notes.append(f"time limit: {i} of {len(picked)} refinements done")
                    break
                if len({c.topology.key for c in self.cands if c.chamfer <= tolerance}) >= need:
                    self.notes.append(f"{need} topologies within {100 * tolerance:g} % after {i} refinements")
                    break
                c = _refine(s, self.target, self.bounds, self.max_nfev)
                longest = max(longest, time.perf_counter() - now)
                self.done += 1
                if c is not None:
                    self.nfev += c.nfev
                    if self.keeps(c):
                        self.cands.append(c)
                        best = min(best, c.chamfer)
                    else:
                        self.misses.append(c)
                self.report("refine", i + 1, len(picked), best, self.nfev)
        except KeyboardInterrupt:
            self.interrupted = True
            self.notes.append("interrupted: the best found so far")

    def keeps(self, c: CurveCandidate) -> bool:
        """Within the size, link-ratio and transmission bounds and the ground region."""
        exc = self.bounds.excess(np.array([c.size]), np.array([c.link_length_ratio]),
                                 np.array([c.min_transmission_angle]))
        return bool(exc.max() <= 1e-9) and (self.bounds.region is None or _in_region(c, self.bounds.region))


def _rank_key(c: CurveCandidate, tolerance: float, prefer: str) -> tuple:
    if prefer == "accuracy" or c.chamfer > tolerance:
        return (1 if prefer != "accuracy" else 0, 0, 0, 0, c.chamfer)
    return (0, c.topology.n_links, not c.full_turn, -np.floor(c.min_transmission_angle / 5.0), c.chamfer)


def _ranked(cands: list[CurveCandidate], top: int, tolerance: float, prefer: str,
            notes: list[str]) -> list[CurveCandidate]:
    """Best first (see :func:`synthesize_curve`'s ``prefer``), distinct, each verified by
    ``simulate``; with ``prefer="simple"`` the first three of distinct topologies where
    that many are within the tolerance; at most ``top``."""
    cands.sort(key=lambda c: _rank_key(c, tolerance, prefer))
    order = cands
    if prefer == "simple":
        first: list[CurveCandidate] = []
        for c in cands:
            if c.chamfer <= tolerance and len(first) < 3 and all(o.topology.key != c.topology.key for o in first):
                first.append(c)
        order = first + [c for c in cands if all(c is not o for o in first)]
    out: list[CurveCandidate] = []
    for c in order:
        if any(o.topology.key == c.topology.key and abs(o.chamfer - c.chamfer) < 1e-5
               and abs(o.link_length_ratio - c.link_length_ratio) < 1e-3 * c.link_length_ratio for o in out):
            continue
        _verify(c)
        if c.verified:
            out.append(c)
        else:
            notes.append(f"{c.topology.key}: dropped, {c.verification}")
        if len(out) >= top:
            break
    return out


def _nearest_miss(misses: list[CurveCandidate], bounds: Bounds, notes: list[str]) -> CurveCandidate | None:
    """The design found closest to the bounds (then the most accurate), verified."""
    def key(c):
        e = bounds.excess(np.array([c.size]), np.array([c.link_length_ratio]), np.array([c.min_transmission_angle]))
        return (float(e.sum()), c.chamfer)

    for c in sorted(misses, key=key):
        _verify(c)
        if c.verified:
            return c
    notes.append("no design assembled over its range was found")
    return None


def _miss_reason(c: CurveCandidate, bounds: Bounds) -> str:
    """``no candidate within the bounds; nearest miss: ...`` with the options that lift them."""
    out = []
    if bounds.radius is not None and c.size > bounds.radius * (1 + 1e-9):
        out.append(f"size {c.size_ratio:.2f} diagonals > {bounds.radius / bounds.unit:g} (--max-size)")
    if bounds.link_ratio is not None and c.link_length_ratio > bounds.link_ratio * (1 + 1e-9):
        out.append(f"link ratio {c.link_length_ratio:.1f} > {bounds.link_ratio:g} (--max-link-ratio)")
    if c.min_transmission_angle < bounds.transmission:
        out.append(f"transmission angle {c.min_transmission_angle:.1f}° < {bounds.transmission:g}° "
                   "(--min-transmission-angle)")
    if not out:
        out.append("frame pivots outside the ground region (--ground-region)")
    return (f"no candidate within the bounds; nearest miss: {c.topology.label}, chamfer {100 * c.chamfer:.2f} %, "
            + ", ".join(out) + "; lift the bound named to accept it")


def _result(target: TargetCurve, out: list[CurveCandidate], seconds: float, retrieved: int, refined: int,
            nfev: int, interrupted: bool, notes: list[str]) -> CurveSynthesisResult:
    """The result, its common synthesis fields from the best candidate."""
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
