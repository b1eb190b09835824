"""``mechsyn capability``: directional speed limits of a (redundant) serial arm.

A thin layer over :mod:`mechsyn.capability`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Optional

import numpy as np
import typer
from rich import box
from mechsyn.cli.common import SafeConsole
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.capability.arm import SerialArm, load_arm
from mechsyn.capability.maps import capability_map, interpolate_configuration, is_closed_form, measure_values
from mechsyn.capability.measures import MEASURES
from mechsyn.capability.point import MEASURE_HELP, PointCapability, capability_at
from mechsyn.cli.app import app
from mechsyn.cli.common import check_writable, console, emit_json, is_stdout, one_stdout, parse_floats, parse_range, progress_bar, stop_if_interrupted, write_output
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


@app.command("capability")
def capability(
    arm_file: Path = typer.Argument(..., help="arm file (YAML/JSON: planar_serial, dh, urdf) or .urdf"),
    point: Optional[str] = typer.Option(None, "--point", help="tool point X,Y (X,Y,Z for spatial arms)"),
    grid: Optional[str] = typer.Option(None, "--grid", help="X0:X1:DX,Y0:Y1:DY: a map over a grid"),
    z: Optional[float] = typer.Option(None, "--z", help="plane z = Z of the grid (spatial arms)"),
    direction: str = typer.Option(..., "--direction", help="direction d of motion, e.g. 1,0"),
    q1: Optional[str] = typer.Option(None, "--q1", help="q1 samples in degrees, START:STOP:STEP "
                                     "or a list (default: 20 deg steps over q1's limits)"),
    branch: Optional[str] = typer.Option(None, "--branch", help="planar 3R elbow: negative "
                                         "(q3 < 0, the paper's, default), positive or both"),
    ignore_limits: bool = typer.Option(False, "--ignore-limits", help="let configurations "
                                       "outside the joint position limits through"),
    measure: str = typer.Option("exact", "--measure", help="what 'best' maximises: "
                                + ", ".join(MEASURES)),
    step: float = typer.Option(5.0, "--step", help="speed step of the paper's stepping method"),
    continuous: bool = typer.Option(False, "--continuous", help="maps: continuous search "
                                    "over the self-motion instead of the samples"),
    polytope: bool = typer.Option(False, "--polytope", help="add the best configuration's "
                                  "velocity polytope and ellipse"),
    map_png: Optional[Path] = typer.Option(None, "--map", help="write a heat/contour map (PNG)"),
    csv_out: Optional[Path] = typer.Option(None, "--csv", help="write the grid as CSV (- for stdout)"),
    interpolate: Optional[str] = typer.Option(None, "--interpolate", help="grid: the optimal "
                                              "configuration interpolated at X,Y"),
    json_out: bool = typer.Option(False, "--json", help="print JSON on stdout"),
    workers: int = typer.Option(1, "--workers", help="grid: solve it in N local processes"),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="grid: solve it on a Dask "
                                            "cluster (scheduler address; extra mechsyn[dask])"),
) -> None:
    """Largest tool speed along a direction under joint speed limits (paper 004), at a point
    over the arm's self-motion, or mapped over a grid."""
    check_writable(map_png, "--map")
    check_writable(csv_out, "--csv")
    from mechsyn.parallel import check_parallel_options

    check_parallel_options(workers, scheduler)
    arm = load_arm(arm_file)
    m = arm.task_dim
    d = np.array(parse_floats(direction, "--direction", m))
    _check_finite(d, "--direction")
    if not np.any(d):
        raise MechsynInputError("the direction must not be zero", source="--direction",
                                hint="e.g. --direction 1,0 (along x)")
    if measure not in MEASURES:
        raise MechsynInputError(f"unknown measure {measure!r}", source="--measure",
                                hint="one of " + ", ".join(MEASURES))
    if not (step > 0 and math.isfinite(step)):
        raise MechsynInputError("step must be positive", source="--step", hint="e.g. --step 1")
    if branch is not None:
        if branch.lower() not in _BRANCH_ALIASES:
            raise MechsynInputError(f"unknown branch {branch!r}", source="--branch",
                                    hint="negative (q3 < 0), positive or both")
        if not is_closed_form(arm):
            raise MechsynInputError("--branch applies to planar 3R arms only", source="--branch",
                                    hint="drop --branch: this arm's configurations are all searched")
    br = _BRANCH_ALIASES[(branch or "negative").lower()]
    q1_vals = None
    if q1 is not None:
        q1_vals = _values(q1, "--q1")
        _check_finite(q1_vals, "--q1")
        q1_vals = np.radians(q1_vals) if arm.is_revolute[0] else q1_vals
    if (point is None) == (grid is None):
        raise MechsynInputError("give exactly one of --point and --grid", source="--point",
                                hint="--point 1300,900 or --grid 1300:2100:200,100:900:200")
    if point is not None:
        if map_png or csv_out or interpolate:
            raise MechsynInputError("--map, --csv and --interpolate go with --grid",
                                    source="--map" if map_png else "--csv" if csv_out
                                    else "--interpolate", hint="give --grid X0:X1:DX,Y0:Y1:DY instead of --point")
        _point(arm, np.array(parse_floats(point, "--point", m)), d, q1_vals, br,
               not ignore_limits, measure, step, polytope, json_out)
    else:
        at = None
        if interpolate is not None:
            at = np.array(parse_floats(interpolate, "--interpolate", 2))
            _check_finite(at, "--interpolate")
        _grid(arm, grid, z, d, q1_vals, br, not ignore_limits, measure, continuous,
              map_png, csv_out, json_out, at, {"workers": workers, "scheduler": scheduler})


