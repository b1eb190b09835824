"""The classic formulas next to the rank method, and remedies re-checked by it.

:func:`compare_with_formulas` puts each formula's answer (Chebyshev, Malyshev,
Somov-Malyshev per contour, Ozol, paper 003's per-contour counts and drives) next to the
rank method's with one line on why they differ; :func:`check_remedy` re-checks a class-change
remedy (paper 003) with the rank method; :func:`rank_to_markdown` writes both as Markdown.

References
----------
.. [1] "Rational structural synthesis of schemes of crank-slider mechanisms of gripping
   devices" (in Ukrainian, with an English abstract) ("paper 002"; see docs/references.md).
.. [2] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
.. [3] G. Gogu, "Mobility of mechanisms: a critical review", *Mechanism and Machine
   Theory*, 40(9), 1068-1097, 2005.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from mechsyn.model.mechanism import Joint, Mechanism
from mechsyn.results import counted
from mechsyn.structure.rank import RankAnalysis, analyze_rank, rank_summary_lines
from mechsyn.structure.screws import _E, InsufficientGeometry, _pad3, _unit

__all__ = ["Comparison", "compare_with_formulas", "RemedyCheck", "check_remedy", "rank_to_markdown"]


# --------------------------------------------------------------------------- formulas side by side
@dataclass(frozen=True)
class Comparison:
    """One formula's answer next to the rank method's, with why they differ."""

    quantity: str
    formula: str
    formula_value: float | int | None
    rank_value: float | int | None
    agree: bool
    why: str

    def to_dict(self) -> dict[str, Any]:
        return {"quantity": self.quantity, "formula": self.formula, "formula_value": self.formula_value,
                "rank_value": self.rank_value, "agree": self.agree, "why": self.why}


def _q_reasons(ra: RankAnalysis) -> str:
    parts = []
    for c in ra.contours:
        if c.redundant:
            parts.append(f"contour {c.index}: {c.redundant}, {c.reason.split(':')[0]}")
    return "; ".join(parts)


def _idle_words(ra: RankAnalysis) -> str:
    return ", ".join(f"{i.link or '?'} ({' '.join(i.joints)})" for i in ra.idle_mobilities)


def compare_with_formulas(fa: Any, ra: RankAnalysis) -> list[Comparison]:
    """Each formula of ``fa`` (:class:`~mechsyn.structure.analysis.StructuralAnalysis`)
    next to the rank answer ``ra``, with one line on why they differ.

    Identities used: Malyshev's ``W = F - 6K`` and Chebyshev's ``W = F - 3K`` equal
    ``m - q`` (instantaneous mobility minus redundant constraints), and Ozol's
    ``q = W + λK - f`` is the rank's ``q`` exactly when ``W`` is the instantaneous mobility.
    """
    out: list[Comparison] = []
    m, u, q = ra.mobility, ra.useful_mobility, ra.redundant_constraints
    idle = len(ra.idle_mobilities)
    planar = ra.motion == "planar"
    reasons = _q_reasons(ra)
    idle_txt = f"; it includes {counted(idle, 'idle mobility', 'idle mobilities')}: {_idle_words(ra)}" if idle else ""
    main = (("chebyshev", "Chebyshev W = 3n - 2p5 - p4 (planar)") if planar
            else ("malyshev", "Malyshev W = 6n - Σ i·p_i (spatial)"))
    f = fa.formulas.get(main[0])
    if f is not None and f.value is not None:
        w = f.value
        if w == m:
            why = "agree: no constraint is redundant" + idle_txt
        else:
            why = (f"W = m - q = {m} - {q} = {m - q}: the formula counts every constraint as independent, "
                   f"{q} are redundant ({reasons})" + idle_txt)
        out.append(Comparison("mobility", main[1], w, m, w == m, why))
    if not planar:
        f = fa.formulas.get("somov_malyshev")
        if f is not None and f.value is not None:
            w = f.value
            s_idle = fa.idle_mobilities
            if w == m:
                why = "agree: the per-contour S_Σ + G_Σ matches the redundant constraints the rank method finds"
            elif w == u:
                why = (f"W equals the useful mobility {u}: S_Σ = {fa.structural_redundancy} nets "
                       f"{counted(s_idle, 'idle mobility', 'idle mobilities')} against redundant constraints; the "
                       f"rank method counts {counted(q, 'redundant constraint')} and "
                       f"{counted(idle, 'idle mobility', 'idle mobilities')} apart (m = {m} = {u} + {idle})")
            else:
                bad = []
                for rc, fc in zip(ra.contours, fa.contours):
                    fq = max(fc.S, 0) + fc.T
                    if fq != rc.redundant:
                        bad.append(f"contour {rc.index}: S + T = {fq:g}, rank {rc.redundant}"
                                   + (f" ({rc.reason.split(':')[0]})" if rc.reason else ""))
                why = ("the per-contour counts assume generic geometry (each contour's pairs independent): "
                       + ("; ".join(bad) if bad else f"S_Σ + G_Σ = {fa.structural_redundancy + fa.constructive_redundancy:g}"
                          f" vs rank q = {q}") + idle_txt)
            out.append(Comparison("mobility", "Somov-Malyshev W = 6n - Σ i·p_i + S_Σ + G_Σ (003, spatial)", w, m, w == m, why))
    f = fa.formulas.get("ozol_redundant")
    if f is not None and f.value is not None:
        w_used = fa.declared_mobility if fa.declared_mobility is not None else fa.mobility
        why = ("agree" if f.value == q else
               f"Ozol's q = W + {3 if planar else 6}K - f used W = {w_used:g}; with the rank's instantaneous "
               f"mobility m = {m} (idle included) it gives q = {q}")
        if f.value == q and q:
            why = f"agree: {reasons}"
        out.append(Comparison("redundant constraints", f"Ozol q = W + {3 if planar else 6}K - f (002, {ra.motion})", f.value, q, f.value == q, why))
    if fa.contours and len(fa.contours) == len(ra.contours) and not planar:
        for fc, rc in zip(fa.contours, ra.contours):
            sj = max(fc.S, 0) + fc.T
            agree = sj == rc.redundant
            why = "agree" if agree else (
                f"the rank method finds {rc.redundant}" + (f": {rc.reason}" if rc.reason else "")
                + (f" (formula: S = {fc.S}, T = {fc.T:g})"))
            if not agree and rc.redundant < sj:
                why += ("; S_j counts freedoms, not their directions: with this geometry the pairs' "
                        "freedoms absorb the constraints it counts as redundant")
            if agree and rc.redundant:
                why = f"agree: {', '.join(rc.directions)}"
            out.append(Comparison(f"redundant constraints, contour {fc.index}", "003: max(S_j, 0) + T_j",
                                  sj, rc.redundant, agree, why))
    f_idle = fa.idle_mobilities
    if not planar:
        out.append(Comparison(
            "idle mobilities", "003: Σ max(-S_j, 0)", f_idle, idle, f_idle == idle,
            "agree" + (f": {_idle_words(ra)}" if idle else "") if f_idle == idle else
            (f"the rank method finds {idle}: {_idle_words(ra) or 'none'}"
             + ("; the per-contour count misses idle motions that a contour's redundant constraints mask"
                if idle > f_idle else "; the per-contour count assumes a generic geometry"))))
    h = fa.degrees_of_mobility
    why = "agree" if h == ra.drives_needed else (
        f"drives needed = useful mobility = {ra.drives_needed} (rank); the rule H = n - Σ A_j is "
        "topological and misses special geometry" + (f" (exclusive-link reading: {fa.degrees_of_mobility_exclusive})"
                                                      if fa.degrees_of_mobility_exclusive != h else ""))
    out.append(Comparison("drives", "003: H = n - Σ A_j", h, ra.drives_needed, h == ra.drives_needed, why))
    return out


# --------------------------------------------------------------------------- remedies re-checked
@dataclass(frozen=True)
class RemedyCheck:
    """The rank method's verdict on a remedy variant."""

    accepted: bool
    reason: str
    rank: RankAnalysis | None
    geometry: dict[str, dict[str, list[float]]]

    def to_dict(self) -> dict[str, Any]:
        r = self.rank
        return {"accepted": self.accepted, "reason": self.reason, "geometry": self.geometry,
                "rank": None if r is None else {
                    "mobility": r.mobility, "useful_mobility": r.useful_mobility,
                    "idle_mobilities": [i.to_dict() for i in r.idle_mobilities],
                    "redundant_constraints": r.redundant_constraints,
                    "redundant_by_contour": r.redundant_by_contour,
                    "redundant_directions": r.redundant_directions}}


