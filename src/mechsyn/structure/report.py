"""The structural report: one library call for what ``mechsyn analyze`` shows.

:func:`analyze` runs the classic formulas (:func:`~mechsyn.structure.analysis.analyze_structure`),
the rank method where the file gives the joints' geometry
(:func:`~mechsyn.structure.rank.analyze_rank`), compares them, analyses each state and, on
request, lists pair-class remedies re-checked by the rank method. The
:class:`StructureReport` it returns gives the same dict as ``mechsyn analyze --json``
(``to_dict()``) and the same Markdown as ``--markdown`` (``to_markdown()``, shown by Jupyter).

References
----------
.. [1] "Rational structural synthesis of schemes of crank-slider mechanisms of gripping
   devices" (in Ukrainian, with an English abstract) ("paper 002"; see docs/references.md).
.. [2] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from mechsyn._result import Result
from mechsyn.errors import MechsynInputError
from mechsyn.model.mechanism import Mechanism
from mechsyn.progress import ProgressCallback
from mechsyn.results import to_jsonable
from mechsyn.structure.analysis import StructuralAnalysis, analyze_structure
from mechsyn.structure.drives import DriveCheck, drive_check_of_formulas
from mechsyn.structure.remedies import Remedy, find_remedies

__all__ = ["StructureReport", "analyze", "to_markdown", "verdict", "formula_sections", "explain_negative",
           "drive_check", "why_it_differs", "formula_summary", "formula_reasons", "FORMULA_COUNTS"]

FORMULA_TITLES = {
    "chebyshev": "Chebyshev (planar)",
    "grubler": "Grübler (N with the frame)",
    "malyshev": "Malyshev",
    "somov_malyshev": "Somov-Malyshev, per-contour S_Σ and G_Σ (003)",
    "gokhman_contours": "Gokhman: independent contours",
    "scheme_check": "Scheme check (002)",
    "ozol_redundant": "Ozol: redundant constraints (002)",
    "redundant_from_mobility": "Somov-Malyshev solved for S",
}


#: paper 003's per-contour counts are the spatial reading (each contour against 6 freedoms)
CONTOUR_READING = {"planar": ", spatial reading", "spatial": ""}

#: what each reading of a formula counts
READINGS = {
    "planar": "planar reading: 3 freedoms per free link, 3 closure equations per contour",
    "spatial": "spatial reading: 6 freedoms per free link, 6 closure equations per contour",
    "topology": "counts of links, pairs and contours only",
}

#: the section of the spatial readings of a planar file: its title and what it says
SPATIAL_OF_PLANAR = (
    "Spatial reading of this planar mechanism (paper 003)",
    "Counted as if each link had 6 freedoms: the out-of-plane conditions a planar loop repeats "
    "count as redundant, 3 per contour. They say what a 3-D build must hold (parallel axes), "
    "not how the planar mechanism moves: that is the verdict above.")


def formula_sections(a: StructuralAnalysis) -> tuple[list[str], list[str]]:
    """The formula keys of the file's own kind (with the topology counts), and the spatial
    readings of a planar file (empty for a spatial one). A planar formula that does not apply
    to a spatial file (value None) is left out of both."""
    if a.kind == "planar":
        own = [k for k, f in a.formulas.items() if getattr(f, "reading", "") != "spatial"]
        return own, [k for k in a.formulas if k not in own]
    return [k for k, f in a.formulas.items() if f.value is not None or getattr(f, "reading", "") == "spatial"], []


def _used_mobility(a: StructuralAnalysis) -> Any:
    """The W Ozol's q and S-from-W use: the file's declared mobility, else the formulas' own."""
    if a.declared_mobility is not None:
        return a.declared_mobility
    return a.formulas["chebyshev" if a.kind == "planar" else "somov_malyshev"].value


