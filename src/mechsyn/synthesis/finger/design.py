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
   range (see :func:`force_objective`); its best few distinct designs are then checked in both
   modes (VLL range found again, forces at ``l_min`` and ``l_max``) and one replaces the
   stage-1 design only if its peak reaction is not higher and its criterion lower.
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
   links" (in Russian), ITMO University, St. Petersburg; journal, volume and year are
   not in the project's copy ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, fields, replace
from typing import Any, Callable

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.interrupt import BestSoFar
from mechsyn.synthesis.finger.cases import FingerCase
from mechsyn.synthesis.problem import SynthesisResult
from mechsyn.synthesis.finger.vll import copy_mechanism, locked_model, points_in_region, region_excess, vll_ends

__all__ = ["apply_design", "Evaluation", "evaluate_locked", "evaluate_drawn", "stage1_objective",
           "stage1_population", "force_objective", "force_population", "redraw", "underactuated_paths",
           "vll_range", "mode_forces", "design_finger", "FingerDesign", "VariantResult", "INFEASIBLE"]

INFEASIBLE = 1e6
Objective = Callable[[np.ndarray], float]


# --------------------------------------------------------------------------- designs
def apply_design(case: FingerCase, x: np.ndarray, combo: tuple[str, ...] | None = None) -> dict:
    """The mechanism dict of design ``x``: joint / point coordinates set; each VLL of the
    combination ``combo`` (default: every VLL) drawn at its minimum constructible length
    along its direction, the other VLL (plain rigid links in this variant) at their drawn
    length."""
    d = copy_mechanism(case.mech_dict)
    joints = {j["id"]: j for j in d["joints"]}
    angles: dict[str, float] = {}
    for v, val in zip(case.variables, np.asarray(x, float)):
        if v.kind == "joint":
            joints[v.target]["point"][v.coord] = float(val)
        elif v.kind == "point":
            d["points"][v.target]["at"][v.coord] = float(val)
        else:
            angles[v.target] = float(val)
    for jid, j in joints.items():
        if not j.get("vll"):
            continue
        _cyl, L, K, _pis = vll_ends(d, jid, case.source)
        pk = np.asarray(joints[K]["point"], float)
        u = np.asarray(j["point"], float) - pk
        ang = np.radians(angles[jid]) if jid in angles else np.arctan2(u[1], u[0])
        length = case.vll_limits(jid)[0] if combo is None or jid in combo else float(np.linalg.norm(u))
        u = np.array([np.cos(ang), np.sin(ang)])
        p = pk + length * u
        j["point"] = p.tolist()
        j["axis"] = u.tolist()
        joints[L]["point"] = p.tolist()
    return d


@dataclass
class Evaluation:
    """A design in the fully actuated (VLL locked) mode over the dense crank grid."""

    feasible: bool
    reason: str
    error_rms: float = np.inf          # deg, over targets and links
    error_max: float = np.inf
    achieved: dict[str, np.ndarray] = field(default_factory=dict)
    paths: dict[str, np.ndarray] = field(default_factory=dict)
    inputs: np.ndarray | None = None
    q: np.ndarray | None = None
    system: Any = None
    violation: float = 0.0


def evaluate_locked(case: FingerCase, x: np.ndarray, combo: tuple[str, ...] = ()) -> Evaluation:
    """Closed-form positions of design ``x`` (VLL locked at their minimum) over
    ``case.sweep_inputs``, with the target errors and the region check."""
    try:
        d = apply_design(case, x, combo or None)
    except (MechsynInputError, ValueError, KeyError) as exc:
        return Evaluation(False, f"cannot build: {exc}", violation=1e3)
    return evaluate_drawn(case, d)


