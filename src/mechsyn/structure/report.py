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
   devices" (in Ukrainian, with an English abstract); authors, journal and year are
   not in the project's copy ("paper 002"; see docs/references.md).
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

__all__ = ["StructureReport", "analyze", "to_markdown"]

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


def formula_title(title: str, f: object) -> str:
    """``title`` with the formula's planar/spatial reading, when it has one."""
    reading = getattr(f, "reading", "")
    return f"{title} ({reading})" if reading in ("planar", "spatial") and reading not in title else title


def pair_list(row_pairs: Sequence[object]) -> str:
    return " ".join(f"{p.id}{p.pair_class}" for p in row_pairs)  # type: ignore[attr-defined]


def _fmt(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


def to_markdown(a: StructuralAnalysis, remedies: Sequence[Remedy] | None = None, level: int = 1) -> str:
    h = "#" * level
    pbc = ", ".join(f"p{k} = {v}" for k, v in a.pairs_by_class.items())
    out = [
        f"{h} {a.name}", "",
        f"{a.kind} mechanism: n = {a.moving_links} moving links (N = {a.links_with_frame} with the frame), "
        f"{a.pairs} pairs ({pbc}), K = {a.independent_contours} independent contours.", "",
        f"{h}# Formulas", "", "| formula | expression | value |", "|---|---|---|",
    ]
    for key, f in a.formulas.items():
        val = "n/a" if f.value is None else _fmt(f.value)
        out.append(f"| {formula_title(FORMULA_TITLES.get(key, key), f)} | `{f.expression}` | {val} |")
    if a.contours:
        out += ["", f"{h}# Contours (paper 003{CONTOUR_READING[a.kind]})", "",
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
        f"- mobility W = {_fmt(a.mobility)} ({a.mobility_source})",
        f"- degrees of mobility (drives): `{a.degrees_of_mobility_expression}`"
        + (f" (reading by exclusive links: {a.degrees_of_mobility_exclusive})"
           if a.degrees_of_mobility_exclusive != a.degrees_of_mobility else ""),
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
    def rejected(self) -> list:
        return [(k, r, c) for k, r, c in self.checks if not c.accepted]

    def _summary(self) -> list[tuple[str, str]]:
        a = self.analysis
        rows = [("mechanism", self.mechanism.name), ("method", self.method),
                ("mobility W", f"{self.mobility:g}"),
                ("redundant constraints", str(self.rank.redundant_constraints if self.rank is not None
                                              else a.redundant_constraints)),
                ("idle mobilities", str(len(self.rank.idle_mobilities) if self.rank is not None else a.idle_mobilities))]
        if self.remedies is not None:
            rows.append(("remedies", str(len(self.remedies))))
        return rows

    def to_dict(self) -> dict[str, Any]:
        ra = self.rank
        data = to_jsonable(self.analysis)
        data["method"] = self.method
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

        text = to_markdown(self.analysis, self.remedies) if self.method != "rank" else ""
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