def explain_negative(key: str, a: StructuralAnalysis, rank: Any = None) -> str | None:
    """One line on what a negative W, q or S of formula ``key`` means (None if not negative)."""
    f = a.formulas[key]
    if f.value is None or f.value >= 0 or getattr(f, "reading", "") == "topology":
        return None
    v = _fmt(f.value)
    if key in ("ozol_redundant", "redundant_from_mobility"):
        w = _fmt(_used_mobility(a))
        if rank is not None:
            return (f"{v} < 0: it is given W = {w}, below the instantaneous mobility {rank.mobility} ({rank.useful_mobility} "
                    f"useful + {len(rank.idle_mobilities)} idle); with that W it gives {rank.redundant_constraints}.")
        return (f"{v} < 0: a count of redundant constraints is never negative, so the W = {w} put into it is below "
                "the mechanism's instantaneous mobility (idle mobilities count there).")
    if a.kind == "planar" and getattr(f, "reading", "") == "spatial":
        return (f"W = {v} < 0 in the spatial reading: a planar loop repeats 3 of its 6 closure conditions and "
                "this count takes them as independent; the planar mechanism still moves (see the verdict).")
    return (f"W = {v} < 0: the formula takes every pair's constraints as independent; some repeat (redundant "
            "constraints), so it does not mean the mechanism cannot move (see the verdict).")


#: what each formula counts, in plain words (the first column of its row)
FORMULA_COUNTS = {
    "chebyshev": "mobility", "grubler": "mobility", "malyshev": "mobility", "somov_malyshev": "mobility",
    "gokhman_contours": "independent contours", "scheme_check": "consistency",
    "ozol_redundant": "redundant constraints", "redundant_from_mobility": "redundant constraints",
}


def formula_value_text(key: str, value: Any) -> str:
    """A formula's value as printed: ``yes``/``no`` for the scheme check, else the number."""
    if value is None:
        return "n/a"
    if key == "scheme_check":
        return "yes" if value else "no"
    return _fmt(value)


def why_it_differs(key: str, a: StructuralAnalysis, rank: Any = None) -> str | None:
    """One plain sentence on why formula ``key`` differs from the verdict's exact answer
    (None when it agrees, counts topology only, or nothing exact is known to compare with:
    no rank method, except for the spatial reading of a planar file).

    Examples
    --------
    >>> import mechsyn as ms
    >>> r = ms.analyze(ms.examples.load("delta"))
    >>> why_it_differs("somov_malyshev", r.analysis, r.rank)[:61]
    "It corrects the count by paper 003's contour by contour tally"
    >>> why_it_differs("chebyshev", ms.analyze(ms.examples.load("fourbar")).analysis) is None
    True
    """
    f = a.formulas[key]
    reading = getattr(f, "reading", "")
    planar_as_3d = a.kind == "planar" and reading == "spatial"
    if f.value is None or reading == "topology" or (rank is None and not planar_as_3d):
        return None
    negative = explain_negative(key, a, rank)
    if negative:
        return negative[0].upper() + negative[1:]
    if FORMULA_COUNTS.get(key) == "mobility":
        exact = rank.useful_mobility if rank is not None else a.mobility
        if f.value == exact:
            return None
        if planar_as_3d:
            return (f"It counts the links as free in 3-D, where each planar loop repeats 3 out-of-plane "
                    f"conditions; the planar mechanism's mobility is {_fmt(exact)} (the verdict).")
        q, idle = rank.redundant_constraints, len(rank.idle_mobilities)
        if key == "somov_malyshev":
            return (f"It corrects the count by paper 003's contour by contour tally, which assumes each contour's "
                    f"joints in general position; from the actual axes the rank method finds {q} redundant "
                    f"constraint{_s(q)} and {idle} idle motion{_s(idle)}, so the mobility is {exact}.")
        parts = ([f"{q} constraint{_s(q)} repeat{'s' if q == 1 else ''} others"] if q else []) + (
            [f"{idle} motion{_s(idle)} {'is' if idle == 1 else 'are'} idle (a link spinning in place)"] if idle else [])
        return (f"It takes every joint's constraints as independent and every motion as useful; here "
                f"{' and '.join(parts)}, so the mobility is {exact}.")
    if FORMULA_COUNTS.get(key) == "redundant constraints" and rank is not None:
        if f.value == rank.redundant_constraints:
            return None
        return (f"It is given W = {_fmt(_used_mobility(a))}; with the exact instantaneous mobility "
                f"{rank.mobility} (idle motions included) it gives {rank.redundant_constraints}.")
    return None


