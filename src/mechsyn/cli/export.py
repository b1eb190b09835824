"""``mechsyn export FILE --dxf parts.dxf``: link plates to cut, laid out on a sheet."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.markup import escape
from rich.table import Table

from mechsyn.cli.app import app
from mechsyn.cli.common import check_output_suffix, console, emit_json, err_console
from mechsyn.errors import MechsynInputError


@app.command("export")
def export_cmd(
    file: Annotated[Path, typer.Argument(help="Planar mechanism file (YAML, JSON or a Pyslvs .pyslvs) with joint points.")],
    dxf: Annotated[Optional[Path], typer.Option("--dxf", help="Write the link plates as DXF (needs the "
                                                "`cad` extra: ezdxf).")] = None,
    width: Annotated[Optional[float], typer.Option("--width", help="Plate width (default: a fifth of the "
                                                   "shortest hole spacing).")] = None,
    hole: Annotated[Optional[float], typer.Option("--hole", help="Pin diameter (default: 40% of the "
                                                  "width).")] = None,
    clearance: Annotated[float, typer.Option("--clearance", help="Added to the pin diameter for the cut "
                                             "holes.")] = 0.0,
    frame: Annotated[bool, typer.Option("--frame/--no-frame", help="Cut the frame's plate too.")] = True,
    sheet_width: Annotated[Optional[float], typer.Option("--sheet-width", help="Width of the sheet the rows "
                                                         "of plates fill.")] = None,
    json_: Annotated[bool, typer.Option("--json", help="Print the plates (hole centres, sizes) as JSON.")] = False,
) -> None:
    """Link plates with joint holes, laid out flat on a sheet, for a laser cutter or CNC."""
    from mechsyn.export.plates import link_plates
    from mechsyn.io.convert import load_any

    check_output_suffix(dxf, (".dxf",), "--dxf")
    if dxf is None and not json_:
        raise MechsynInputError("nothing to export", source="--dxf", hint="add --dxf parts.dxf or --json")
    mech = load_any(file)
    layout = link_plates(mech, width=width, hole_diameter=hole, clearance=clearance, frame=frame,
                         sheet_width=sheet_width)
    if dxf is not None:
        from mechsyn.export.dxf import write_dxf

        write_dxf(layout, dxf)
    if json_:
        emit_json(layout)
        return
    t = Table(title=f"{escape(layout.mechanism)}: {len(layout.plates)} plates, width {layout.width:.4g}, "
                    f"holes {layout.cut_diameter:.4g} (pin {layout.hole_diameter:.4g} + {layout.clearance:.4g})")
    for col in ("link", "holes", "size"):
        t.add_column(col)
    for p in layout.plates:
        t.add_row(escape(p.link), escape(", ".join(p.hole_names)), f"{p.size[0]:.4g} x {p.size[1]:.4g}")
    console.print(t)
    for note in layout.notes:
        err_console.print(f"note: {escape(note)}", highlight=False, soft_wrap=True)
    if dxf is not None:
        console.print(f"wrote {escape(str(dxf))} (sheet {layout.sheet[0]:.4g} x {layout.sheet[1]:.4g})")
