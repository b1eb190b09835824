"""``mechsyn export FILE --dxf parts.dxf``: link plates to cut, laid out on a sheet."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from mechsyn.cli.app import app
from mechsyn.cli.common import (check_output_suffix, emit_json, is_stdout, one_stdout, parse_range, say_written,
                                write_output)
from mechsyn.errors import MechsynInputError


def _values(items: list[str] | None) -> dict[str, float]:
    out = {}
    for item in items or []:
        jid, _, v = item.partition("=")
        try:
            out[jid.strip()] = float(v)
        except ValueError:
            raise MechsynInputError(f"expected J=VALUE, got {item!r}", source="--pose",
                                    hint="write e.g. --pose A=30") from None
    return out


def _sweep(text: str | None):
    if text is None:
        return None
    from mechsyn.kinematics.analysis import input_grid

    jid, _, spec = text.partition("=")
    start, stop, step = parse_range(spec, "--sweep", f"{jid or 'A'}=0:360:2")
    return {jid.strip(): input_grid(start, stop, step)}


FileArg = Annotated[Path, typer.Argument(help="Planar mechanism file (YAML, JSON or a Pyslvs .pyslvs) with joint points.")]
DxfOpt = Annotated[Optional[Path], typer.Option("--dxf", help="Write the link plates as DXF (ezdxf, "
    "installed with mechsyn; $INSUNITS from the file's unit).")]
WidthOpt = Annotated[Optional[float], typer.Option("--width", help="Plate width (default: a fifth of the "
    "shortest hole spacing).")]
HoleOpt = Annotated[Optional[float], typer.Option("--hole", help="Pin diameter (default: 40% of the "
    "width).")]
ClearanceOpt = Annotated[float, typer.Option("--clearance", help="Added to the pin diameter for the cut "
    "holes.")]
FrameOpt = Annotated[bool, typer.Option("--frame/--no-frame", help="Cut the frame's plate too.")]
SheetWidthOpt = Annotated[Optional[float], typer.Option("--sheet-width", help="Width of the sheet the rows "
    "of plates fill.")]
SvgOpt = Annotated[Optional[Path], typer.Option("--svg", help="Write the plates as SVG (cut lines, holes, "
    "labels; - for stdout).")]
DrawingOpt = Annotated[Optional[Path], typer.Option("--drawing", help="Write an SVG drawing of the mechanism at "
    "a pose, with --path and --dimensions.")]
PoseOpt = Annotated[Optional[list[str]], typer.Option("--pose", metavar="J=V", help="Driven joint value of the drawing: J=V "
    "(deg for R, length for P; default: the file's).")]
PathOpt = Annotated[Optional[list[str]], typer.Option("--path", metavar="POINT", help="Draw the path of this point (a name from "
    "`points:` or a joint id) over --sweep.")]
SweepOpt = Annotated[Optional[str], typer.Option("--sweep", help="Input range of the paths: "
    "J=START:STOP:STEP.")]
DimensionsOpt = Annotated[bool, typer.Option("--dimensions", help="Write the bar lengths on the drawing.")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print the plates (hole centres, sizes) as JSON.")]


@app.command("export")
def export_cmd(
    file: FileArg,
    dxf: DxfOpt = None,
    width: WidthOpt = None,
    hole: HoleOpt = None,
    clearance: ClearanceOpt = 0.0,
    frame: FrameOpt = True,
    sheet_width: SheetWidthOpt = None,
    svg: SvgOpt = None,
    drawing: DrawingOpt = None,
    pose: PoseOpt = None,
    path: PathOpt = None,
    sweep: SweepOpt = None,
    dimensions: DimensionsOpt = False,
    json_: JsonOpt = False,
) -> None:
    """Link plates with joint holes, laid out flat on a sheet, for a laser cutter or CNC; a
    vector drawing of the mechanism at a pose with its paths."""
    from mechsyn.cli.render import render_plates
    from mechsyn.export.plates import link_plates
    from mechsyn.io.convert import load_any

    _check_outputs(dxf, svg, drawing, json_)
    mech = load_any(file)
    if drawing is not None:
        _write_drawing(mech, drawing, pose, path, sweep, dimensions)
        if dxf is None and svg is None and not json_:
            return
    layout = link_plates(mech, width=width, hole_diameter=hole, clearance=clearance, frame=frame,
                         sheet_width=sheet_width)
    _write_plates(layout, dxf, svg)
    if is_stdout(svg):
        return
    if json_:
        emit_json(layout.to_dict())
        return
    render_plates(layout)



def _check_outputs(dxf: Optional[Path], svg: Optional[Path], drawing: Optional[Path], json_: bool) -> None:
    check_output_suffix(dxf, (".dxf",), "--dxf")
    check_output_suffix(svg, (".svg",), "--svg")
    check_output_suffix(drawing, (".svg",), "--drawing")
    one_stdout(json_, svg, drawing)
    if dxf is None and svg is None and drawing is None and not json_:
        raise MechsynInputError("nothing to export", source="--dxf",
                                hint="add --dxf parts.dxf, --svg parts.svg, --drawing mech.svg or --json")


def _write_drawing(mech, drawing: Path, pose, path, sweep, dimensions: bool) -> None:
    from mechsyn.export.drawing import drawing_of

    write_output(drawing, drawing_of(mech, _values(pose), path or [], _sweep(sweep), dimensions))


def _write_plates(layout, dxf: Optional[Path], svg: Optional[Path]) -> None:
    if dxf is not None:
        from mechsyn.export.dxf import write_dxf

        write_dxf(layout, dxf)
        say_written(dxf, f"sheet {layout.sheet[0]:.4g} x {layout.sheet[1]:.4g}")
    if svg is not None:
        from mechsyn.export.svg import plates_svg

        write_output(svg, plates_svg(layout))