def _s(n: Any) -> str:
    return "" if n == 1 else "s"


def formula_summary(a: StructuralAnalysis, rank: Any = None) -> dict[str, dict[str, Any]]:
    """The lines below the formula tables, each labelled by what it counts, with the reason
    for any disagreement with the verdict's exact answer (``why_it_differs``, None when
    they agree): ``mobility`` (the formulas' W), ``drives`` (paper 003's H) and
    ``redundancy`` (paper 003's per-contour S_Σ and G_Σ).

    Examples
    --------
    >>> import mechsyn as ms
    >>> s = formula_summary(ms.analyze(ms.examples.load("fourbar")).analysis)
    >>> s["redundancy"]["label"]
    'redundant constraints per contour (paper 003), counted as a 3-D build'
    >>> s["redundancy"]["why_it_differs"][:47]
    'A planar loop repeats 3 out-of-plane conditions'
    """
    planar = a.kind == "planar"
    v = verdict(a, rank)
    main = "chebyshev" if planar else "somov_malyshev"
    out = {"mobility": {
        "counts": "mobility", "value": a.mobility, "text": f"W = {_fmt(a.mobility)}",
        "label": "mobility by the formulas (" + ("Chebyshev, planar reading)" if planar else
                                                  "Somov-Malyshev, paper 003)"),
        "why_it_differs": why_it_differs(main, a, rank)}}
    h = a.degrees_of_mobility
    ex = (f" (reading by exclusive links: {a.degrees_of_mobility_exclusive})"
          if a.degrees_of_mobility_exclusive != h else "")
    out["drives"] = {"counts": "drives", "value": h, "text": a.degrees_of_mobility_expression + ex,
                     "label": "drives by paper 003's rule (links per contour)",
                     "why_it_differs": None if rank is None or rank.useful_mobility == h else (
                         f"The rule counts links per contour, not the joints' axes; from the geometry the rank "
                         f"method needs {rank.useful_mobility} drive{_s(rank.useful_mobility)}.")}
    q, idle = v["redundant_constraints"], v["idle_mobilities"]
    why = None
    if planar and a.contours and q is not None and a.redundant_constraints != q:
        why = (f"A planar loop repeats 3 out-of-plane conditions that a 3-D build must hold (parallel axes), and "
               f"this count takes them as redundant; the planar mechanism has {_fmt(q)} (the verdict).")
    elif not planar and rank is not None and (a.redundant_constraints, a.idle_mobilities) != (q, idle):
        why = (f"Each contour is counted on its own with its joints in general position; from the actual axes the "
               f"rank method finds {_fmt(q)} redundant constraint{_s(q)} and {idle} idle mobilit"
               f"{'y' if idle == 1 else 'ies'}.")
    out["redundancy"] = {
        "counts": "redundant constraints", "value": a.redundant_constraints,
        "label": "redundant constraints per contour (paper 003)" + (", counted as a 3-D build" if planar else ""),
        "text": (f"S_Σ = {a.structural_redundancy} ({a.redundant_constraints} redundant constraint"
                 f"{_s(a.redundant_constraints)}, {a.idle_mobilities} idle mobilit"
                 f"{'y' if a.idle_mobilities == 1 else 'ies'}); G_Σ = {_fmt(a.constructive_redundancy)} "
                 f"(metric constraints {_fmt(a.metric_constraints)}, redundant links {a.redundant_links})"),
        "why_it_differs": why}
    return out


