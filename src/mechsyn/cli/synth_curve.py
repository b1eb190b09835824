"""``mechsyn synth curve``: linkages (4, 6, 8 links) whose tracing point follows a drawn curve."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import check_writable, console, emit_json, err_console, parse_floats, stop_if_interrupted
from mechsyn.errors import MechsynInputError


@synth_app.command("curve")
def synth_curve(
    target: Path = typer.Argument(..., help="Target curve: CSV of x,y rows, JSON {\"points\": [[x, y], ...], \"closed\": true}, or SVG (one path)."),
    max_links: int = typer.Option(8, "--max-links", help="Largest linkage: 4, 6 or 8 links."),
    time_limit: float = typer.Option(60.0, "--time-limit", help="Seconds for retrieval and refinement."),
    top: int = typer.Option(5, "--top", help="How many candidates to list."),
    crank: bool = typer.Option(False, "--crank", help="Only fully rotating inputs (closed targets)."),
    ground_region: Optional[str] = typer.Option(None, "--ground-region", help="Box x0,y0,x1,y1 the frame pivots must stay in."),
    max_link_ratio: Optional[float] = typer.Option(None, "--max-link-ratio", help="Largest longest/shortest link length."),
    min_transmission: float = typer.Option(15.0, "--min-transmission", help="Transmission angles below this (deg) are penalised."),
    database: Optional[Path] = typer.Option(None, "--database", help="Curve database directory (default: the local one, built on first use)."),
    as_json: bool = typer.Option(False, "--json", help="Print {\"candidates\": [...]} as JSON."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write each candidate's mechanism file and figure into DIR."),
) -> None:
    """Curve to mechanism: ranked 4-, 6- and 8-bar linkages tracing the target, each re-simulated."""
    from mechsyn.synthesis.curves.database import load_database
    from mechsyn.synthesis.curves.synthesis import synthesize_curve
    from mechsyn.synthesis.curves.target import read_target

    box = None
    if ground_region is not None:
        box = tuple(parse_floats(ground_region, "--ground-region", 4))
        if not (box[0] < box[2] and box[1] < box[3]):
            raise MechsynInputError("expected x0,y0,x1,y1 with x0 < x1 and y0 < y1", source="--ground-region")
    if out is not None and out.exists() and not out.is_dir():
        raise MechsynInputError(f"{out} is a file", source="--out", hint="give a directory")
    check_writable(out, "--out", directory=True)
    tgt = read_target(target)
    show = err_console.is_terminal
    if show:
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

        with Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                      TextColumn("best {task.fields[best]}"), TimeElapsedColumn(),
                      console=err_console, transient=True) as prog:
            task = prog.add_task("synth curve", total=None, best="-")

            def callback(state: dict) -> None:
                best = state.get("best")
                text = f"{100 * best:.2f} %" if isinstance(best, float) and best == best else "-"
                prog.update(task, description=f"synth curve: {state['stage']}", completed=state.get("done", 0),
                            total=state.get("total"), best=text)

            db = load_database(database, max_links=max_links, callback=callback)
            res = synthesize_curve(tgt, max_links=max_links, time_limit=time_limit, top=top, crank=crank,
                                   ground_region=box, max_link_ratio=max_link_ratio,
                                   min_transmission=min_transmission, database=db, callback=callback)
    else:
        db = load_database(database, max_links=max_links)
        res = synthesize_curve(tgt, max_links=max_links, time_limit=time_limit, top=top, crank=crank,
                               ground_region=box, max_link_ratio=max_link_ratio,
                               min_transmission=min_transmission, database=db)
    if out is not None:
        _write_out(out, res)
    if as_json:
        emit_json(res)
        stop_if_interrupted(res)
        return
    t = Table(title=f"Curve synthesis: {tgt.source} ({'closed' if tgt.closed else 'open'}, "
                    f"{len(tgt.points)} points)")
    for c in ("#", "topology", "links", "chamfer", "ordered", "min mu", "ratio", "input [deg]"):
        t.add_column(c, justify="right" if c not in ("topology",) else "left")
    for i, c in enumerate(res.candidates, 1):
        d = c.to_dict()
        inp = d["input"]
        t.add_row(str(i), d["topology"] or c.topology.key, str(d["links"]), f"{100 * c.chamfer:.2f} %",
                  f"{100 * c.ordered:.2f} %", f"{c.min_transmission_angle:.0f}", f"{c.link_length_ratio:.1f}",
                  f"{inp['joint']} {inp['start']:.0f}..{inp['stop']:.0f}")
    console.print(t)
    console.print(f"errors per bounding-box diagonal ({tgt.diagonal:.4g}); {res.refined} refined of "
                  f"{res.retrieved} retrieved in {res.seconds:.1f} s; every candidate re-simulated by simulate"
                  + ("; interrupted: best so far" if res.interrupted else ""))
    for n in res.notes:
        console.print(f"note: {n}")
    stop_if_interrupted(res)


def _write_out(out: Path, res) -> None:
    from mechsyn.cli.common import save_plot
    from mechsyn.synthesis.export import write_mechanism_file

    out.mkdir(parents=True, exist_ok=True)
    for i, c in enumerate(res.candidates, 1):
        d = c.to_dict()
        write_mechanism_file(d["mechanism"], out / f"candidate_{i}.yaml", header=(
            f"mechsyn synth curve: candidate {i}, {d['topology'] or c.topology.key}, tracer T\n"
            f"input {d['input']['joint']} from {d['input']['start']:.3f} to {d['input']['stop']:.3f} deg; "
            f"chamfer {100 * c.chamfer:.3f} %, ordered {100 * c.ordered:.3f} % of the target's diagonal"))
        save_plot(out / f"candidate_{i}.png", _draw_candidate, c, res.target,
                  f"candidate {i}: {d['topology'] or c.topology.key}", figsize=(6, 5))


def _draw_candidate(candidate, target, title: str, ax) -> None:
    from mechsyn.plot.curves import plot_candidate

    plot_candidate(candidate, target, ax=ax)
    ax.legend(fontsize=8)
    ax.set_title(title)
