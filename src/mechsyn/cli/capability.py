"""``mechsyn capability``: directional speed limits of a (redundant) serial arm.

A thin layer over :mod:`mechsyn.capability`.

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from mechsyn.capability.arm import SerialArm
from mechsyn.capability.arm_file import load_arm
from mechsyn.capability.maps import capability_grid, is_closed_form
from mechsyn.capability.measures import MEASURES
from mechsyn.capability.point import capability_at
from mechsyn.cli.app import app
from mechsyn.cli.common import (check_writable, console, emit_json, is_stdout, one_stdout, parse_floats, parse_range,
                                progress_bar, stop_if_interrupted, write_output)
from mechsyn.cli.render import render_capability_map, render_point_capability
from mechsyn.errors import MechsynInputError

_BRANCH_ALIASES = {"negative": "negative", "neg": "negative", "-": "negative", "down": "negative",
                   "positive": "positive", "pos": "positive", "+": "positive", "up": "positive",
                   "both": "both"}


def _values(text: str, option: str) -> np.ndarray:
    """``A:B:S`` (inclusive of B) or a single number or a comma list."""
    if ":" in text:
        a, b, s = parse_range(text, option)
        n = int(math.floor((b - a) / s + 1e-9)) + 1
        if n > 100_000:
            raise MechsynInputError(f"{n:,} values is too many (at most 100,000 per axis)", source=option,
                                    hint="use a larger step or a shorter range")
        return a + s * np.arange(n)
    return np.array(parse_floats(text, option))


def _check_finite(values, option: str) -> None:
    if not np.all(np.isfinite(values)):
        raise MechsynInputError("values must be finite", source=option, hint="give finite numbers")


PointOpt = Annotated[Optional[str], typer.Option("--point", help="tool point X,Y (X,Y,Z for spatial arms)")]
GridOpt = Annotated[Optional[str], typer.Option("--grid", help="X0:X1:DX,Y0:Y1:DY: a map over a grid")]
Q1Opt = Annotated[Optional[str], typer.Option("--q1", help="q1 samples in degrees, START:STOP:STEP or a list "
                                              "(default: 20 deg steps over q1's limits)")]
BranchOpt = Annotated[Optional[str], typer.Option("--branch", help="planar 3R elbow: negative (q3 < 0, the paper's, "
                                                  "default), positive or both")]
IgnoreLimitsOpt = Annotated[bool, typer.Option("--ignore-limits", help="let configurations outside the joint "
                                               "position limits through")]
MeasureOpt = Annotated[str, typer.Option("--measure", help="what 'best' maximises: " + ", ".join(MEASURES))]
ContinuousOpt = Annotated[bool, typer.Option("--continuous", help="maps: continuous search over the self-motion "
                                             "instead of the samples")]
PolytopeOpt = Annotated[bool, typer.Option("--polytope", help="add the best configuration's velocity polytope "
                                           "and ellipse")]
InterpolateOpt = Annotated[Optional[str], typer.Option("--interpolate", help="grid: the optimal configuration "
                                                       "interpolated at X,Y")]
GridSchedulerOpt = Annotated[Optional[str], typer.Option("--scheduler", help="grid: solve it on a Dask cluster "
                                                         "(scheduler address; extra mechsyn[dask])")]


@app.command("capability")
def capability(
    arm_file: Path = typer.Argument(..., help="arm file (YAML/JSON: planar_serial, dh, urdf) or .urdf"),
    point: PointOpt = None,
    grid: GridOpt = None,
    z: Optional[float] = typer.Option(None, "--z", help="plane z = Z of the grid (spatial arms)"),
    direction: str = typer.Option(..., "--direction", help="direction d of motion, e.g. 1,0"),
    q1: Q1Opt = None,
    branch: BranchOpt = None,
    ignore_limits: IgnoreLimitsOpt = False,
    measure: MeasureOpt = "exact",
    step: float = typer.Option(5.0, "--step", help="speed step of the paper's stepping method"),
    continuous: ContinuousOpt = False,
    polytope: PolytopeOpt = False,
    map_png: Optional[Path] = typer.Option(None, "--map", help="write a heat/contour map (PNG)"),
    csv_out: Optional[Path] = typer.Option(None, "--csv", help="write the grid as CSV (- for stdout)"),
    interpolate: InterpolateOpt = None,
    json_out: bool = typer.Option(False, "--json", help="print JSON on stdout"),
    workers: int = typer.Option(1, "--workers", help="grid: solve it in N local processes"),
    scheduler: GridSchedulerOpt = None,
) -> None:
    """Largest tool speed along a direction under joint speed limits (paper 004), at a point
    over the arm's self-motion, or mapped over a grid."""
    from mechsyn.parallel import check_parallel_options

    check_writable(map_png, "--map"), check_writable(csv_out, "--csv"), check_parallel_options(workers, scheduler)
    arm = load_arm(arm_file)
    common = _common_options(arm, direction, q1, branch, ignore_limits, measure, step)
    if (point is None) == (grid is None):
        raise MechsynInputError("give exactly one of --point and --grid", source="--point",
                                hint="--point 1300,900 or --grid 1300:2100:200,100:900:200")
    if point is not None:
        if map_png or csv_out or interpolate:
            raise MechsynInputError("--map, --csv and --interpolate go with --grid",
                                    source="--map" if map_png else "--csv" if csv_out else "--interpolate",
                                    hint="give --grid X0:X1:DX,Y0:Y1:DY instead of --point")
        _point(arm, parse_floats(point, "--point", arm.task_dim), common, step, polytope, json_out)
    else:
        at = None if interpolate is None else parse_floats(interpolate, "--interpolate", 2)
        _grid(arm, grid, dict(common, z=z, continuous=continuous, interpolate=at, workers=workers,
                              scheduler=scheduler), map_png, csv_out, json_out)