def drive_check(a: StructuralAnalysis, rank: Any = None) -> DriveCheck:
    """The declared drives against the mobility: the rank method's independent drives at the
    drawn pose where it ran, else the formulas' mobility (drives after the first W in excess).

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.io import mechanism_from_dict, mechanism_to_dict
    >>> d = mechanism_to_dict(ms.examples.load("fourbar"))
    >>> d["joints"][3]["actuated"] = True               # a drive on the rocker's pivot D too
    >>> r = ms.analyze(mechanism_from_dict(d))
    >>> drive_check(r.analysis, r.rank).text()
    '2 drives (A, D) for mobility 1: drop `actuated: true` on D'
    """
    if rank is not None:
        return DriveCheck(list(rank.actuated), int(rank.useful_mobility), list(rank.excess_drives), "rank method")
    return drive_check_of_formulas(list(a.actuated), a.mobility)


def verdict(a: StructuralAnalysis, rank: Any = None) -> dict[str, Any]:
    """The answer first: mobility, useful and idle, redundant constraints and where they come
    from (the exact rank method at the drawn pose where the file gives the geometry, else the
    formulas of the file's own kind), with one sentence saying it.

    Examples
    --------
    >>> import mechsyn as ms
    >>> v = verdict(ms.analyze(ms.examples.load("fourbar")).analysis)
    >>> v["mobility"], v["redundant_constraints"], v["source"]
    (1, 0, 'formulas, planar reading (no rank method)')
    """
    if rank is not None:
        out: dict[str, Any] = {
            "mobility": rank.useful_mobility, "instantaneous_mobility": rank.mobility,
            "idle_mobilities": len(rank.idle_mobilities), "redundant_constraints": rank.redundant_constraints,
            "singular": bool(rank.singular), "shaky": bool(getattr(rank, "shaky", False)),
            "finite_mobility": rank.finite_mobility, "source": "exact rank method at the drawn pose"}
        pose = (f"SINGULAR at the drawn pose (finite mobility nearby {rank.finite_mobility})" if rank.singular
                else f"not singular but SHAKY: finite mobility {rank.finite_mobility}, "
                     f"{rank.mobility - rank.finite_mobility} instantaneous motion(s) do not extend"
                if getattr(rank, "shaky", False) else "not singular")
        idle = len(rank.idle_mobilities)
        split = (f" (instantaneous {rank.mobility} = {rank.useful_mobility} useful + {idle} idle)" if idle
                 else " (no idle mobility)")
        from mechsyn.structure.rank import motion_headline

        out["drives_needed"] = rank.drives_needed
        out["text"] = (f"{motion_headline(rank)}; drives needed: {rank.drives_needed}; instantaneous mobility "
                       f"{rank.useful_mobility}{split}, {rank.redundant_constraints} redundant "
                       f"constraints, {pose}; from the {out['source']}")
        return _with_drives(out, drive_check(a, rank))
    planar = a.kind == "planar"
    q = a.formulas["ozol_redundant"].value if planar else a.redundant_constraints
    idle = None if planar else a.idle_mobilities
    out = {"mobility": a.mobility, "instantaneous_mobility": None, "idle_mobilities": idle,
           "redundant_constraints": q, "singular": None, "shaky": None, "finite_mobility": None,
           "source": f"formulas, {a.kind} reading (no rank method)"}
    idle_text = "idle mobilities unknown without the joints' geometry" if idle is None else f"{idle} idle"
    out["text"] = (f"mobility W = {_fmt(a.mobility)}, {_fmt(q) if q is not None else 'n/a'} redundant "
                   f"constraints, {idle_text}; from the {out['source']}: give each joint's point and axis "
                   "for the exact rank method")
    return _with_drives(out, drive_check(a, rank))


def _with_drives(out: dict[str, Any], check: DriveCheck) -> dict[str, Any]:
    """The verdict with its ``over_actuation`` line (None when no drive is in excess),
    also said at the end of its text."""
    out["over_actuation"] = check.text() or None
    if check.over_actuated:
        out["text"] += f". {check.text()}"
    return out


