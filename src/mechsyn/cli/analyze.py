"""``mechsyn analyze FILE``: structural analysis by the papers' formulas, and ``mechsyn schema``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.panel import Panel

from mechsyn.cli.app import app
from mechsyn.cli.common import Table, console, emit_json, err_console, safe, strip_control  # Table: cells fold
from mechsyn.io import json_schema, load_mechanism
from mechsyn.results import write_atomic
from mechsyn.structure.analysis import StructuralAnalysis
from mechsyn.structure.compare import Comparison, RemedyCheck
from mechsyn.structure.rank import RankAnalysis, rank_summary_lines
from mechsyn.structure.remedies import Remedy
from mechsyn.structure.report import CONTOUR_READING, StructureReport, formula_title, pair_list
from mechsyn.structure.report import analyze as structure_report


SHORT_TITLES = {
    "chebyshev": "Chebyshev", "grubler": "Grübler", "malyshev": "Malyshev",
    "somov_malyshev": "Somov-Malyshev", "gokhman_contours": "Gokhman K", "scheme_check": "scheme check",
    "ozol_redundant": "Ozol q", "redundant_from_mobility": "S from W",
}


def _fmt(x: float | None) -> str:
    if x is None:
        return "n/a"
    return str(int(x)) if float(x).is_integer() else f"{x:g}"


def render(a: StructuralAnalysis, title_prefix: str = "") -> None:
    pbc = ", ".join(f"p{k} = {v}" for k, v in a.pairs_by_class.items())
    console.print(Panel.fit(
        f"[bold]{title_prefix}{safe(a.name)}[/]\n{a.kind} mechanism: n = {a.moving_links} moving links "
        f"(N = {a.links_with_frame}), {a.pairs} pairs ({pbc}), K = {a.independent_contours} contours",
    ))
    t = Table(title="Formulas", show_lines=False)
    t.add_column("formula", no_wrap=True)
    t.add_column("expression", no_wrap=True)
    t.add_column("value", justify="right")
    for key, f in a.formulas.items():
        t.add_row(formula_title(SHORT_TITLES.get(key, key), f), f.expression, _fmt(f.value))
    console.print(t)
    if a.contours:
        c = Table(title=f"Contours (paper 003, sequential reading{CONTOUR_READING[a.kind]})")
        for col in ("#", "joints", "new pairs", "n_j", "n_k", "S_j", "idle", "T_j", "Z_j", "A_j"):
            c.add_column(col, justify="right" if col not in ("joints", "new pairs") else "left")
        for r in a.contours:
            c.add_row(f"{r.index}{'' if r.from_file else '*'}", " ".join(r.joints), pair_list(r.new_pairs),
                      str(r.n_j), str(r.n_k), str(r.S), str(r.idle_mobilities), _fmt(r.T), str(r.Z), str(r.A))
        console.print(c)
        if a.contours_chosen_by_program:
            console.print("  * contour chosen by the program")
        for r in a.contours:
            console.print(f"  {r.S_expression};  {r.T_expression}", highlight=False, soft_wrap=True)
    console.print(
        f"S_Σ = {a.structural_redundancy}{CONTOUR_READING[a.kind]} ({a.redundant_constraints} redundant constraints, "
        f"{a.idle_mobilities} idle mobilities);  G_Σ = {_fmt(a.constructive_redundancy)} "
        f"(metric {_fmt(a.metric_constraints)}, redundant links {a.redundant_links})", highlight=False,
        soft_wrap=True)
    console.print(f"[bold]W = {_fmt(a.mobility)}[/] ({a.mobility_source});  "
                  f"drives: {a.degrees_of_mobility_expression}", highlight=False, soft_wrap=True)
    if a.external is not None:
        e = a.external
        console.print(f"external (paper 002): S_a = {e.S_a}, W_f = {e.W_f}, W_rob = {e.W_rob}, "
                      f"W_a = {e.W_a}, S_ai = {e.S_ai}", highlight=False)
        console.print(f"  {e.external_redundant.expression}\n  {e.system_redundant.expression}", highlight=False)
    for n in a.notes:
        console.print(f"[dim]note:[/] {n}", highlight=False, soft_wrap=True)
    for name, sub in a.states.items():
        console.print()
        render(sub, title_prefix=f"state '{safe(name)}': ")


def render_remedies(remedies: list[Remedy]) -> None:
    t = Table(title="Remedies (pair-class changes; fewest changes first)")
    t.add_column("#", justify="right")
    t.add_column("changes")
    t.add_column("S_j after", justify="right")
    t.add_column("W after")
    for k, r in enumerate(remedies, 1):
        t.add_row(str(k), "\n".join(c.describe() for c in r.changes),
                  ", ".join(str(x.S) for x in r.analysis.contours),
                  r.analysis.formulas["somov_malyshev"].expression)
    if not remedies:
        console.print("No class-change remedy: nothing to remedy, or a planar mechanism "
                      "(its pairs' planar classes are fixed).")
    else:
        console.print(t)
        left = remedies[0].analysis.metric_constraints
        if left:
            console.print(f"note: {left:g} metric constraint(s) remain in every variant: class changes cannot "
                          "remove them; change the structure (e.g. replace the duplicating link by a two-link "
                          "group, as paper 003 does for fig. 4).", highlight=False)


def render_rank(ra: RankAnalysis, comparisons: list[Comparison] | None, title: str = "") -> None:
    lines = [f"[bold red]{x}[/]" if x.startswith("SINGULAR") else x for x in rank_summary_lines(ra)]
    console.print(Panel.fit("[bold]Rank method (screw theory)" + (f": {title}" if title else "") + "[/]\n"
                            + "\n".join(lines), border_style="cyan"), highlight=False)
    if any(c.redundant for c in ra.contours):
        t = Table(title="Redundant constraints located (rank, contours in order)")
        for col in ("#", "joints", "q_j", "redundant directions", "why"):
            t.add_column(col, justify="right" if col in ("#", "q_j") else "left")
        for c in ra.contours:
            t.add_row(str(c.index), " ".join(c.joints), str(c.redundant), "\n".join(c.directions), c.reason)
        console.print(t)
    if comparisons:
        t = Table(title="Formulas and rank side by side")
        for col in ("quantity", "formula", "formula", "rank", "why they differ"):
            t.add_column(col, justify="right" if col in ("rank",) else "left")
        for c in comparisons:
            fv = "n/a" if c.formula_value is None else _fmt(c.formula_value)
            mark = "" if c.agree else "[yellow]≠[/] "
            t.add_row(c.quantity, c.formula, fv, f"{mark}{c.rank_value}", c.why)
        console.print(t)
    for n in ra.notes:
        console.print(f"[dim]note:[/] {n}", highlight=False)


def render_remedy_checks(checks: list[tuple[int, Remedy, RemedyCheck]]) -> None:
    kept = [c for c in checks if c[2].accepted]
    if kept:
        console.print(f"rank method: the {len(kept)} variant(s) above are confirmed "
                      f"({kept[0][2].reason.removeprefix('confirmed: ')})", highlight=False)
    dropped = [c for c in checks if not c[2].accepted]
    if dropped:
        console.print(f"[bold]dropped by the rank method ({len(dropped)}):[/]")
    for _, r, chk in dropped:
        console.print(f"  - {'; '.join(c.describe() for c in r.changes)}: [red]{chk.reason}[/]", highlight=False)


#: From this many joints, ``analyze`` says the size and shows the rank method's stages on stderr.
LARGE_JOINTS = 1000


def _analyze_reporting(mech, **options):
    """:func:`mechsyn.structure.report.analyze`, with the size and the rank method's stages on
    stderr for a large mechanism."""
    if len(mech.joints) < LARGE_JOINTS:
        return structure_report(mech, **options)
    from mechsyn.structure.contours import cycle_rank

    err_console.print(f"large mechanism: {len(mech.joints)} joints, {len(mech.links)} links, "
                      f"{cycle_rank(mech)} contours; the rank method's work grows about linearly for chains "
                      f"of loops (2,000 joints: a few seconds)", highlight=False)
    with err_console.status("rank method") as status:
        return structure_report(mech, progress=lambda stage: status.update(f"rank method: {stage}"), **options)


@app.command("analyze")
def analyze(
    file: Annotated[Path, typer.Argument(help="Mechanism file (YAML or JSON).")],
    json_out: Annotated[bool, typer.Option("--json", help="Print the result as JSON.")] = False,
    markdown: Annotated[bool, typer.Option("--markdown", help="Print a Markdown report.")] = False,
    remedies: Annotated[bool, typer.Option("--remedies", help="List pair-class changes that remove redundant constraints and idle mobilities.")] = False,
    max_variants: Annotated[int, typer.Option("--max-variants", min=1, help="Remedy variants to list.")] = 10,
    method: Annotated[Optional[str], typer.Option("--method", help="formulas | rank | both (default: both when the file gives the joints' geometry, else formulas).")] = None,
    spatial: Annotated[bool, typer.Option("--as-spatial", help="Analyse a planar file as a spatial mechanism (the 3-D picture: R axes along z).")] = False,
    tol: Annotated[Optional[float], typer.Option("--tol", help="Rank tolerance on the normalised singular values (default: 1e-6, raised for coordinates written with few decimals).")] = None,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="Write the JSON or Markdown to this file instead.")] = None,
) -> None:
    """Structural analysis: mobility by the classic formulas (Chebyshev, Grübler, Malyshev,
    Somov-Malyshev, Gokhman, Ozol), paper 003's per-contour redundant constraints, idle
    mobilities, redundant links, metric constraints and drives, and each state of a
    variable-structure mechanism with paper 002's external constraints.

    When the file gives the joints' geometry, the rank method (screw theory) answers exactly: instantaneous mobility, useful and idle mobilities, redundant constraints per contour and their directions, drives, singularity; each formula is shown next to it."""
    from mechsyn.cli.common import check_writable
    from mechsyn.cli.working import reading

    check_writable(out, "--out")
    with reading(file):
        mech = load_mechanism(file)
    report = _analyze_reporting(mech, method=method, remedies=remedies,
                                max_variants=max_variants, tol=tol, as_spatial=spatial)
    if json_out:
        emit_json(report.to_dict(), out)
    elif markdown:
        if out is None:
            typer.echo(strip_control(report.to_markdown()), nl=False)  # a file's escapes never reach the terminal
        else:
            write_atomic(out, report.to_markdown())
    else:
        render_report(report)


def render_report(report: StructureReport) -> None:
    """The terminal tables of a structural report."""
    ra, method = report.rank, report.method
    if method != "rank":
        render(report.analysis)
    for n in report.notes:
        console.print(f"[dim]note:[/] {n}", highlight=False)
    if ra is not None:
        console.print()
        render_rank(ra, report.comparisons if method == "both" else None)
        for name, (sr, why) in report.state_ranks.items():
            if sr is not None:
                render_rank(sr, None, title=f"state '{name}'")
            else:
                console.print(f"[dim]state '{name}': no rank analysis ({why})[/]", highlight=False)
    if report.remedies is not None:
        console.print()
        render_remedies(report.remedies)
        if report.checks:
            render_remedy_checks(report.checks)


@app.command("schema")
def schema(
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="Write the schema to this file.")] = None,
) -> None:
    """Print the JSON Schema of mechanism files."""
    text = json.dumps(json_schema(), indent=2)
    if out is None:
        typer.echo(text)
    else:
        write_atomic(out, text + "\n")