def _candidate_dirs(mech: Mechanism, j: Joint) -> list[np.ndarray]:
    p = _pad3(j.point)
    out: list[np.ndarray] = []
    for other in mech.joints:
        if other is j or other.point is None or not set(other.links) & set(j.links):
            continue
        d = _pad3(other.point) - p
        if np.linalg.norm(d) > 1e-9:
            out.append(_unit(d))
    out += [e for e in _E]
    uniq: list[np.ndarray] = []
    for d in out:
        if all(abs(abs(d @ e) - 1) > 1e-9 for e in uniq):
            uniq.append(d)
    return uniq


def _variant_geometry(original: Mechanism, variant: Mechanism) -> list[tuple[Mechanism, dict[str, dict[str, list[float]]]]]:
    """Geometric realisations of a remedy variant: changed pairs at the same point with the
    same axis; directions a new pair needs (sphere-with-pin's blocked rotation, a line
    contact's line) tried among the directions to the neighbouring joints and x, y, z."""
    import itertools

    old = {j.id: j for j in original.joints}
    choices: list[list[tuple[Joint, dict[str, list[float]]]]] = []
    for j in variant.joints:
        o = old[j.id]
        if o.type == j.type and o.pair_class == j.pair_class:
            choices.append([(o, {})])
            continue
        base = replace(j, point=o.point, axis=o.axis, axis2=o.axis2, normal=o.normal, pitch=None, ratio=None)
        opts: list[tuple[Joint, dict[str, list[float]]]] = []
        if j.type == "S_pin" and (o.axis is None or o.axis2 is None):
            if o.point is not None:
                for d in _candidate_dirs(original, o):
                    opts.append((replace(base, normal=d, axis=None, axis2=None), {"normal": [float(x) for x in d]}))
        elif j.type == "line_contact" and base.axis is None and base.normal is not None:
            n = _unit(_pad3(base.normal))
            for e in _E:
                ln = np.cross(n, e)
                if np.linalg.norm(ln) > 1e-6:
                    ln = _unit(ln)
                    opts.append((replace(base, axis=ln), {"axis": [float(x) for x in ln]}))
        elif j.type == "U" and o.axis is not None and o.axis2 is None:
            for d in _candidate_dirs(original, o):
                a2 = np.cross(_pad3(o.axis), d)
                if np.linalg.norm(a2) > 1e-6:
                    opts.append((replace(base, axis2=_unit(a2)), {"axis2": [float(x) for x in _unit(a2)]}))
        else:
            g = {}
            if base.point is not None:
                g["point"] = [float(x) for x in base.point]
            if base.axis is not None and j.type not in ("S",):
                g["axis"] = [float(x) for x in base.axis]
            opts.append((base, g))
        choices.append(opts or [(base, {})])
    combos = itertools.islice(itertools.product(*choices), 64)
    out = []
    for combo in combos:
        joints = tuple(c[0] for c in combo)
        geo = {j.id: c[1] for j, c in zip(joints, combo) if c[1] and (old[j.id].type != j.type)}
        out.append((replace(variant, joints=joints), geo))
    return out


