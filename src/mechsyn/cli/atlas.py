"""``mechsyn atlas``: number and topological synthesis of planar kinematic chains."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import typer

from mechsyn.cli.app import app
from mechsyn.cli.common import check_writable, emit_json, progress_bar, say_written
from mechsyn.errors import MechsynInputError
from mechsyn.results import write_atomic

MAX_DRAWN = 600


def _check_files(out: Path | None, stream: Path | None, mechanisms: Path | None, links: int, mobility: int) -> None:
    from mechsyn.synthesis.chains import estimated_chains

    if out is not None and out.suffix.lower() not in (".svg", ".png", ".pdf"):
        raise MechsynInputError(f"cannot draw to {out.name!r}", source="--out",
                                hint="give a file ending in .svg, .png or .pdf")
    if out is not None and estimated_chains(links, mobility) > MAX_DRAWN:  # before, not after, the enumeration
        raise MechsynInputError(f"about {estimated_chains(links, mobility):,.0f} chains are too many to draw on "
                                f"one sheet (limit {MAX_DRAWN})", source="--out",
                                hint="use --json or --mechanisms DIR for this many chains")
    check_writable(out, "--out")
    check_writable(stream, "--stream")
    check_writable(mechanisms, "--mechanisms", directory=True)


def _write_files(atlas: Any, out: Path | None, mechanisms: Path | None, stream: Path | None = None) -> None:
    if out is not None and len(atlas.kinematic_chains) > MAX_DRAWN:
        raise MechsynInputError(
            f"{len(atlas.kinematic_chains)} chains are too many to draw on one sheet (limit {MAX_DRAWN})",
            source="--out", hint="use --json or --mechanisms DIR for this many chains")
    if mechanisms is not None:
        import yaml

        files = atlas.mechanism_files()
        for name, doc in files.items():
            write_atomic(mechanisms / name, yaml.safe_dump(doc, sort_keys=False, default_flow_style=None))
        say_written(mechanisms, f"{len(files)} mechanism files")
    if out is not None:
        from mechsyn.cli.common import save_plot

        save_plot(out, lambda fig: atlas.plot(fig=fig))
    if stream is not None:
        say_written(stream, "chain stream")


@app.command("atlas")
def atlas(
    links: int = typer.Option(..., "--links", "-n", help="Number of links, frame included."),
    mobility: int = typer.Option(1, "--mobility", "-F", help="Degrees of freedom of the chain."),
    json_out: bool = typer.Option(False, "--json", help="Print the atlas as JSON."),
    out: Optional[Path] = typer.Option(
        None, "--out", "-o", help="Draw the atlas to this file (.svg, .png or .pdf)."),
    mechanisms: Optional[Path] = typer.Option(
        None, "--mechanisms", help="Write one mechanism file (YAML) per chain into DIR."),
    include_degenerate: bool = typer.Option(
        False, "--include-degenerate", help="Also list (flagged) degenerate chains."),
    inputs: bool = typer.Option(
        False, "--inputs", help="List the distinct mechanisms by frame AND input link."),
    stream: Optional[Path] = typer.Option(
        None, "--stream", help="Stream chains to this JSON-lines file; rerun to resume."),
    force: bool = typer.Option(
        False, "--force", help="Let --stream overwrite a file that is not a chain stream."),
    workers: int = typer.Option(1, "--workers", help="Share the enumeration among N local processes."),
    scheduler: Optional[str] = typer.Option(
        None, "--scheduler", help="Run on a Dask cluster (scheduler address; extra mechsyn[dask])."),
) -> None:
    """All non-isomorphic planar simple-jointed kinematic chains with N links and
    mobility F, their link assortments and distinct mechanisms (choices of frame)."""
    from mechsyn.cli.render import render_atlas
    from mechsyn.parallel import check_parallel_options
    from mechsyn.synthesis.atlas import chain_atlas
    from mechsyn.synthesis.chains import n_units

    _check_files(out, stream, mechanisms, links, mobility)
    check_parallel_options(workers, scheduler)
    with progress_bar(f"{links}-link chains, F={mobility}", n_units(links, mobility)) as progress:
        result = chain_atlas(links, mobility, include_degenerate=include_degenerate, inputs=inputs,
                             stream=stream, force=force, workers=workers, scheduler=scheduler, progress=progress)
    _write_files(result, out, mechanisms, stream)
    if json_out:
        emit_json(result.to_dict())
        return
    render_atlas(result, include_degenerate)