def evaluate_drawn(case: FingerCase, d: dict) -> Evaluation:
    """Closed-form positions of the mechanism dict ``d`` with every VLL locked at its
    drawn length (the locked model), over the crank grid ``case.sweep_inputs``."""
    from mechsyn.io import mechanism_from_dict
    from mechsyn.kinematics import dyads
    from mechsyn.kinematics.system import build_system

    vlls = [j["id"] for j in case.mech_dict["joints"] if j.get("vll")]
    try:
        d = locked_model(d, vlls, case.source)
        mech = mechanism_from_dict(d, source=case.source)
        S = build_system(mech)
        plan = dyads.decompose(S)
    except (MechsynInputError, ValueError, KeyError, ZeroDivisionError) as exc:
        return Evaluation(False, f"cannot build: {exc}", violation=1e3)
    if plan is None:
        return Evaluation(False, "the locked model does not decompose into dyads", violation=1e3)
    k = [dr.joint for dr in S.drivers].index(case.input)
    grid = case.sweep_inputs
    U = np.tile([dr.assembled for dr in S.drivers], (len(grid), 1)).astype(float)
    U[:, k] = S.drivers[k].assembled + np.radians(grid)
    with np.errstate(invalid="ignore", divide="ignore"):
        q, _ = dyads.solve_positions(S, plan, U)
    ok = np.all(np.isfinite(q), axis=1)
    if not ok.all():
        return Evaluation(False, f"not assembled at {int((~ok).sum())} of {len(grid)} crank angles "
                                 "(dead point between the targets)", violation=float((~ok).sum()))
    ev = Evaluation(True, "", inputs=grid, q=q, system=S)
    idx = np.searchsorted(grid, case.target_inputs)
    errs = []
    for link, tgt in case.target_angles.items():
        i = S.index(link)
        rot = np.degrees(q[:, 3 * i + 2] - S.q0[3 * i + 2])
        ev.achieved[link] = rot[idx]
        errs.append(rot[idx] - tgt)
    e = np.concatenate(errs)
    ev.error_rms = float(np.sqrt(np.mean(e ** 2)))
    ev.error_max = float(np.max(np.abs(e)))
    from mechsyn.kinematics.analysis import resolve_points

    viol = 0.0
    for name, (link, at) in resolve_points(mech, case.points).items():
        P = S.point(q, S.index(link), S.to_local(link, at))
        ev.paths[name] = P
        viol += region_excess(P, case.region)
    if viol > 0:
        ev.feasible, ev.reason, ev.violation = False, "a path leaves the working region", viol
    return ev


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
    from mechsyn.synthesis.finger.population import locked_population

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
    from mechsyn.synthesis.finger.population import locked_population

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


