"""``mechsyn curves build``: build or extend the local curve database (resumable)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from mechsyn.cli.app import app
from mechsyn.cli.common import console, emit_json, progress_bar
from mechsyn.errors import MechsynInputError

curves_app = typer.Typer(help="The local curve database of curve synthesis.", no_args_is_help=True)
app.add_typer(curves_app, name="curves")


@curves_app.command("build")
def curves_build(
    links: int = typer.Option(8, "--links", help="Topologies up to this many links: 4, 6 or 8."),
    per_topology: int = typer.Option(3000, "--per-topology", help="Curves kept per four- and six-bar topology (a tenth of it per eight-bar one)."),
    database: Optional[Path] = typer.Option(None, "--database", help="Directory (default: the local one)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the random designs."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Build on a Dask cluster (scheduler address; extra mechsyn[dask])."),
    as_json: bool = typer.Option(False, "--json", help="Print a summary as JSON."),
) -> None:
    """Build or extend the curve database; rerun to resume or to add curves."""
    from mechsyn.synthesis.curves.topologies import curve_topologies
    from mechsyn.synthesis.reports import curve_database

    if links not in (4, 6, 8):  # --links here, --max-links in synth curve
        raise MechsynInputError(f"{links} links: choose 4, 6 or 8", source="--links")
    with progress_bar("curves build", len(curve_topologies(links)), enabled=not as_json) as progress:
        report = curve_database(database, max_links=links, per_topology=per_topology, seed=seed,
                                scheduler=scheduler, progress=progress)
    if as_json:
        emit_json(report.to_dict())
        return
    console.print(f"{report.curves} curves ({report.closed} closed, {report.open} open arcs) of "
                  f"{report.topologies} topologies in {report.database} ({report.bytes / 1e6:.1f} MB)")