def _common_options(arm: SerialArm, direction: str, q1: Optional[str], branch: Optional[str],
                    ignore_limits: bool, measure: str, step: float) -> dict:
    """The options of a point and a grid as the library's keyword arguments."""
    d = parse_floats(direction, "--direction", arm.task_dim)
    if not (step > 0 and math.isfinite(step)):
        raise MechsynInputError("step must be positive", source="--step", hint="e.g. --step 1")
    if branch is not None:
        if branch.lower() not in _BRANCH_ALIASES:
            raise MechsynInputError(f"unknown branch {branch!r}", source="--branch",
                                    hint="negative (q3 < 0), positive or both")
        if not is_closed_form(arm):
            raise MechsynInputError("--branch applies to planar 3R arms only", source="--branch",
                                    hint="drop --branch: this arm's configurations are all searched")
    q1_vals = None
    if q1 is not None:
        q1_vals = _values(q1, "--q1")
        _check_finite(q1_vals, "--q1")
        q1_vals = np.radians(q1_vals) if arm.is_revolute[0] else q1_vals
    return {"direction": d, "measure": measure, "q1": q1_vals,
            "branch": _BRANCH_ALIASES[(branch or "negative").lower()], "respect_limits": not ignore_limits}


def _point(arm, p, common: dict, step: float, polytope: bool, json_out: bool) -> None:
    common = dict(common)
    res = capability_at(arm, p, common.pop("direction"), step=step, polytope=polytope, **common)
    if json_out:
        emit_json(res.to_dict())
        return
    render_point_capability(arm, res, step)


def _grid(arm, grid: str, options: dict, map_png: Optional[Path], csv_out: Optional[Path], json_out: bool) -> None:
    parts = grid.split(",")
    if len(parts) != 2:
        raise MechsynInputError(f"expected X0:X1:DX,Y0:Y1:DY, got {grid!r}", source="--grid",
                                hint="e.g. --grid 1300:2100:200,100:900:200")
    xs, ys = _values(parts[0], "--grid"), _values(parts[1], "--grid")
    total = xs.size * ys.size
    with progress_bar("capability map", total, enabled=total >= 2000 or not is_closed_form(arm)) as progress:
        cmap = capability_grid(arm, xs, ys, progress=progress, **options)
    one_stdout(json_out, csv_out)
    if csv_out is not None:
        write_output(csv_out, cmap.to_csv())
    if map_png is not None:
        from mechsyn.cli.common import save_plot
        from mechsyn.plot.capability import plot_capability_map

        save_plot(map_png, plot_capability_map, cmap)
    if is_stdout(csv_out):
        return stop_if_interrupted(cmap)
    if json_out:
        emit_json(cmap.to_dict())
        return stop_if_interrupted(cmap)
    render_capability_map(cmap)
    if cmap.interrupted:
        console.print(f"interrupted: {int(cmap.done().sum())} of {total} points solved (? in the table); the outputs hold those")
    stop_if_interrupted(cmap)