# --------------------------------------------------------------------------- VLL range
def redraw(case: FingerCase, design: dict, lengths: dict[str, float]) -> dict | None:
    """The mechanism dict redrawn at the same crank angle with the VLL lengths
    ``lengths``: the underactuated mode (VLL free, length prescribed) solved by the
    kinematics engine's Newton continuation from the drawn lengths; None when it cannot
    be assembled. Joint points, named points, centres of mass and P axes follow their
    links; a VLL's ``limits`` are kept."""
    from mechsyn.io import mechanism_from_dict
    from mechsyn.kinematics.solve import assemble
    from mechsyn.kinematics.system import _rot, build_system

    d = copy_mechanism(design)
    for j in d["joints"]:  # the engine refuses lengths outside limits: widen them for the solve
        if j["id"] in lengths:
            lim = j.get("limits") or [lengths[j["id"]]] * 2
            j["limits"] = [min(lim[0], lengths[j["id"]]), max(lim[1], lengths[j["id"]])]
    mech = mechanism_from_dict(d, source=case.source)
    free = tuple(lengths)
    try:
        S = build_system(mech, vll={jid: "free" for jid in free}, prescribed=free)
        u = np.array([lengths[dr.joint] if dr.joint in lengths else dr.assembled for dr in S.drivers])
        q = assemble(S, u)[None]  # Newton continuation from the drawn lengths (crank held)
    except MechsynInputError:
        return None
    ground = mech.ground

    def moved(link: str, p: Any) -> list[float]:
        if link == ground:
            return [float(v) for v in p]
        return S.point(q, S.index(link), S.to_local(link, np.asarray(p, float)))[0].tolist()

    def turned(link: str, u: Any) -> list[float]:
        if link == ground:
            return [float(v) for v in u]
        i = S.index(link)
        c, sn = _rot(q[:, 3 * i + 2] - S.q0[3 * i + 2])
        u = np.asarray(u, float)
        return [float(c[0] * u[0] - sn[0] * u[1]), float(sn[0] * u[0] + c[0] * u[1])]

    for j in d["joints"]:
        link = j["links"][1] if j["links"][1] != ground else j["links"][0]
        if j.get("axis") is not None:
            j["axis"] = turned(j["links"][0], j["axis"])
        j["point"] = moved(link, j["point"])
    for p in (d.get("points") or {}).values():
        p["at"] = moved(p["link"], p["at"])
    for k, e in enumerate(d["links"]):
        name = e if isinstance(e, str) else e["name"]
        if name == ground:
            continue
        if isinstance(e, str):
            e = d["links"][k] = {"name": e}
        if e.get("com") is None:  # the file's default (its joints' mean, drawn), fixed on the link
            e["com"] = np.mean([j["point"] for j in design["joints"] if name in j["links"]], axis=0).tolist()
        e["com"] = moved(name, e["com"])
    for ld in d.get("loads") or []:
        if ld.get("at") is not None:
            ld["at"] = moved(ld["link"], ld["at"])
    for j in d["joints"]:
        if j["id"] in lengths:
            j["limits"] = next(x for x in design["joints"] if x["id"] == j["id"]).get("limits")
    return d


def underactuated_paths(case: FingerCase, design: dict, jid: str, lengths: np.ndarray
                        ) -> dict[str, np.ndarray]:
    """Output paths over the crank grid in the underactuated mode with VLL ``jid`` held
    at each length: point -> (n_lengths, n_inputs, 2), NaN where not assembled. Each
    length: :func:`redraw`, then the closed-form locked model."""
    n = len(case.sweep_inputs)
    out = {p: np.full((len(lengths), n, 2), np.nan) for p in case.points}
    for r, length in enumerate(lengths):
        d = redraw(case, design, {jid: float(length)})
        if d is None:
            continue
        ev = evaluate_drawn(case, d)
        for p, P in ev.paths.items():
            out[p][r] = P
    return out


def vll_range(case: FingerCase, design: dict, jid: str, rel_tol: float = 1e-3
              ) -> tuple[float, float, dict[str, np.ndarray], np.ndarray]:
    """(l_min, l_max, paths, lengths): the largest ``l_max`` in the VLL's limits such that
    every output path (whole crank range) for the lengths ``l_min ... l_max`` is
    assembled and inside the region (grid of ``case.vll_steps`` lengths, then bisection
    to ``rel_tol`` of the limits' range)."""
    lo, hi = case.vll_limits(jid)
    lengths = np.linspace(lo, hi, case.vll_steps + 1)
    paths = underactuated_paths(case, design, jid, lengths)

    def inside(P: dict[str, np.ndarray], r: int) -> bool:
        return all(points_in_region(arr[r], case.region).all() for arr in P.values())

    ok = np.array([inside(paths, r) for r in range(len(lengths))])
    if not ok[0]:
        return lo, lo, paths, lengths
    last = int(np.argmin(ok)) - 1 if not ok.all() else len(ok) - 1
    l_max = float(lengths[last])
    if last < len(lengths) - 1:  # bisection between the last good and the first bad length
        a, b = l_max, float(lengths[last + 1])
        while b - a > rel_tol * (hi - lo):
            m = 0.5 * (a + b)
            if inside(underactuated_paths(case, design, jid, np.array([m])), 0):
                a = m
            else:
                b = m
        l_max = a
    return lo, l_max, paths, lengths


