"""``mechsyn analyze FILE``: structural analysis by the papers' formulas, and ``mechsyn schema``.

References
----------
.. [1] "Rational structural synthesis of schemes of crank-slider mechanisms of gripping
   devices" (in Ukrainian, with an English abstract) ("paper 002"; see docs/references.md).
.. [2] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Optional

import typer

from mechsyn.cli.app import app
from mechsyn.cli.common import emit_json, err_console, progress_bar, strip_control, write_output
from mechsyn.io import json_schema, load_mechanism
from mechsyn.structure.report import analyze as structure_report


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
    with progress_bar("rank method") as progress:
        return structure_report(mech, progress=progress, **options)


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
            write_output(out, report.to_markdown())
    else:
        from mechsyn.cli.render import render_report

        render_report(report)


@app.command("schema")
def schema(
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="Write the schema to this file.")] = None,
) -> None:
    """Print the JSON Schema of mechanism files."""
    text = json.dumps(json_schema(), indent=2)
    if out is None:
        typer.echo(text)
    else:
        write_output(out, text + "\n")
