"""``mechsyn structure FILE``: Assur group decomposition of a planar mechanism.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import app
from mechsyn.cli.common import console, emit_json, safe


@app.command("structure")
def structure(
    file: Path = typer.Argument(..., help="Planar mechanism file (YAML or JSON)."),
    json_out: bool = typer.Option(False, "--json", help="Print JSON."),
    output: Optional[list[str]] = typer.Option(
        None, "--output", metavar="LINK", help="Output link (repeatable; default: links carrying points)."),
) -> None:
    """Input links, Assur groups (class and order, Artobolevsky), structural formula and
    class of a planar mechanism; the binary links paper 000 may turn into ternary ones."""
    from mechsyn.io import load_mechanism
    from mechsyn.structure.assur import assur_decomposition, roman

    from mechsyn.cli.working import LARGE_JOINTS, reading, working

    with reading(file):
        mech = load_mechanism(file)
    with working(f"Assur groups of {len(mech.links):,} links", len(mech.joints) >= LARGE_JOINTS):
        result = assur_decomposition(mech, output_links=output or None)
    if json_out:
        emit_json(result)
        return
    console.print(f"[bold]{safe(result.name)}[/]: mobility W = {result.mobility}, frame "
                  f"{result.frame}", highlight=False)
    table = Table(title="Initial mechanisms and Assur groups, in order of formation")
    for col in ("", "class", "order", "links", "internal pairs", "external pairs", "attached to"):
        table.add_column(col)
    for i, g in enumerate(result.groups, start=1):
        kind = "input" + (" (imaginary)" if g.imaginary_input else "") if g.group_class == 1 \
            else "group"
        table.add_row(f"{i} {kind}", roman(g.group_class), str(g.order), ", ".join(g.links),
                      ", ".join(g.internal_pairs) or "-", ", ".join(g.external_pairs),
                      ", ".join(g.attached_to))
    console.print(table)
    console.print(f"structural formula: {result.structural_formula}", highlight=False)
    console.print(f"mechanism class: {roman(result.mechanism_class)}", highlight=False)
    if result.output_links:
        console.print(f"output link(s): {', '.join(result.output_links)}", highlight=False)
    console.print("binary links that may become ternary (free leashes, paper 000): "
                  + (", ".join(result.leash_candidates) or "none"), highlight=False)
    for note in result.replaced_higher_pairs + result.notes:
        console.print(f"note: {note}", highlight=False)
