"""Paper 000's adaptive finger in both modes: the VLL range (step 9) and the static forces
(steps 10-12) of :mod:`mechsyn.synthesis.finger.design`.

:func:`redraw` moves a design to other VLL lengths at the same crank angle (the
underactuated mode, solved by the kinematics engine's Newton continuation);
:func:`vll_range` finds the largest length whose output paths stay assembled and in the
working region; :func:`mode_forces` reports the peak joint reaction and balancing moment
in the fully actuated and underactuated modes; :func:`force_objective` is the force
stage's objective.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.io import mechanism_from_dict
from mechsyn.kinetostatics.reactions import kinetostatics
from mechsyn.kinematics.solve import assemble
from mechsyn.kinematics.plane import cos_sin
from mechsyn.kinematics.system import build_system
from mechsyn.synthesis.finger.cases import FingerCase
from mechsyn.synthesis.finger.evaluation import INFEASIBLE, Objective, apply_design, evaluate_drawn, evaluate_locked
from mechsyn.synthesis.finger.vll import copy_mechanism, points_in_region, vll_ends

__all__ = ["redraw", "underactuated_paths", "vll_range", "mode_forces", "force_objective"]


# --------------------------------------------------------------------------- VLL range
def redraw(case: FingerCase, design: dict, lengths: dict[str, float]) -> dict | None:
    """The mechanism dict redrawn at the same crank angle with the VLL lengths
    ``lengths``: the underactuated mode (VLL free, length prescribed) solved by the
    kinematics engine's Newton continuation from the drawn lengths; None when it cannot
    be assembled. Joint points, named points, centres of mass and P axes follow their
    links; a VLL's ``limits`` are kept."""
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
        c, sn = cos_sin(q[:, 3 * i + 2] - S.q0[3 * i + 2])
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
