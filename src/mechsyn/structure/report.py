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

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Callable

from mechsyn._result import Result
from mechsyn.errors import MechsynInputError
from mechsyn.model.mechanism import Mechanism
from mechsyn.results import to_jsonable
from mechsyn.structure.analysis import StructuralAnalysis, analyze_structure
from mechsyn.structure.remedies import Remedy, find_remedies

__all__ = ["StructureReport", "analyze", "to_markdown", "verdict", "formula_sections", "explain_negative"]

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
        exact = (f"; the rank method's instantaneous mobility is {rank.mobility} ({rank.useful_mobility} useful "
                 f"+ {len(rank.idle_mobilities)} idle) and {rank.redundant_constraints} redundant constraints"
                 if rank is not None else "")
        return (f"{v} < 0: a count of redundant constraints is never negative for the true mobility, so the "
                f"W = {_fmt(_used_mobility(a))} put into it is below the mechanism's instantaneous mobility "
                f"(idle mobilities count there){exact}.")
    if a.kind == "planar" and getattr(f, "reading", "") == "spatial":
        return (f"W = {v} < 0 in the spatial reading: a planar loop repeats 3 of its 6 closure conditions and "
                "this count takes them as independent; the planar mechanism still moves (see the verdict).")
    return (f"W = {v} < 0: the formula takes every pair's constraints as independent; some repeat (redundant "
            "constraints), so it does not mean the mechanism cannot move (see the verdict).")


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
        return out
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
    rows = ["| formula | expression | value |", "|---|---|---|"]
    for key in keys:
        f = a.formulas[key]
        val = "n/a" if f.value is None else _fmt(f.value)
        rows.append(f"| {formula_title(FORMULA_TITLES.get(key, key), f)} | `{f.expression}` | {val} |")
    why = [line for line in (explain_negative(k, a, rank) for k in keys) if line]
    return rows + ([""] + [f"- {line}" for line in why] if why else [])


def to_markdown(a: StructuralAnalysis, remedies: Sequence[Remedy] | None = None, level: int = 1,
                rank: Any = None) -> str:
    """The Markdown report of ``a``: the verdict, the formulas of the file's own kind, then
    (for a planar file) its spatial readings in a section of their own."""
    h = "#" * level
    pbc = ", ".join(f"p{k} = {v}" for k, v in a.pairs_by_class.items())
    own, spatial = formula_sections(a)
    out = [
        f"{h} {a.name}", "",
        f"{a.kind} mechanism: n = {a.moving_links} moving links (N = {a.links_with_frame} with the frame), "
        f"{a.pairs} pairs ({pbc}), K = {a.independent_contours} independent contours.", "",
        f"**Verdict**: {verdict(a, rank)['text']}.", "",
        f"{h}# Formulas ({READINGS['planar' if a.kind == 'planar' else 'spatial']})", "",
        *_formula_rows(a, own, rank),
        "", f"- mobility W = {_fmt(a.mobility)} ({a.mobility_source})",
        f"- degrees of mobility (drives): `{a.degrees_of_mobility_expression}`"
        + (f" (reading by exclusive links: {a.degrees_of_mobility_exclusive})"
           if a.degrees_of_mobility_exclusive != a.degrees_of_mobility else ""),
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
    out += [
        "", f"- structural redundancy S_Σ = {a.structural_redundancy}{CONTOUR_READING[a.kind]} "
        f"({a.redundant_constraints} redundant constraints, {a.idle_mobilities} idle mobilities)",
        f"- constructive redundancy G_Σ = {_fmt(a.constructive_redundancy)} "
        f"(metric constraints {_fmt(a.metric_constraints)}, redundant links {a.redundant_links})",
    ]
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
        own, spatial = formula_sections(self.analysis)
        data["formula_readings"] = {k: getattr(f, "reading", "") or None for k, f in self.analysis.formulas.items()}
        data["formula_sections"] = {"own": own, "spatial_reading_of_planar": spatial}
        data["formula_explanations"] = {k: e for k in self.analysis.formulas
                                        if (e := explain_negative(k, self.analysis, ra))}
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
            progress: Callable[[str], None] | None = None) -> StructureReport:
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
        Called with the name of each stage of the rank method (large mechanisms).

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
