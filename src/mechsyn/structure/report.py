"""Markdown report of a structural analysis (the terminal report is drawn by the CLI)."""

from __future__ import annotations

from collections.abc import Sequence

from mechsyn.structure.analysis import StructuralAnalysis
from mechsyn.structure.remedies import Remedy

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