def check_remedy(original: Mechanism, variant: Mechanism, base: RankAnalysis, metric_left: float = 0.0,
                 tol: float | None = None) -> RemedyCheck:
    """Re-check a remedy variant (paper 003's class changes) with the rank method.

    Accepted when, for some realisation of the new pairs at the old pairs' points and
    axes, the useful mobility is unchanged, no idle mobility is left and no more
    redundant constraints remain than the metric constraints the formulas admit
    (``metric_left``, which class changes cannot remove).
    """
    old = {j.id: j for j in original.joints}
    moved = [j for j in variant.joints if j.actuated and j.type != old[j.id].type
             and not (old[j.id].type == "P" and j.type == "C")]
    if moved:
        return RemedyCheck(False, "rejected by the rank method: " + "; ".join(
            f"the driven pair {j.id} would become {j.type} ({j.freedom} freedoms): a drive sets one coordinate"
            for j in moved), None, {})
    best: tuple[tuple[int, int, int], RankAnalysis, dict[str, Any]] | None = None
    for mech, geo in _variant_geometry(original, variant):
        try:
            r = analyze_rank(mech, tol=tol if tol is not None else base.tolerance, check_singular=False)
        except InsufficientGeometry as exc:
            return RemedyCheck(True, f"not checked: {exc.message}", None, {})
        lost_drive = int(base.actuation_determined is True and r.actuation_determined is False)
        score = (abs(r.useful_mobility - base.useful_mobility) + lost_drive, len(r.idle_mobilities),
                 max(0, r.redundant_constraints - int(round(metric_left))))
        if best is None or score < best[0]:
            best = (score, r, geo)
        if score == (0, 0, 0):
            break
    assert best is not None
    score, r, geo = best
    if score == (0, 0, 0):
        extra = (f"; {r.redundant_constraints} metric constraint(s) remain, as the formulas say"
                 if r.redundant_constraints else "")
        return RemedyCheck(True, f"confirmed: useful mobility {r.useful_mobility}, no idle mobility, "
                                 f"no redundant constraint{extra}", r, geo)
    why = []
    if score[0] and r.useful_mobility != base.useful_mobility:
        why.append(f"changes the useful mobility from {base.useful_mobility} to {r.useful_mobility}")
    elif score[0]:
        why.append(f"the drives at {', '.join(r.actuated)} no longer determine the motion")
    if score[1]:
        why.append(f"leaves {counted(len(r.idle_mobilities), 'idle mobility', 'idle mobilities')}: {_idle_words(r)}")
    if score[2]:
        locs = "; ".join(f"contour {c.index}: {', '.join(c.directions)}" for c in r.contours if c.redundant)
        why.append(f"leaves {r.redundant_constraints} redundant constraint(s) ({locs})")
    return RemedyCheck(False, "rejected by the rank method: " + "; ".join(why), r, geo)


def rank_to_markdown(ra: RankAnalysis, comparisons: list[Comparison] | None = None, level: int = 2) -> str:
    h = "#" * level
    out = [f"{h} Rank method (screw theory)", ""] + [f"- {x}" for x in rank_summary_lines(ra)]
    if any(c.redundant for c in ra.contours):
        out += ["", "| contour | joints | redundant | directions | why |", "|---|---|---|---|---|"]
        for c in ra.contours:
            out.append(f"| {c.index} | {' '.join(c.joints)} | {c.redundant} | {'; '.join(c.directions)} | {c.reason} |")
    if comparisons:
        out += ["", f"{h}# Formulas and rank side by side", "", "| quantity | formula | formula | rank | why |",
                "|---|---|---|---|---|"]
        for c in comparisons:
            fv = "n/a" if c.formula_value is None else f"{c.formula_value:g}"
            out.append(f"| {c.quantity} | {c.formula} | {fv} | {c.rank_value} | {c.why} |")
    if ra.notes:
        out += [""] + [f"- note: {n}" for n in ra.notes]
    return "\n".join(out) + "\n"