# --------------------------------------------------------------------------- forces
def _peaks(S: Any, q: np.ndarray, case: FingerCase, skip: tuple[str, ...] = ()) -> tuple[float, float, str]:
    from mechsyn.kinematics.forces import kinetostatics

    R = kinetostatics(S, q, None, None, gravity=(0.0, -case.gravity))
    peak, where = 0.0, ""
    for j, F in R.force.items():
        if j in skip:
            continue
        m = float(np.nanmax(np.linalg.norm(F, axis=1)))
        if m > peak:
            peak, where = m, j
    return peak, float(np.nanmax(np.abs(R.effort[case.input]))), where


def mode_forces(case: FingerCase, design: dict, combo: tuple[str, ...],
                ranges: dict[str, tuple[float, float]]) -> dict[str, Any]:
    """Peak joint reaction and peak balancing moment at the input over the crank range,
    statically (gravity along -y, the file's loads), in the fully actuated mode (VLL
    locked at ``l_min``) and in the underactuated mode (VLL free, held at each end of
    its range by a spring or stop: the axial force at the piston's pivot is reported as
    ``vll_force_peak``; the spring force differs from it by at most the piston's weight). Closed-form locked models (``kinetostatics`` on the merged
    cylinder-piston link); the tests compare them with the engine's Newton solution of
    the full file in both modes."""
    out: dict[str, Any] = {"fully_actuated": _static_summary(case, design, ())}
    if not out["fully_actuated"]["assembled"]:
        raise MechsynInputError("the design does not assemble over the crank range", source=case.source)
    worst = {"peak_reaction": out["fully_actuated"]["peak_reaction"],
             "peak_input_moment": out["fully_actuated"]["peak_input_moment"]}
    out["underactuated"] = []
    for jid in combo:
        lo, hi = ranges[jid]
        for length in sorted({lo, hi}):
            d = design if length == lo else redraw(case, design, {jid: length})
            s = _static_summary(case, d, (jid,)) if d is not None else {"assembled": False}
            if not s["assembled"]:
                raise MechsynInputError(f"the design does not assemble with {jid} = {length:g}",
                                        source=case.source)
            s["vll_length"] = length
            out["underactuated"].append(s)
            for k in worst:
                worst[k] = max(worst[k], s[k])
    out.update(worst)
    modes = [out["fully_actuated"]] + out["underactuated"]
    out["peak_joint"] = max(modes, key=lambda m: m["peak_reaction"])["peak_joint"]
    out["criterion"] = out["peak_reaction"] + case.weight_moment * out["peak_input_moment"]
    return out


def _static_summary(case: FingerCase, d: dict, vlls: tuple[str, ...]) -> dict[str, Any]:
    from mechsyn.kinematics.forces import kinetostatics

    ev = evaluate_drawn(case, d)
    if ev.q is None:
        return {"assembled": False}
    S, q = ev.system, ev.q
    R = kinetostatics(S, q, None, None, gravity=(0.0, -case.gravity))
    mags = {j: float(np.max(np.linalg.norm(F, axis=1))) for j, F in R.force.items()}
    j = max(mags, key=mags.get)
    out = {"peak_reaction": mags[j], "peak_joint": j,
           "peak_input_moment": float(np.max(np.abs(R.effort[case.input]))), "assembled": True}
    for jid in vlls:  # axial force in the merged VLL link, at the piston's pivot L
        _cyl, L, K, _pis = vll_ends(case.mech_dict, jid, case.source)
        jl, jk = S.mech.joint(L), S.mech.joint(K)
        cyl = jl.links[0]
        pl = S.point(q, S.index(cyl), S.to_local(cyl, jl.point))
        pk = S.point(q, S.index(cyl), S.to_local(cyl, jk.point))
        u = (pl - pk) / np.linalg.norm(pl - pk, axis=1)[:, None]
        out["vll_force_peak"] = float(np.max(np.abs(np.sum(R.force[L] * u, axis=1))))
    return out