def _point(arm, p, d, q1_vals, br, respect, measure, step, polytope, json_out) -> None:
    _check_finite(p, "--point")
    res = capability_at(arm, p, d, measure=measure, q1=q1_vals, branch=br, respect_limits=respect, step=step,
                        polytope=polytope)
    if json_out:
        emit_json(res.to_dict())
        return
    _render_point(arm, res, step)


def _render_point(arm: SerialArm, res: PointCapability, step: float) -> None:
    p, dn, measure, configs = res.point, res.direction, res.measure, res.configurations
    table = Table(box=box.SIMPLE_HEAD, pad_edge=False, title=f"{arm.name}: speed along ({', '.join(f'{c:g}' for c in np.round(dn, 4))}) "
                        f"at ({', '.join(f'{c:g}' for c in p)})")
    table.add_column("")
    for name in arm.joint_names:
        table.add_column(name, justify="right", no_wrap=True, min_width=6)
    for head in ("exact", "compon.", "min-nrm", "st.mn", "stepped"):
        table.add_column(head, justify="right", no_wrap=True)
    kbest = res.best_index
    shown = list(range(len(configs)))
    if len(configs) > 15:  # many IK solutions (spatial arms): the best ones
        shown = sorted(np.argsort([-c[measure] for c in configs], kind="stable")[:12].tolist())
    for k in shown:
        c = configs[k]
        table.add_row("best" if k == kbest else "", *[f"{v:.1f}" for v in c["q_deg"]],
                      *[f"{c[mn]:.2f}" for mn in MEASURES],
                      style="bold green" if k == kbest else None)
    cb = res.continuous_best
    if cb:
        table.add_row("cont", *[f"{v:.1f}" for v in cb["q_deg"]],
                      *[f"{cb[mn]:.2f}" for mn in MEASURES], style="cyan")
    need = 12 + 8 * arm.n + 50
    out = console if console.is_terminal or console.width >= need else SafeConsole(width=need)
    out.print(table)
    if len(shown) < len(configs):
        console.print(f"showing the best {len(shown)} of {len(configs)} configurations "
                      "(all with --json)")
    if not configs:
        console.print("[yellow]no allowed configuration reaches this point[/]")
    else:
        console.print(f"best sampled ({measure}): {configs[kbest][measure]:.3f}"
                      + (f"; continuous search over the self-motion (cont): "
                         f"{cb[measure]:.3f}" if cb else ""))
    for r in res.rejected:
        console.print(f"rejected q = ({', '.join(f'{v:.2f}' for v in r['q_deg'])}): {r['reason']}")
    console.print("[dim]exact: " + MEASURE_HELP["exact"] + "; compon.: " + MEASURE_HELP["component"]
                  + "; min-nrm: " + MEASURE_HELP["min_norm"] + "; st.mn / stepped: the paper's "
                  f"{step:g}-step raise with minimum-norm rates / with the null space in full[/]")


