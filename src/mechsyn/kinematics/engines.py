"""The kinematics engines behind :func:`mechsyn.kinematics.analysis.simulate`.

An engine computes a sweep (:class:`~mechsyn.kinematics.sweep.Sweep`: poses, rates and
events over the input values) or says it cannot (returns None), and ``simulate`` takes the
first engine of :data:`PLANAR_ENGINES` that answers. Each is an object with a ``name``
and a ``sweep`` method (the :class:`Engine` protocol); a new engine (the spatial one, a
compiled one) is written against that protocol and put in the list at the place where it
should be tried.

The planar engines, in the order they are tried:

1. ``regular pass`` (:func:`mechsyn.kinematics.regular.sweep_through_folds`): a driver-R +
   RRR chain whose groups stay clear of change points, in one array pass of complex
   arithmetic through its folds (dead points found on each group's discriminant array);
   declines when a group's discriminant has a local minimum under 0.05 (a change or
   branch point may be near) and for ``change_points="switch"``.
2. ``tracked chain`` (:func:`mechsyn.kinematics.tracking.solve_tracked_rates`): the same
   chains through folds, change and branch points, every group's assembly mode tracked on
   its discriminant, rates in closed form.
3. ``tracked groups`` (:func:`mechsyn.kinematics.tracking.solve_tracked`): any mechanism of
   drivers and dyads (RRR, RRP, PRR, RPR, RPP, PRP), rates by batched linear solves.
4. ``newton`` (:func:`mechsyn.kinematics.solve.sweep`): Newton continuation of the
   constraint equations, for every mechanism (gears, cams, belts, closed loops that do
   not split into dyads).

A ``kind: spatial`` mechanism goes to :data:`SPATIAL_ENGINE` (``spatial``,
:mod:`mechsyn.kinematics.spatial`): the pairs' constraint equations on the link poses,
predictor-corrector continuation from the drawn assembly.

The tracked engines and Newton sweep outwards from the drawn configuration when the
drawn input lies inside the sweep (:func:`outward`), so every sweep that contains the
drawn input passes through the drawn configuration.

Examples
--------
>>> import mechsyn as ms
>>> [e.name for e in PLANAR_ENGINES]
['regular pass', 'tracked chain', 'tracked groups', 'newton']
>>> ms.examples.load("crank_rocker").simulate(A=(0, 360, 10)).engine
'regular pass'
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.progress import ProgressCallback, counter, report, shifted
from mechsyn.kinematics.chain import solve_all
from mechsyn.kinematics.groups import Plan
from mechsyn.kinematics.regular import Folded, sweep_through_folds
from mechsyn.kinematics.solve import sweep as newton_sweep
from mechsyn.kinematics.spatial import SpatialEngine
from mechsyn.kinematics.sweep import Event, Sweep, by_row
from mechsyn.kinematics.system import PlanarSystem
from mechsyn.kinematics.topology import CACHE
from mechsyn.kinematics.tracking import solve_tracked, solve_tracked_rates

__all__ = ["Engine", "ENGINES", "engine_named", "PLANAR_ENGINES", "SPATIAL_ENGINE", "RegularPass", "TrackedChain", "TrackedGroups", "Newton",
           "first_sweep", "drawn_row", "outward", "merged", "merged_events"]


class Engine(Protocol):
    """A kinematics engine: ``sweep`` gives the :class:`Sweep` of ``system`` over the inputs
    (N, k) (radians for R, lengths for P) at the input ``speeds`` (k,), or None when the
    engine cannot answer for this mechanism or these options (the next one is tried).

    ``plan``: the mechanism's decomposition into drivers and Assur groups
    (:class:`mechsyn.kinematics.groups.Plan`), None when it has none or Newton is asked
    for; ``change_points``: ``"keep"`` or ``"switch"``; ``progress``: ``progress(state)``
    (:class:`mechsyn.progress.Progress`: rows done of the sweep's), or None.
    """

    name: str

    def sweep(self, system: Any, plan: Any, inputs: np.ndarray, speeds: np.ndarray, *,
              change_points: str = "keep", progress: ProgressCallback | None = None) -> Sweep | None:
        ...


class RegularPass:
    """A driver-R + RRR chain without change points, in one pass through its folds (see
    the module doc)."""

    name = "regular pass"

    def sweep(self, system: PlanarSystem, plan: Plan | None, inputs: np.ndarray, speeds: np.ndarray, *,
              change_points: str = "keep", progress: ProgressCallback | None = None) -> Sweep | None:
        if plan is None or change_points != "keep":
            return None
        k = drawn_row(system, inputs)
        res = sweep_through_folds(system, plan, inputs, speeds, k)
        if res is None:
            return None
        N = inputs.shape[0]
        report(progress, N, N, "sweep")
        if isinstance(res, Folded):  # through folds: the tracked sweeps' singular rows and events
            return _folded_sweep(system, inputs, speeds, k, res, self.name)
        q, qd, qdd, links = res
        ok = np.empty(N, bool)  # (empty + fill: np.ones is a Python function around these two calls)
        ok.fill(True)
        return Sweep(system, inputs, speeds, q, qd, qdd, ok, [], links=links, engine=self.name)

    def declined(self, system: PlanarSystem, plan: Plan | None, change_points: str) -> str:
        """Why :meth:`sweep` gave None, in one line."""
        if plan is None:
            return _NO_PLAN
        if change_points != "keep":
            return "it follows the drawn branch only (change_points='keep')"
        if not plan.closed_form_rates or system.n != 3 * len(system.links):
            return "it takes chains of R drivers and RRR dyads only"
        return "a group's discriminant has a minimum near zero (a change or branch point may be near)"


class TrackedGroups:
    """Any mechanism of drivers and dyads, rates by batched linear solves."""

    name = "tracked groups"

    def sweep(self, system: PlanarSystem, plan: Plan | None, inputs: np.ndarray, speeds: np.ndarray, *,
              change_points: str = "keep", progress: ProgressCallback | None = None) -> Sweep | None:
        if not self.takes(plan):
            return None
        switch = change_points == "switch"
        advance = counter(progress, len(inputs), "sweep")

        def run(parts: list) -> list[Sweep]:
            res = self.solved(system, plan, parts, speeds, switch)
            return [_tracked_sweep(system, U, speeds, r, self.name, advance) for U, r in zip(parts, res)]

        return outward(system, inputs, run)

    def takes(self, plan: Plan | None) -> bool:
        """Whether the engine answers for a mechanism of this plan."""
        return plan is not None

    def solved(self, system: PlanarSystem, plan: Plan, parts: list, speeds: np.ndarray, switch: bool) -> list:
        """``(q, qd, qdd, singular rows, group events)`` of each of ``parts`` (input rows)."""
        out = []
        for U in parts:
            tracked = solve_tracked(system, plan, U, switch=switch)
            out.append((*solve_all(system, plan, U, speeds, tracked=tracked), tracked.singular, tracked.events))
        return out

    def declined(self, system: PlanarSystem, plan: Plan | None, change_points: str) -> str:
        """Why :meth:`sweep` gave None, in one line."""
        return _NO_PLAN


class TrackedChain(TrackedGroups):
    """A driver-R + RRR chain through folds and change points, rates in closed form: the
    tracked groups' sweep with the chain's solver."""

    name = "tracked chain"

    def takes(self, plan: Plan | None) -> bool:
        return plan is not None and plan.closed_form_rates

    def solved(self, system: PlanarSystem, plan: Plan, parts: list, speeds: np.ndarray, switch: bool) -> list:
        return solve_tracked_rates(system, plan, parts, speeds, switch=switch)

    def declined(self, system: PlanarSystem, plan: Plan | None, change_points: str) -> str:
        return _NO_PLAN if plan is None else "it takes chains of R drivers and RRR dyads only"


#: Why an engine of drivers and Assur groups declines a mechanism without such a plan.
_NO_PLAN = "the mechanism does not split into drivers and dyads"


class Newton:
    """Newton continuation of the constraint equations: every planar mechanism."""

    name = "newton"

    def sweep(self, system: PlanarSystem, plan: Plan | None, inputs: np.ndarray, speeds: np.ndarray, *,
              change_points: str = "keep", progress: ProgressCallback | None = None) -> Sweep | None:
        if change_points != "keep":
            return None

        def run(parts: list) -> list[Sweep]:
            out, before = [], 0
            for U in parts:  # rows counted over the parts: the sweep's rows done of all
                out.append(newton_sweep(system, U, speeds, progress=shifted(progress, before, len(inputs))))
                before += len(U)
            return out

        return outward(system, inputs, run)

    def declined(self, system: PlanarSystem, plan: Plan | None, change_points: str) -> str:
        """Why :meth:`sweep` gave None, in one line."""
        return "it follows the drawn branch only (change_points='keep')"


#: The planar engines in the order :func:`first_sweep` tries them.
PLANAR_ENGINES: tuple[Engine, ...] = (RegularPass(), TrackedChain(), TrackedGroups(), Newton())

#: The engine of ``kind: spatial`` mechanisms (:class:`mechsyn.kinematics.spatial.SpatialEngine`).
#: It takes the mechanism itself (``simulate(mech, inputs, ...)``: no planar system, no
#: Assur plan) and answers with a :class:`~mechsyn.kinematics.spatial_result.SpatialSimulation`,
#: a :class:`~mechsyn.kinematics.simulation.Motion` like the planar engines' ``Simulation``.
#: It also takes planar mechanisms of R and P pairs, as their 3-D equivalent (an oracle
#: for the planar engines).
SPATIAL_ENGINE = SpatialEngine()

#: Every engine, each by a unique ``name``: ``simulate(..., method=NAME)`` runs that one
#: alone (:func:`engine_named`). The planar engines sweep a compiled planar system
#: (``sweep(system, plan, inputs, speeds, ...)`` behind the planar front end of
#: :func:`mechsyn.kinematics.analysis.simulate`); an engine with a ``simulate`` method
#: takes the mechanism whole (the spatial one).
ENGINES: tuple[Any, ...] = PLANAR_ENGINES + (SPATIAL_ENGINE,)


def engine_named(name: str) -> Any:
    """The engine of :data:`ENGINES` called ``name`` (spaces, ``-`` and ``_`` alike, any
    case), or a :class:`~mechsyn.errors.MechsynInputError` listing the names.

    Examples
    --------
    >>> engine_named("regular_pass").name, engine_named("Spatial").name
    ('regular pass', 'spatial')
    """
    key = name.replace("_", " ").replace("-", " ").lower()
    for e in ENGINES:
        if e.name == key:
            return e
    raise MechsynInputError(f"unknown method {name!r}", field="method",
                            hint="auto, assur or an engine: " + ", ".join(e.name for e in ENGINES))


def first_sweep(engines: tuple[Engine, ...], system: Any, plan: Any, inputs: np.ndarray, speeds: np.ndarray, *,
                change_points: str = "keep", progress: ProgressCallback | None = None) -> Sweep | None:
    """The sweep of the first of ``engines`` that answers (None when none does)."""
    for engine in engines:
        sw = engine.sweep(system, plan, inputs, speeds, change_points=change_points, progress=progress)
        if sw is not None:
            return sw
    return None


def _tracked_sweep(S: PlanarSystem, U: np.ndarray, sp: np.ndarray, res: tuple, engine: str,
                   advance: Callable[[int], None]) -> Sweep:
    """A tracked engine's arrays, singular rows and group events as a Sweep."""
    q, qd, qdd, singular, tr_events = res
    qd[singular] = np.nan  # a group folded flat: rates not defined here
    qdd[singular] = np.nan
    ok = np.all(np.isfinite(q), axis=1)
    advance(U.shape[0])
    return Sweep(S, U, sp, q, qd, qdd, ok, _tracked_events(tr_events, bool(ok[0]), U[0]), engine=engine)


def _folded_sweep(S: PlanarSystem, U: np.ndarray, sp: np.ndarray, k: int | None, res: Folded, engine: str) -> Sweep:
    """The Sweep of the regular pass through folds: the tracked sweeps' singular rows
    (rates not defined) and events, forwards and backwards from row ``k`` when the drawn
    input values lie inside the sweep."""
    (_, ev), *back = res.parts
    q, qd, qdd = res.q, res.qd, res.qdd
    rates_ok, ok = res.rates_ok, res.assembled  # the singular rows already blanked
    sw = Sweep(S, U, sp, q, qd, qdd, ok, [], engine=engine, rates_ok=rates_ok, nan_rows=True, links=res.links,
               singular_rows=None if res.singular else [])
    if not back:
        sw.events = _tracked_events(ev, bool(ok[0]), U[0])
    else:
        sw.events = merged_events(k, _tracked_events(back[0][1], bool(ok[k - 1]), U[k - 1]),
                                  _tracked_events(ev, bool(ok[k]), U[k]))
    return sw


def _tracked_events(tracked_events: list[Event], first_assembled: bool, first_input: np.ndarray) -> list[Event]:
    """Events of the closed-form sweep: dead points, reassembly and change / branch points
    found and refined on the groups' discriminants (:func:`solve_tracked`); the sweep's
    first row assembled or not, and its input values."""
    out, seen = [], set()
    for e in tracked_events:  # a gap of an upstream group is one reassembly of the mechanism
        if e.kind == "reassembled":
            if e.index in seen:
                continue
            seen.add(e.index)
        out.append(e)
    if not first_assembled and not any(e.index == 0 and e.kind == "dead point" for e in out):
        out.insert(0, Event(0, "not assembled", "the mechanism cannot be assembled at the first input",
                            first_input.tolist()))
    return out


#: The rows :func:`drawn_row` found are kept in the kinematics' one cache
#: (:data:`~mechsyn.kinematics.topology.CACHE`) by the inputs' shape: ``(the inputs'
#: bytes, {the drivers' types and drawn values: row})``. A drag or a design loop simulates
#: the same grid again and again (equal bytes: the same rows), each geometry with its own
#: drawn values.
_DRAWN_BYTES = 1 << 16  # sweeps of at most 64 KiB of inputs
_DRAWN_ROWS = 64  # answers kept per sweep (drawn values)


def drawn_row(S: PlanarSystem, U: np.ndarray) -> int | None:
    """Row ``k`` (0 < k < N) such that the drawn input values lie on the sweep's segment from
    row ``k - 1`` to row ``k`` (R inputs up to whole turns), else None.

    The row of the same inputs (byte for byte, up to 64 KiB of them) with the same drawn
    values is remembered.

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.kinematics.analysis import compile_plan
    >>> from mechsyn.io import load_mechanism
    >>> S = compile_plan(load_mechanism("examples/kinematics/crank_rocker.yaml"), inputs=("A",)).system
    >>> u0 = float(np.degrees(S.drivers[0].assembled))
    >>> U = np.radians(np.arange(0.0, 361.0))[:, None]
    >>> k = drawn_row(S, U)
    >>> bool(np.degrees(U[k - 1, 0]) < u0 <= np.degrees(U[k, 0])), drawn_row(S, U[:1]) is None
    (True, True)
    """
    if U.shape[0] < 2:
        return None
    if U.nbytes > _DRAWN_BYTES:  # a long sweep: its own cost dwarfs the search, not kept
        return _segment_row(S.drivers, U)
    drawn = tuple([(d.type, float(d.assembled)) for d in S.drivers])
    key = ("input grid", U.shape, U.dtype.str)
    data = U.tobytes()
    hit = CACHE.get(key)
    if hit is None or hit[0] != data:
        hit = (data, {})
        CACHE.put(key, hit)
    rows = hit[1]
    k = rows.get(drawn, rows)
    if k is rows:
        if len(rows) >= _DRAWN_ROWS:
            rows.clear()
        k = rows[drawn] = _segment_row(S.drivers, U)
    return k


def _segment_row(drivers: Any, U: np.ndarray) -> int | None:
    """:func:`drawn_row`, searched: the first segment from row ``k - 1`` to row ``k`` that
    holds the drivers' drawn values (R: the turn nearest each row, or the one before or
    after), with ``p = (v - a) . d``: ``0 < p <= d . d``; with several inputs the drawn
    values must also lie on the segment's line (one input: always)."""
    u0 = np.array([d.assembled for d in drivers], float)
    isR = np.array([d.type == "R" for d in drivers])
    a = U[:-1]
    d = U[1:] - a
    dd = _dot(d, d)
    v = a - u0  # the drawn values in the turn of each row
    v /= 2 * np.pi
    np.rint(v, out=v)
    v *= 2 * np.pi
    v += u0
    if not isR.all():
        v[:, ~isR] = u0[~isR]
    for shift in (0.0, 2 * np.pi, -2 * np.pi) if isR.any() else (0.0,):
        w = v + shift * isR if shift else v
        p = _dot(w - a, d)
        hit = (p > 0.0) & (p <= dd)
        if U.shape[1] > 1:
            with np.errstate(invalid="ignore", divide="ignore"):
                off = np.abs(a + (p / dd)[:, None] * d - w).max(axis=1)
            hit &= off <= 1e-12 * (1 + np.abs(w).max(axis=1))
        k = int(hit.argmax())  # the first row hit (or 0 when none is)
        if hit[k]:
            return k + 1
    return None


def _dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """The row-wise dot products of ``x`` and ``y`` (N, k)."""
    return (x * y).sum(axis=1) if x.shape[1] > 1 else (x * y).reshape(-1)


def outward(S: PlanarSystem, U: np.ndarray, run: Callable[[list], list[Sweep]]) -> Sweep:
    """The sweep computed outwards from the drawn configuration when the drawn input lies
    inside it (rows after it forwards, rows before it backwards), so every sweep that
    contains the drawn input passes through the drawn configuration; else one run.
    ``run(parts)`` sweeps each of ``parts`` from the drawn configuration."""
    k = drawn_row(S, U)
    if k is None:
        return run([U])[0]
    return merged(S, U, k, *run([U[k:], U[:k][::-1].copy()]))


def merged(S: PlanarSystem, U: np.ndarray, k: int, fwd: Sweep, bwd: Sweep) -> Sweep:
    """The sweep of the inputs ``U`` from its sweeps forwards from row ``k`` (``fwd``) and
    backwards from row ``k - 1`` (``bwd``), events re-indexed and worded for the way back."""
    events = merged_events(k, bwd.events, fwd.events)

    def cat(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.concatenate([a[::-1], b])

    return Sweep(S, U, fwd.speeds, cat(bwd.q, fwd.q), cat(bwd.qd, fwd.qd), cat(bwd.qdd, fwd.qdd),
                 cat(bwd.assembled, fwd.assembled), events, engine=fwd.engine)


#: What a dead point and a reassembly found going back from the drawn configuration say.
_BACK_MESSAGES = {
    "dead point": "a limit of the working range: the Jacobian is singular (dead point)",
    "reassembled": "assembles again (going back from the drawn configuration) after a gap, in the "
                   "assembly mode nearest the drawn one"}


def merged_events(k: int, bwd: list[Event], fwd: list[Event]) -> list[Event]:
    """The events of the sweeps backwards from row ``k - 1`` and forwards from row ``k``
    as events of the whole sweep (re-indexed, worded for the way back, by row)."""
    events = []
    for e in bwd:
        at_row = e.kind == "singular" and not e.crossed
        events.append(e.with_(index=(k - 1 - e.index) if at_row else max(0, k - e.index), before_sweep=None,
                              message=_BACK_MESSAGES.get(e.kind, e.message)))
    for e in fwd:
        events.append(e.with_(index=e.index + k, before_sweep=None))
    events.sort(key=by_row)
    return events
