"""``mechsyn synth curve``: linkages (4, 6, 8 links) whose tracing point follows a drawn curve."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer
from rich.markup import escape

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import check_writable, emit_json, err_console, parse_floats, progress_bar, stop_if_interrupted
from mechsyn.errors import MechsynInputError


@synth_app.command("curve")
def synth_curve(
    target: Path = typer.Argument(..., help="Target curve: CSV of x,y rows, JSON {\"points\": [[x, y], ...], \"closed\": true}, or SVG (one path)."),
    max_links: int = typer.Option(8, "--max-links", help="Largest linkage: 4, 6 or 8 links."),
    time_limit: float = typer.Option(60.0, "--time-limit", help="Seconds for the whole search (loading, retrieval, refinement, checks); the search refines and widens until then and answers with the best it has."),
    refinements: Optional[int] = typer.Option(None, "--refinements", help="A fixed number of refinements instead (deterministic; the time limit still holds)."),
    target_error: Optional[float] = typer.Option(None, "--target-error", help="Stop once the best error is within this [% of the diagonal] (default: once three topologies are within --tolerance)."),
    top: int = typer.Option(5, "--top", help="How many candidates to list."),
    crank: bool = typer.Option(False, "--crank", help="Only fully rotating inputs (closed targets)."),
    ground_region: Optional[str] = typer.Option(None, "--ground-region", help="Box x0,y0,x1,y1 the frame pivots must stay in."),
    max_size: float = typer.Option(1.5, "--max-size", help="Every joint within this many target diagonals of the target's centroid over the motion (0: no bound)."),
    max_link_ratio: float = typer.Option(10.0, "--max-link-ratio", help="Largest longest/shortest link length (0: no bound)."),
    min_transmission: float = typer.Option(30.0, "--min-transmission-angle", "--min-transmission", help="Smallest transmission angle [deg] over the motion (0: no bound)."),
    prefer: str = typer.Option("simple", "--prefer", help="simple: fewest links within the tolerance, then quality, then error; accuracy: error alone."),
    tolerance: float = typer.Option(0.5, "--tolerance", help="Error [% of the diagonal] within which fewer links rank first."),
    database: Optional[Path] = typer.Option(None, "--database", help="Curve database directory (default: the local one, built on first use)."),
    as_json: bool = typer.Option(False, "--json", help="Print {\"candidates\": [...]} as JSON."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write each candidate's mechanism file and figure into DIR."),
) -> None:
    """Curve to mechanism: ranked 4-, 6- and 8-bar linkages tracing the target, sized to it, each re-simulated."""
    from mechsyn.cli.main import STARTED     # the limit counts from the command's start, imports included
    from mechsyn.cli.render import render_curve_synthesis
    from mechsyn.synthesis.curves.synthesis import synthesize_curve
    from mechsyn.synthesis.curves.target import read_target

    box = _ground_region(ground_region)
    check_writable(out, "--out", directory=True)
    tgt = read_target(target)
    _say_first_build(database)
    with progress_bar("synth curve", best="best {:.2%}") as progress:
        res = synthesize_curve(tgt, max_links=max_links, time_limit=time_limit, top=top, crank=crank,
                               ground_region=box, max_size=max_size or None, max_link_ratio=max_link_ratio or None,
                               min_transmission=min_transmission, prefer=prefer, tolerance=_fraction(tolerance),
                               database=database, progress=progress, refinements=refinements, started=STARTED,
                               target_error=None if target_error is None else _fraction(target_error, "--target-error"))
    if out is not None:
        _write_out(out, res)
    emit_json(res.to_dict()) if as_json else render_curve_synthesis(res)
    stop_if_interrupted(res)
    _fail_if_empty(res)


def _say_first_build(database: Optional[Path]) -> None:
    """One line on stderr when the curve database is about to be built (its folder is empty
    or missing): the wait that follows is the build, done once and reused."""
    from mechsyn.synthesis.curves.database import default_database_dir

    where = database if database is not None else default_database_dir()
    if where.exists() and not where.is_dir():
        return  # not a directory: the library refuses it in one line
    if not where.exists() or not any(where.iterdir()):
        err_console.print(f"building the curve database on first use (4-, 6- and 8-bar curves, once; later runs "
                          f"reuse it) in {escape(str(where))}", highlight=False, soft_wrap=True)


def _fraction(percent: float, option: str = "--tolerance") -> float:
    if not 0 < percent < 100:
        raise MechsynInputError(f"{percent:g}: give a percentage of the diagonal in (0, 100)", source=option)
    return percent / 100.0


def _fail_if_empty(res) -> None:
    """No candidate within the bounds is an error (exit status 1), the nearest miss named."""
    if not res.candidates:
        err_console.print(f"[bold red]error:[/] {escape(res.reason)}", highlight=False, soft_wrap=True)
        raise typer.Exit(1)


def _ground_region(text: Optional[str]) -> Optional[tuple[float, ...]]:
    if text is None:
        return None
    box = tuple(parse_floats(text, "--ground-region", 4))
    if not (box[0] < box[2] and box[1] < box[3]):
        raise MechsynInputError("expected x0,y0,x1,y1 with x0 < x1 and y0 < y1", source="--ground-region")
    return box


def _write_out(out: Path, res) -> None:
    from mechsyn.cli.common import save_plot, say_written
    from mechsyn.synthesis.export import write_mechanism_file
    from mechsyn.synthesis.reports import curve_candidate_files

    out.mkdir(parents=True, exist_ok=True)
    for i, (c, (name, mech, header)) in enumerate(zip(res.candidates, curve_candidate_files(res)), 1):
        d = c.to_dict()
        write_mechanism_file(mech, out / name, header=header)
        say_written(out / name)
        save_plot(out / f"candidate_{i}.png", _draw_candidate, c, res.target,
                  f"candidate {i}: {d['topology'] or c.topology.key}", figsize=(6, 5))


def _draw_candidate(candidate, target, title: str, ax) -> None:
    from mechsyn.plot.curves import plot_candidate

    plot_candidate(candidate, target, ax=ax)
    ax.legend(fontsize=8)
    ax.set_title(title)