def force_objective(case: FingerCase, combo: tuple[str, ...], tol: float,
                    hold: dict[str, float] | None = None, bound: float = np.inf) -> Objective:
    """Stage 2: ``peak |R| + w peak |M_in|`` (static, closed form), feasible only when the
    target error stays within ``tol`` (deg RMS) and the paths in the region.

    The locked mode is evaluated first; its value is a lower bound of the both-mode
    criterion, so only a design whose locked value is below ``bound`` (the stage-1
    design's both-mode criterion) is also evaluated in the underactuated mode with the
    VLL held at ``hold`` (stage 1's ``l_max``): there it must assemble over the crank
    range and keep the paths in the region (the force stage keeps the adaptive range),
    and its value becomes the both-mode criterion.
    """
    def f(x: np.ndarray) -> float:
        ev = evaluate_locked(case, x, combo)
        if not ev.feasible:
            return INFEASIBLE + ev.violation
        if ev.error_rms > tol:
            return INFEASIBLE + (ev.error_rms - tol)
        try:
            pr, pm, _ = _peaks(ev.system, ev.q, case)
        except Exception:  # noqa: BLE001 - a singular design is infeasible, never rewarded
            return INFEASIBLE + 1.0
        if not (np.isfinite(pr) and np.isfinite(pm)):
            return INFEASIBLE + 1.0
        value = pr + case.weight_moment * pm
        if not hold or value >= bound:
            return value
        d = redraw(case, apply_design(case, x, combo), hold)
        ev2 = evaluate_drawn(case, d) if d is not None else None
        if ev2 is None or not ev2.feasible:
            return INFEASIBLE + (ev2.violation if ev2 is not None else 1.0)
        try:
            pr2, pm2, _ = _peaks(ev2.system, ev2.q, case)
        except Exception:  # noqa: BLE001
            return INFEASIBLE + 1.0
        return max(pr, pr2) + case.weight_moment * max(pm, pm2)
    return f




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
    progress: Callable[[str], None] | None
    notes: list[str] = field(default_factory=list)
    stopped: bool = False
    state: dict = field(default_factory=lambda: {"interrupted": False})

    def say(self, msg: str) -> None:
        if self.progress:
            self.progress(msg)

    def reporter(self, label: str, stage: str, maxiter: int, what: str) -> Callable[[int, float], None] | None:
        """``report(generation, best)`` for :func:`_de`: a progress line, ``what`` formats the best."""
        if not self.progress:
            return None

        def report(g: int, best: float) -> None:
            self.say(f"VLL {label}: {stage}, generation {g}/{maxiter}, best " + (
                what.format(best) if best < INFEASIBLE else "design still infeasible"))
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
                  progress: Callable[[str], None] | None = None, checkpoint: Any = None,
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
        ``progress(message)`` with the stage and the best value so far.
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
    from mechsyn.checkpoint import open_search_checkpoint

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


def _design(case: FingerCase, seed: int, time_limit: float, progress: Callable[[str], None] | None,
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
    d1 = apply_design(case, x1, combo)
    run.say("VLL ranges and forces of the stage-1 design")
    ranges1 = {j: vll_range(case, d1, j)[:2] for j in combo}
    forces1 = mode_forces(case, d1, combo, ranges1)
    pop, n2 = _force_stage(run, combo, x1, f1, max(case.tolerance_deg, ev1.error_rms), ranges1, forces1)
    chosen, ranges, forces_, improved = _pick(run, combo, x1, pop, ranges1, forces1)
    return _variant(case, combo, x1, ev1, chosen, ranges, forces1, forces_, improved, n1 + n2)


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


def _variant(case: FingerCase, combo: tuple[str, ...], x1: np.ndarray, ev1: Evaluation, chosen: np.ndarray,
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
