"""``mechsyn atlas``: number and topological synthesis of planar kinematic chains."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer
import yaml
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import app
from mechsyn.cli.common import check_writable, console, emit_json, progress_bar
from mechsyn.errors import MechsynInputError
from mechsyn.results import write_atomic

MAX_DRAWN = 600


def _label(assortment: dict[int, int]) -> str:
    names = {2: "B", 3: "T", 4: "Q", 5: "P", 6: "H"}
    return " ".join(f"{c}{names.get(d, f'd{d}')}" for d, c in sorted(assortment.items()))


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
    from mechsyn.synthesis.chains import (
        link_assortments, n_units, synthesize_chains, synthesize_chains_to_file)
    from mechsyn.parallel import check_parallel_options
    from mechsyn.synthesis.mechanisms import distinct_mechanisms, frame_orbits, mechanism_dict

    if out is not None and out.suffix.lower() not in (".svg", ".png", ".pdf"):
        raise MechsynInputError(f"cannot draw to {out.name!r}", source="--out",
                                hint="give a file ending in .svg, .png or .pdf")
    check_writable(out, "--out")
    check_writable(stream, "--stream")
    check_writable(mechanisms, "--mechanisms", directory=True)
    check_parallel_options(workers, scheduler)
    total_units = n_units(links, mobility)
    with progress_bar(f"{links}-link chains, F={mobility}", total_units) as advance:
        if stream is not None:
            chains = synthesize_chains_to_file(stream, links, mobility, include_degenerate,
                                               progress=advance, force=force, workers=workers,
                                               scheduler=scheduler)
        else:
            chains = synthesize_chains(links, mobility, include_degenerate, progress=advance,
                                       workers=workers, scheduler=scheduler)
    if out is not None and len(chains) > MAX_DRAWN:
        raise MechsynInputError(
            f"{len(chains)} chains are too many to draw on one sheet (limit {MAX_DRAWN})",
            source="--out", hint="use --json or --mechanisms DIR for this many chains")

    records = []
    for i, chain in enumerate(chains, start=1):
        rec = {"number": i, **chain.to_dict()}
        if not chain.degenerate:
            rec["frames"] = [o[0] for o in frame_orbits(chain)]
            if inputs:
                rec["mechanisms"] = [{"frame": m.frame, "input": m.input}
                                     for m in distinct_mechanisms(chain)]
        records.append(rec)
    good = [c for c in chains if not c.degenerate]
    by_assortment: dict[str, dict] = {}
    for assortment in link_assortments(links, mobility):  # number synthesis, in order
        key = ",".join(f"{d}:{c}" for d, c in sorted(assortment.items()))
        by_assortment[key] = {
            "assortment": {str(d): c for d, c in sorted(assortment.items())},
            "label": _label(assortment), "chains": 0, "non_planar": 0,
            "fractionated": 0, "degenerate": 0, "mechanisms": 0}
    for chain, rec in zip(chains, records):
        key = ",".join(f"{d}:{c}" for d, c in sorted(chain.assortment.items()))
        row = by_assortment.setdefault(key, {
            "assortment": {str(d): c for d, c in sorted(chain.assortment.items())},
            "label": chain.assortment_label(), "chains": 0, "non_planar": 0,
            "fractionated": 0, "degenerate": 0, "mechanisms": 0})
        if chain.degenerate:
            row["degenerate"] += 1
            continue
        row["chains"] += 1
        row["non_planar"] += not chain.planar_graph
        row["fractionated"] += chain.fractionated
        row["mechanisms"] += len(rec["mechanisms"] if inputs else rec["frames"])
    result = {
        "n_links": links,
        "mobility": mobility,
        "n_joints": (3 * (links - 1) - mobility) // 2,
        "count": len(good),
        "non_planar": sum(not c.planar_graph for c in good),
        "fractionated": sum(c.fractionated for c in good),
        "degenerate_listed": len(chains) - len(good),
        "mechanisms": sum(r["mechanisms"] for r in by_assortment.values()),
        "mechanisms_by": "frame and input link" if inputs else "frame",
        "assortments": list(by_assortment.values()),
        "chains": records,
    }

    if mechanisms is not None:
        for i, chain in enumerate(chains, start=1):
            if chain.degenerate:
                continue
            doc = mechanism_dict(chain, name=f"Chain {i} of the {links}-link atlas, "
                                 f"F = {mobility} ({chain.assortment_label()})")
            text = yaml.safe_dump(doc, sort_keys=False, default_flow_style=None)
            write_atomic(mechanisms / f"chain_{links}_{mobility}_{i:04d}.yaml", text)
    if out is not None:
        from mechsyn.cli.common import save_plot
        from mechsyn.plot.atlas import plot_atlas

        save_plot(out, plot_atlas, chains, f"Planar kinematic chains: {links} links, mobility "
                  f"{mobility}: {len(good)} chains")
    if json_out:
        emit_json(result)
        return
    table = Table(title=f"{links} links, mobility {mobility}, "
                  f"{result['n_joints']} joints: {len(good)} chains")
    for col in ("assortment", "chains", "non-planar", "fractionated",
                "mechanisms" + (" (frame, input)" if inputs else " (frames)")):
        table.add_column(col, justify="right" if col != "assortment" else "left")
    if include_degenerate:
        table.add_column("degenerate", justify="right")
    realised = [row for row in by_assortment.values() if row["chains"] or row["degenerate"]]
    empty = [row["label"] for row in by_assortment.values() if row not in realised]
    for row in realised:
        cells = [row["label"], str(row["chains"]), str(row["non_planar"]),
                 str(row["fractionated"]), str(row["mechanisms"])]
        if include_degenerate:
            cells.append(str(row["degenerate"]))
        table.add_row(*cells)
    console.print(table)
    if empty:
        console.print("assortments without a non-degenerate chain: " + ", ".join(empty),
                      highlight=False)
    if len(chains) <= 40:
        for rec, chain in zip(records, chains):
            console.print(f"#{rec['number']} {chain.assortment_label()}: joints "
                          + " ".join(f"{a}-{b}" for a, b in chain.edges), highlight=False)
    if out is not None:
        console.print(f"atlas drawn to {out}")
    if mechanisms is not None:
        console.print(f"{len(good)} mechanism files written to {mechanisms}/")