def formula_title(title: str, f: object) -> str:
    """``title`` with the formula's reading (planar, spatial, topology, or a family's), when
    it has one: every printed formula says what it counts."""
    reading = getattr(f, "reading", "")
    return f"{title} ({reading})" if reading and reading not in title else title


def pair_list(row_pairs: Sequence[object]) -> str:
    return " ".join(f"{p.id}{p.pair_class}" for p in row_pairs)  # type: ignore[attr-defined]


def _fmt(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


def _formula_rows(a: StructuralAnalysis, keys: list[str], rank: Any = None) -> list[str]:
    rows = ["| counts | formula | expression | value |", "|---|---|---|---|"]
    for key in keys:
        f = a.formulas[key]
        rows.append(f"| {FORMULA_COUNTS.get(key, '')} | {formula_title(FORMULA_TITLES.get(key, key), f)} | "
                    f"`{f.expression}` | {formula_value_text(key, f.value)} |")
    why = [f"{', '.join(formula_title(FORMULA_TITLES.get(k, k), a.formulas[k]) for k in ks)}: {line}"
           for line, ks in formula_reasons(a, keys, rank)]
    return rows + ([""] + [f"- {line}" for line in why] if why else [])


def formula_reasons(a: StructuralAnalysis, keys: list[str], rank: Any = None) -> list[tuple[str, list[str]]]:
    """The reasons (:func:`why_it_differs`) of the formulas ``keys`` with the formulas each
    explains, said once; the formulas' own mobility is left to its line below the table
    (:func:`formula_summary`)."""
    main = "chebyshev" if a.kind == "planar" else "somov_malyshev"
    out: dict[str, list[str]] = {}
    for k in keys:
        line = why_it_differs(k, a, rank) if k != main else None
        if line:
            out.setdefault(line, []).append(k)
    return list(out.items())


def _summary_bullet(line: dict[str, Any]) -> str:
    why = f" *Differs from the verdict:* {line['why_it_differs']}" if line["why_it_differs"] else ""
    return f"- {line['label']}: `{line['text']}`.{why}"


def to_markdown(a: StructuralAnalysis, remedies: Sequence[Remedy] | None = None, level: int = 1,
                rank: Any = None) -> str:
    """The Markdown report of ``a``: the verdict, the formulas of the file's own kind, then
    (for a planar file) its spatial readings in a section of their own."""
    h = "#" * level
    pbc = ", ".join(f"p{k} = {v}" for k, v in a.pairs_by_class.items())
    own, spatial = formula_sections(a)
    summary = formula_summary(a, rank)
    out = [
        f"{h} {a.name}", "",
        f"{a.kind} mechanism: n = {a.moving_links} moving links (N = {a.links_with_frame} with the frame), "
        f"{a.pairs} pairs ({pbc}), K = {a.independent_contours} independent contours.", "",
        f"**Verdict**: {verdict(a, rank)['text']}.", "",
        f"{h}# Formulas ({READINGS['planar' if a.kind == 'planar' else 'spatial']})", "",
        *_formula_rows(a, own, rank),
        "", _summary_bullet(summary["mobility"]), _summary_bullet(summary["drives"]),
    ]
    if spatial:
        out += ["", f"{h}# {SPATIAL_OF_PLANAR[0]}", "", SPATIAL_OF_PLANAR[1], "", *_formula_rows(a, spatial, rank)]
    if a.contours:
        out += ["", f"{h}{'#' if spatial else ''}# Contours (paper 003{CONTOUR_READING[a.kind]})", "",
                "| # | joints | new pairs | n_j | n_k | S_j | idle | T_j | Z_j | A_j |",
                "|---|---|---|---|---|---|---|---|---|---|"]
        for r in a.contours:
            mark = "" if r.from_file else " *"
            out.append(f"| {r.index}{mark} | {' '.join(r.joints)} | {pair_list(r.new_pairs)} | {r.n_j} | {r.n_k} | "
                       f"{r.S} | {r.idle_mobilities} | {_fmt(r.T)} | {r.Z} | {r.A} |")
        out += [""] + [f"- `{r.S_expression}`; `{r.T_expression}`" for r in a.contours]
    out += ["", _summary_bullet(summary["redundancy"])]
    if a.external is not None:
        e = a.external
        out += ["", f"{h}# External constraints (paper 002)", "",
                f"- S_a = {e.S_a}, W_f = {e.W_f}, W_rob = {e.W_rob}, W_a = {e.W_a}, S_ai = {e.S_ai}",
                f"- `{e.external_redundant.expression}`", f"- `{e.system_redundant.expression}`"]
    if a.notes:
        out += ["", f"{h}# Notes", ""] + [f"- {n}" for n in a.notes]
    for name, sub in a.states.items():
        out += ["", to_markdown(sub, level=level + 1).replace(f"{'#' * (level + 1)} {sub.name}",
                                                                 f"{'#' * (level + 1)} State `{name}`: {sub.name}", 1)]
    if remedies is not None:
        out += ["", f"{h}# Remedies", ""]
        if not remedies:
            out.append("No class-change remedy found (or nothing to remedy).")
        for k, r in enumerate(remedies, 1):
            out.append(f"{k}. " + "; ".join(c.describe() for c in r.changes)
                       + f" — S_j = {', '.join(str(x.S) for x in r.analysis.contours)}, "
                       f"`{r.analysis.formulas['somov_malyshev'].expression}`")
    return "\n".join(out) + "\n"


@dataclass(repr=False)
class StructureReport(Result):
    """Everything :func:`analyze` found; ``to_dict()`` is ``mechsyn analyze --json``.

    Attributes
    ----------
    method : str
        ``"formulas"``, ``"rank"`` or ``"both"``.
    analysis : StructuralAnalysis
        The formulas, contours (paper 003), external constraints (paper 002), states.
    rank : RankAnalysis or None
        The rank method's result (None with ``method="formulas"``).
    comparisons : list of Comparison
        Each formula beside the rank method, with why they differ.
    state_ranks : dict
        State name -> (its RankAnalysis or None, why not).
    remedies : list of Remedy or None
        Pair-class changes (``remedies=True``); with the rank method, only those it confirms.
    rejected : list
        ``(number, Remedy, RemedyCheck)`` of the remedies the rank method dropped.

    Examples
    --------
    >>> import mechsyn as ms
    >>> r = ms.analyze(ms.examples.load("fourbar"))
    >>> r.to_dict()["mobility"], r.to_dict()["method"]
    (1, 'both')
    """

    mechanism: Mechanism = field(metadata={"json": False})
    method: str
    analysis: StructuralAnalysis
    rank: Any = None
    comparisons: list = field(default_factory=list)
    state_ranks: dict = field(default_factory=dict)
    remedies: list | None = None
    checks: list = field(default_factory=list)
    rank_unavailable: str | None = None
    notes: list = field(default_factory=list)

    @property
    def mobility(self) -> float:
        """The mobility W: the rank method's useful mobility when it ran, else the formulas'."""
        return self.rank.useful_mobility if self.rank is not None else self.analysis.mobility

    @property
    def formulas(self) -> dict:
        """Each classic formula with its numbers substituted (``.value``, ``.expression``)."""
        return self.analysis.formulas

    @property
    def drive_check(self) -> DriveCheck:
        """The declared drives against the mobility (:func:`drive_check`): ``.excess``,
        ``.text()`` the one line of an over-actuated mechanism."""
        return drive_check(self.analysis, self.rank)

    @property
    def verdict(self) -> dict[str, Any]:
        """The answer first (:func:`verdict`): mobility, useful/idle, redundant constraints, source."""
        return verdict(self.analysis, self.rank)

    @property
    def rejected(self) -> list:
        return [(k, r, c) for k, r, c in self.checks if not c.accepted]

    def _summary(self) -> list[tuple[str, str]]:
        a = self.analysis
        v = self.verdict
        rows = [("mechanism", self.mechanism.name), ("method", self.method),
                ("mobility W", f"{self.mobility:g}"),
                ("redundant constraints", "n/a" if v["redundant_constraints"] is None else
                 _fmt(v["redundant_constraints"])),
                ("idle mobilities", "unknown" if v["idle_mobilities"] is None else str(v["idle_mobilities"])),
                ("from", v["source"])]
        if self.remedies is not None:
            rows.append(("remedies", str(len(self.remedies))))
        return rows

    def to_dict(self) -> dict[str, Any]:
        ra = self.rank
        data = to_jsonable(self.analysis)
        data["method"] = self.method
        data["verdict"] = self.verdict
        data["drive_check"] = self.drive_check.to_dict()
        own, spatial = formula_sections(self.analysis)
        data["formula_readings"] = {k: getattr(f, "reading", "") or None for k, f in self.analysis.formulas.items()}
        data["formula_sections"] = {"own": own, "spatial_reading_of_planar": spatial}
        data["formula_explanations"] = {k: e for k in self.analysis.formulas
                                        if (e := explain_negative(k, self.analysis, ra))}
        for k, f in self.analysis.formulas.items():  # the keys stay; what a user reads is beside them
            data["formulas"][k].update(
                label=formula_title(FORMULA_TITLES.get(k, k), f), counts=FORMULA_COUNTS.get(k),
                value_text=formula_value_text(k, f.value), why_it_differs=why_it_differs(k, self.analysis, ra))
        data["formula_summary"] = formula_summary(self.analysis, ra)
        data["rank"] = ra.to_dict() if ra is not None else None
        if ra is None and self.rank_unavailable:
            data["rank_unavailable"] = self.rank_unavailable
        if ra is not None:
            data["mobility_formulas"] = data["mobility"]
            data["mobility"] = ra.useful_mobility
            data["mobility_source"] = "rank method: useful mobility (idle mobilities excluded)"
            data["comparison"] = [c.to_dict() for c in self.comparisons]
            for name, (sr, why) in self.state_ranks.items():
                if name in data.get("states", {}):
                    data["states"][name]["rank"] = sr.to_dict() if sr is not None else None
                    if why:
                        data["states"][name]["rank_unavailable"] = why
        if self.notes:
            data["notes"] = list(data.get("notes", [])) + self.notes
        if self.remedies is not None:
            if self.checks:
                data["remedies"] = [dict(to_jsonable(r), rank_check=c.to_dict()) for _, r, c in self.checks
                                    if c.accepted]
                data["remedies_rejected"] = [dict(to_jsonable(r), rank_check=c.to_dict()) for _, r, c in self.rejected]
            else:
                data["remedies"] = [to_jsonable(r) for r in self.remedies]
        return data

    def to_markdown(self) -> str:
        """The Markdown report (``mechsyn analyze --markdown``)."""
        from mechsyn.structure.compare import rank_to_markdown

        text = (to_markdown(self.analysis, self.remedies, rank=self.rank) if self.method != "rank"
                else f"# {self.analysis.name}\n\n**Verdict**: {self.verdict['text']}.\n")
        if self.rank is not None:
            text += "\n" + rank_to_markdown(self.rank, self.comparisons if self.method == "both" else None)
            if self.checks:
                text += "\n## Remedies re-checked by the rank method\n\n" + "\n".join(
                    f"- variant {k} ({'; '.join(c.joint for c in r.changes)}): {chk.reason}"
                    for k, r, chk in self.checks) + "\n"
        return text

    def _repr_markdown_(self) -> str:
        return self.to_markdown()


def _rank_or_reason(mech: Mechanism, tol: float | None) -> tuple[Any, str | None]:
    from mechsyn.structure.rank import analyze_rank, missing_geometry

    problems = missing_geometry(mech)
    if problems:
        return None, "geometry insufficient: " + "; ".join(problems)
    return analyze_rank(mech, tol=tol), None


def analyze(mech: Mechanism, method: str | None = None, remedies: bool = False, max_variants: int = 10,
            tol: float | None = None, as_spatial: bool = False,
            progress: ProgressCallback | None = None) -> StructureReport:
    """Structural analysis of ``mech`` by the classic formulas and, where the joints' geometry
    is given, the rank method (screw theory), side by side.

    Parameters
    ----------
    mech : Mechanism
        From :func:`mechsyn.load`.
    method : {"formulas", "rank", "both"}, optional
        Default: ``"both"`` when every joint has its geometry, else ``"formulas"``.
    remedies : bool
        Also list pair-class changes that remove redundant constraints and idle mobilities
        (paper 003), re-checked by the rank method when it runs.
    max_variants : int
        How many remedy variants to list.
    tol : float, optional
        Rank tolerance on the normalised singular values, in (0, 1) (default 1e-6, raised
        for coordinates written with few decimals).
    as_spatial : bool
        Analyse a planar mechanism as a spatial one (R axes along z).
    progress : callable, optional
        ``progress(state)`` (:class:`mechsyn.progress.Progress`) at each stage of the rank
        method (large mechanisms).

    Returns
    -------
    StructureReport

    Raises
    ------
    MechsynInputError
        For a bad ``method`` or ``tol`` (naming the parameter), and
        :class:`~mechsyn.structure.rank.InsufficientGeometry` when the rank method is asked
        for without the joints' geometry.

    Examples
    --------
    >>> import mechsyn as ms
    >>> r = ms.analyze(ms.examples.load("fourbar"))
    >>> r.method, r.mobility, r.formulas["chebyshev"].value
    ('both', 1, 1)
    >>> ms.analyze(ms.examples.load("double_parallelogram")).rank.redundant_constraints
    1

    References
    ----------
    The formulas and per-contour reading follow seed papers 002 and 003 (see
    :mod:`mechsyn.structure.analysis`); the rank method Hunt (1978), Davies (1981) and
    Gogu (2005) (see :mod:`mechsyn.structure.rank`).
    """
    from mechsyn.structure.compare import check_remedy, compare_with_formulas
    from mechsyn.structure.rank import InsufficientGeometry, analyze_rank
    from mechsyn.structure.rank import as_spatial as to_spatial
    from mechsyn.structure.rank import missing_geometry

    if method is not None and method not in ("formulas", "rank", "both"):
        raise MechsynInputError(f"unknown method {method!r}", field="method", hint="use formulas, rank or both")
    if tol is not None and not (0 < tol < 1):
        raise MechsynInputError(f"tolerance {tol:g} is out of (0, 1)", field="tol", hint="e.g. 1e-6")
    notes: list[str] = []
    if as_spatial:
        if mech.kind == "planar":
            mech = to_spatial(mech)
        else:
            notes.append("as_spatial: the mechanism is already spatial")
    problems = missing_geometry(mech)
    if method is None:
        method = "formulas" if problems else "both"
    if method in ("rank", "both") and problems:
        raise InsufficientGeometry(
            "the rank method needs each joint's geometry: " + "; ".join(problems), source=mech.source,
            hint="add point/axis (see `mechsyn schema`), or use the formulas method")
    result = analyze_structure(mech)
    ra = analyze_rank(mech, tol=tol, progress=progress) if method != "formulas" else None
    comparisons = compare_with_formulas(result, ra) if ra is not None else []
    state_ranks = {name: _rank_or_reason(mech.in_state(name), tol) for name in mech.states} if ra is not None else {}
    rem = find_remedies(mech, max_variants=max_variants) if remedies else None
    checks = []
    if rem is not None and ra is not None:
        checks = [(k, r, check_remedy(mech, r.mechanism, ra, r.analysis.metric_constraints, tol))
                  for k, r in enumerate(rem, 1)]
    kept = [r for _, r, c in checks if c.accepted] if checks else rem
    return StructureReport(mech, method, result, ra, comparisons, state_ranks, kept, checks,
                           "; ".join(problems) if problems else None, notes)