def _grid(arm, grid, z, d, q1_vals, br, respect, measure, continuous, map_png, csv_out,
          json_out, at=None, parallel=None) -> None:
    parts = grid.split(",")
    if len(parts) != 2:
        raise MechsynInputError(f"expected X0:X1:DX,Y0:Y1:DY, got {grid!r}", source="--grid",
                                hint="e.g. --grid 1300:2100:200,100:900:200")
    xs, ys = _values(parts[0], "--grid"), _values(parts[1], "--grid")
    for v in (xs, ys):
        _check_finite(v, "--grid")
    if xs.size * ys.size > 5_000_000:
        raise MechsynInputError(f"{xs.size * ys.size:,} grid points are more than 5,000,000", source="--grid",
                                hint="use larger steps or a smaller area")
    if arm.kind == "spatial" and z is None:
        raise MechsynInputError("a spatial arm's grid needs its plane", source="--z",
                                hint="add --z 400 (the grid lies in z = 400)")
    total = xs.size * ys.size
    chunk = 2048 if is_closed_form(arm) else 64  # numeric IK: 64 points at once
    with progress_bar("capability map", total, enabled=total >= 2000 or not is_closed_form(arm)) as adv:
        cmap = capability_map(arm, xs, ys, d, z=z, measure=measure, q1=q1_vals, branch=br,
                              respect_limits=respect, continuous=continuous, chunk=chunk,
                              advance=adv, **(parallel or {}))
    one_stdout(json_out, csv_out)
    if csv_out is not None:
        write_output(csv_out, cmap.to_csv())
    if map_png is not None:
        from mechsyn.cli.common import save_plot
        from mechsyn.plot.capability import plot_capability_map

        save_plot(map_png, plot_capability_map, cmap)
    v = np.where(np.isfinite(cmap.value), cmap.value, np.nan)
    interp = None
    if at is not None:
        if not (xs.min() <= at[0] <= xs.max() and ys.min() <= at[1] <= ys.max()):
            raise MechsynInputError(f"({at[0]:g}, {at[1]:g}) lies outside the grid", source="--interpolate",
                                    hint=f"give a point with x in [{xs.min():g}, {xs.max():g}] and y in "
                                         f"[{ys.min():g}, {ys.max():g}]")
        method = "cubic" if xs.size >= 4 and ys.size >= 4 else "linear"
        qi = interpolate_configuration(cmap, method)(at[0], at[1])
        target = at if arm.kind == "planar" else np.array([at[0], at[1], z])
        interp = {"point": target, "method": method, "q_deg": None, "tool_error": None,
                  measure: None}
        if np.all(np.isfinite(qi)):
            interp.update({
                "q_deg": arm.to_user(qi),
                "tool_error": float(np.linalg.norm(arm.fk(qi)[0] - target)),
                measure: float(measure_values(arm, qi[None], d, measure)[0])})
    if is_stdout(csv_out):
        return stop_if_interrupted(cmap)
    if json_out:
        out = cmap.to_dict()
        if interp is not None:
            out["interpolated"] = interp
        emit_json(out)
        return stop_if_interrupted(cmap)
    if total <= 144:
        table = Table(title=f"V_max ({measure}, {cmap.search}); rows x, columns y")
        table.add_column("x \\ y")
        for y in ys:
            table.add_column(f"{y:g}", justify="right")
        for i, x in enumerate(xs):
            table.add_row(f"{x:g}", *["?" if not ok else "-" if not np.isfinite(c) else f"{c:.2f}"
                                      for c, ok in zip(v[i], cmap.done()[i])])
        console.print(table)
    reach = np.isfinite(v)
    if reach.any():
        i, j = np.unravel_index(np.nanargmax(v), v.shape)
        console.print(f"{total} points, {int(reach.sum())} reachable; V_max from "
                      f"{np.nanmin(v):.3f} to {np.nanmax(v):.3f} (at x={xs[i]:g}, y={ys[j]:g})")
    else:
        console.print(f"{total} points, none reachable with the allowed configurations")
    if interp is not None:
        if interp["q_deg"] is None:
            console.print("interpolation: no optimal configuration near this point")
        else:
            console.print(f"interpolated optimal configuration at ({at[0]:g}, {at[1]:g}) "
                          f"({interp['method']}): q = ({', '.join(f'{c:.3f}' for c in interp['q_deg'])})"
                          f"; tool {interp['tool_error']:.3g} from the point (correct with IK); "
                          f"{measure} {interp[measure]:.3f}")
    for what, path in (("map", map_png), ("csv", csv_out)):
        if path is not None:
            console.print(f"wrote {what}: {path}")
    if cmap.interrupted:
        console.print(f"interrupted: {int(cmap.done().sum())} of {total} points solved (? in the table); the outputs hold those")
    stop_if_interrupted(cmap)
