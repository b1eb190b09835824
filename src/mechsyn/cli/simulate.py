"""``mechsyn simulate FILE`` (planar kinematics) and ``mechsyn forces FILE`` (kinetostatics)."""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import Annotated, Any, Optional

import numpy as np
import typer
from rich.markup import escape
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import app
from mechsyn.cli.common import (check_animation_target, check_output_suffix, console, emit_json, fmt_number,
                                is_stdout, one_stdout, parse_range,
                                progress_bar, save_animation, save_plot, write_output)
from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism
from mechsyn.results import to_jsonable

InputOpt = Annotated[list[str], typer.Option(
    "--input", "-i", help="Driven joint and its values: J=START:STOP:STEP (deg for R, length for P), "
                          "or J=V1,V2,... Repeat for several inputs (same number of values).")]
SpeedOpt = Annotated[Optional[list[str]], typer.Option(
    "--speed", help="Input rate J=V (rad/s for R, length/s for P; default 1).")]
VllOpt = Annotated[Optional[list[str]], typer.Option(
    "--vll", help="Variable-length link mode J=locked|free|active (paper 000's two modes).")]
MethodOpt = Annotated[str, typer.Option("--method", help="auto | assur | newton")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print JSON on stdout.")]
CsvOpt = Annotated[Optional[Path], typer.Option("--csv", help="Write a CSV table.")]
PlotOpt = Annotated[Optional[Path], typer.Option("--plot", help="Write a PNG plot.")]


def _parse_inputs(items: list[str]) -> dict[str, np.ndarray]:
    from mechsyn.kinematics.analysis import input_grid

    out: dict[str, np.ndarray] = {}
    for item in items:
        if "=" not in item:
            raise MechsynInputError(f"expected J=START:STOP:STEP, got {item!r}", source="--input",
                                    hint="write e.g. --input A=0:360:1")
        jid, spec = item.split("=", 1)
        jid = jid.strip()
        if ":" in spec:
            start, stop, step = parse_range(spec, "--input", f"{jid}=0:360:1")
            vals = input_grid(start, stop, step)
        else:
            try:
                vals = np.array([float(v) for v in spec.split(",") if v.strip()])
            except ValueError:
                raise MechsynInputError(f"expected numbers for {jid}, got {spec!r}", source="--input",
                                        hint="write e.g. --input A=0:360:1 or --input A=10,20,30") from None
        if jid in out:
            raise MechsynInputError(f"joint {jid} given twice", source="--input")
        if len(vals) > 2_000_000:
            raise MechsynInputError(f"{len(vals)} input values are too many", source="--input",
                                    hint="use a larger step")
        out[jid] = vals
    return out


def _parse_pairs(items: list[str] | None, option: str, number: bool) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for item in items or []:
        if "=" not in item:
            raise MechsynInputError(f"expected J=VALUE, got {item!r}", source=option)
        k, v = item.split("=", 1)
        if number:
            try:
                out[k.strip()] = float(v)
            except ValueError:
                raise MechsynInputError(f"expected a number for {k}, got {v!r}", source=option) from None
        else:
            out[k.strip()] = v.strip().lower()
    return out


def _fmt(v: float) -> str:
    return fmt_number(v)


def _table_rows(n: int, max_rows: int = 25) -> list[int]:
    if n <= max_rows:
        return list(range(n))
    return sorted(set(np.linspace(0, n - 1, max_rows).astype(int).tolist()))


def _say_rows_shown(shown: int, total: int) -> None:
    """Say when the tables show a subset of the positions, and how to see them all."""
    if shown < total:
        console.print(f"(tables show {shown} of {total} positions, evenly spaced; all of them with --json "
                      "or --csv FILE)", highlight=False)


def _csv_text(header: list[str], columns: list[np.ndarray]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for row in zip(*columns):
        w.writerow(["" if (isinstance(v, float) and not np.isfinite(v)) else
                    (repr(float(v)) if isinstance(v, (float, np.floating)) else v) for v in row])
    return buf.getvalue()


@app.command("simulate")
def simulate_cmd(
    file: Annotated[Path, typer.Argument(help="Mechanism file (YAML or JSON) with joint points.")],
    input: InputOpt,
    points: Annotated[Optional[str], typer.Option("--points", help="Points to report: names from "
                                                  "`points:` or joint ids, comma-separated.")] = None,
    speed: SpeedOpt = None,
    vll: VllOpt = None,
    method: MethodOpt = "auto",
    output: Annotated[Optional[str], typer.Option("--output", help="Output link for the mechanical "
                                                  "advantage (default: the last link pivoted on the frame).")] = None,
    straight: Annotated[Optional[list[str]], typer.Option(
        "--straight", help="Straightness of a path segment: P=START:STOP (input values).")] = None,
    json_: JsonOpt = False,
    csv_out: CsvOpt = None,
    plot: PlotOpt = None,
    animate: Annotated[Optional[Path], typer.Option("--animate", help="Write an animation: .gif, .mp4 (the video extra) or .html (a self-contained player).")] = None,
) -> None:
    """Positions, velocities and accelerations of a planar mechanism over its input."""
    from mechsyn.kinematics import derived
    from mechsyn.kinematics.analysis import simulate

    check_output_suffix(plot, (".png", ".pdf", ".svg"), "--plot")
    if animate is not None:
        check_animation_target(animate)
    check_output_suffix(csv_out, (".csv",), "--csv")
    one_stdout(json_, csv_out)
    if method not in ("auto", "assur", "newton"):
        raise MechsynInputError(f"unknown method {method!r}", source="--method", hint="auto, assur or newton")
    mech = load_mechanism(file)
    inputs = _parse_inputs(input)
    speeds = _parse_pairs(speed, "--speed", True)
    modes = _parse_pairs(vll, "--vll", False)
    names = [p.strip() for p in points.split(",") if p.strip()] if points else None
    n = len(next(iter(inputs.values())))
    with progress_bar("simulating", n, enabled=n >= 200) as advance:
        sim = simulate(mech, inputs, speeds=speeds, points=names, vll=modes, method=method, progress=advance)
    out = sim.to_dict()
    derived_d: dict[str, Any] = {}
    mu = derived.transmission_angles(sim)
    if mu:
        derived_d["transmission_angle"] = {
            k: {"values": [None if not np.isfinite(x) else float(x) for x in v],
                "min": _nanf(np.nanmin, v), "max": _nanf(np.nanmax, v)} for k, v in mu.items()}
    out_link = output or derived.default_output_link(mech, list(inputs))
    if out_link is not None and len(inputs) == 1:
        ma = derived.mechanical_advantage(sim, out_link)
        derived_d["mechanical_advantage"] = {"output": out_link,
                                             "values": [None if not np.isfinite(x) else float(x) for x in ma]}
    if len(mech.links) == 4 and len(mech.joints) == 4 and all(j.type == "R" for j in mech.joints):
        derived_d["grashof"] = to_jsonable(derived.grashof(mech))
    derived_d["extent"] = {name: derived.path_extent(pm.position) for name, pm in sim.points.items()}
    for item in straight or []:
        if "=" not in item or item.count(":") != 1:
            raise MechsynInputError(f"expected P=START:STOP, got {item!r}", source="--straight")
        pname, rng = item.split("=", 1)
        if pname not in sim.points:
            raise MechsynInputError(f"no reported point {pname!r}", source="--straight",
                                    hint=f"points: {', '.join(sim.points)}")
        try:
            a, b = (float(x) for x in rng.split(":"))
        except ValueError:
            raise MechsynInputError(f"expected numbers in {rng!r}", source="--straight") from None
        x = sim.inputs[sim.main_input]
        sel = (x >= min(a, b)) & (x <= max(a, b))
        derived_d.setdefault("straightness", {})[pname] = {
            "range": [a, b], **derived.straightness(sim.points[pname].position[sel])}
    out["derived"] = derived_d
    if csv_out is not None:
        header, cols = [f"input_{j}" for j in sim.inputs], [sim.inputs[j] for j in sim.inputs]
        header.append("assembled")
        cols.append(sim.assembled.astype(int))
        for name, pm in sim.points.items():
            for key, arr in (("", pm.position), ("v", pm.velocity), ("a", pm.acceleration)):
                header += [f"{name}_{key}x", f"{name}_{key}y"]
                cols += [arr[:, 0], arr[:, 1]]
        for name, lm in sim.links.items():
            header += [f"{name}_angle", f"{name}_omega", f"{name}_alpha"]
            cols += [lm.angle, lm.angular_velocity, lm.angular_acceleration]
        write_output(csv_out, _csv_text(header, cols))
    if plot is not None:
        from mechsyn.plot.kinematics import plot_simulation
        save_plot(plot, plot_simulation, sim)
    if animate is not None:
        from mechsyn.plot.kinematics import animate_simulation
        save_animation(animate, animate_simulation, sim, dpi=100)
    if is_stdout(csv_out):
        return
    if json_:
        emit_json(out)
        return
    _render_simulation(sim, derived_d)


def _nanf(f, v):
    v = np.asarray(v, float)
    return None if not np.isfinite(v).any() else float(f(v))


def _render_simulation(sim, derived_d: dict) -> None:
    main = sim.main_input
    x = sim.inputs[main]
    unit = "deg" if sim.input_types[main] == "R" else ""
    rows = _table_rows(len(x))
    console.print(f"[bold]{escape(sim.mechanism)}[/]: {len(x)} input values, {int(sim.assembled.sum())} assembled "
                  f"(method: {sim.method})", highlight=False)
    for name, pm in sim.points.items():
        t = Table(title=f"point {name} (on {pm.link})")
        for col in (f"{main} {unit}".strip(), "x", "y", "vx", "vy", "ax", "ay"):
            t.add_column(col, justify="right")
        for k in rows:
            if not sim.assembled[k]:
                t.add_row(f"{x[k]:g}", "not assembled", *[""] * 5)
                continue
            t.add_row(f"{x[k]:g}", *(_fmt(v) for v in (*pm.position[k], *pm.velocity[k], *pm.acceleration[k])))
        console.print(t)
    t = Table(title="links: angle (deg), angular velocity (rad/s), angular acceleration (rad/s²)")
    t.add_column(f"{main} {unit}".strip(), justify="right")
    names = list(sim.links)[:4]
    for name in names:
        t.add_column(f"{name} θ, ω, α", justify="right")
    for k in rows:
        t.add_row(f"{x[k]:g}", *(("—" if not sim.assembled[k] else
                                  f"{sim.links[n].angle[k]:.4f}, {_fmt(sim.links[n].angular_velocity[k])}, "
                                  f"{_fmt(sim.links[n].angular_acceleration[k])}") for n in names))
    console.print(t)
    if len(sim.links) > 4:
        console.print(f"({len(sim.links) - 4} more links in --json / --csv)", highlight=False)
    _say_rows_shown(len(rows), len(x))
    for r in sim.working_ranges():
        console.print(f"working range of {main}: {r[0]:g} .. {r[1]:g} {unit}", highlight=False)
    for e in sim.events:
        where = ", ".join(f"{k} = {v:.6g}" for k, v in e["input"].items()) if isinstance(e.get("input"), dict) else ""
        console.print(f"[yellow]{e['kind']}[/] {where}: {escape(e['message'])}", highlight=False)
    for note in sim.notes:
        console.print(f"note: {escape(note)}", highlight=False)
    if "grashof" in derived_d:
        g = derived_d["grashof"]
        console.print(f"Grashof: {g['expression']} → {g['classification']}", highlight=False)
    for k, v in derived_d.get("transmission_angle", {}).items():
        console.print(f"transmission angle of dyad {k}: {_fmt(v['min'])} .. {_fmt(v['max'])} deg", highlight=False)
    for name, e in derived_d.get("extent", {}).items():
        if e["width"] is not None:
            size = max(abs(e[k]) for k in ("x_min", "x_max", "y_min", "y_max"))  # noise: below 1e-12 of it
            x0, x1, y0, y1, w, h = (fmt_number(e[k], scale=size) for k in ("x_min", "x_max", "y_min", "y_max",
                                                                          "width", "height"))
            console.print(f"path of {name}: x {x0} .. {x1}, y {y0} .. {y1} (width {w}, height {h})", highlight=False)
    for name, s in derived_d.get("straightness", {}).items():
        console.print(f"straightness of {name} over {s['range'][0]:g}..{s['range'][1]:g}: largest deviation "
                      f"{s['max_deviation']:.6g} over a length {s['length']:.6g}", highlight=False)


@app.command("forces")
def forces_cmd(
    file: Annotated[Path, typer.Argument(help="Mechanism file with joint points, masses and loads.")],
    input: InputOpt,
    speed: SpeedOpt = None,
    vll: VllOpt = None,
    gravity: Annotated[float, typer.Option("--gravity", help="Gravity acceleration along -y (e.g. 9.81).")] = 0.0,
    static: Annotated[bool, typer.Option("--static", help="Static case: no inertia loads.")] = False,
    method: MethodOpt = "auto",
    json_: JsonOpt = False,
    csv_out: CsvOpt = None,
    plot: PlotOpt = None,
) -> None:
    """Joint reactions and the balancing moment/force at each driven joint over the input."""
    from mechsyn.kinematics.analysis import forces

    check_output_suffix(plot, (".png", ".pdf", ".svg"), "--plot")
    check_output_suffix(csv_out, (".csv",), "--csv")
    one_stdout(json_, csv_out)
    if not np.isfinite(gravity):
        raise MechsynInputError("gravity must be a finite number", source="--gravity")
    mech = load_mechanism(file)
    inputs = _parse_inputs(input)
    n = len(next(iter(inputs.values())))
    with progress_bar("force analysis", n, enabled=n >= 200) as advance:
        fa = forces(mech, inputs, speeds=_parse_pairs(speed, "--speed", True), gravity=(0.0, -gravity),
                    static=static, vll=_parse_pairs(vll, "--vll", False), method=method, progress=advance)
    sim = fa.simulation
    R = fa.reactions
    if csv_out is not None:
        header, cols = [f"input_{j}" for j in sim.inputs], [sim.inputs[j] for j in sim.inputs]
        header.append("assembled")
        cols.append(sim.assembled.astype(int))
        for j, F in R.force.items():
            header += [f"{j}_Fx", f"{j}_Fy", f"{j}_F", f"{j}_M"]
            cols += [F[:, 0], F[:, 1], np.linalg.norm(F, axis=1), R.moment[j]]
        for j, e in R.effort.items():
            header.append(f"drive_{j}_{R.effort_kind[j]}")
            cols.append(e)
        write_output(csv_out, _csv_text(header, cols))
    if plot is not None:
        from mechsyn.plot.kinematics import plot_forces
        save_plot(plot, plot_forces, fa)
    if is_stdout(csv_out):
        return
    if json_:
        emit_json(fa.to_dict())
        return
    main = sim.main_input
    x = sim.inputs[main]
    rows = _table_rows(len(x))
    kind = "static" if static else "kinetostatic"
    console.print(f"[bold]{escape(sim.mechanism)}[/]: {kind} analysis, gravity {gravity:g} along -y, "
                  f"{int(sim.assembled.sum())} of {len(x)} inputs assembled", highlight=False)
    joints = list(R.force)
    per_input = joints if len(joints) <= 5 else []
    t = Table(title="balancing efforts at the drives" + (" and reactions |F| (on each joint's second link)"
                                                         if per_input else ""))
    t.add_column(main, justify="right")
    for j in R.effort:
        t.add_column(f"{R.effort_kind[j]} at {j}", justify="right")
    for j in per_input:
        t.add_column(f"|F_{j}|", justify="right")
    for k in rows:
        row = [f"{x[k]:g}"] + [_fmt(float(e[k])) for e in R.effort.values()]
        row += [_fmt(float(np.linalg.norm(R.force[j][k]))) for j in per_input]
        t.add_row(*row)
    console.print(t)
    _say_rows_shown(len(rows), len(x))
    mech_joints = {j.id: j for j in sim.system.mech.joints}
    t = Table(title="joint reactions over the sweep (force of the first link on the second)")
    for col in ("joint", "links", "max |F|", f"at {main}", "min |F|", "max |M|"):
        t.add_column(col, justify="left" if col in ("joint", "links") else "right")
    for j in joints:
        mag = np.linalg.norm(R.force[j], axis=1)
        if not np.isfinite(mag).any():
            t.add_row(j, " - ".join(mech_joints[j].links), "—", "—", "—", "—")
            continue
        k = int(np.nanargmax(mag))
        t.add_row(j, " → ".join(mech_joints[j].links), _fmt(float(mag[k])), f"{x[k]:g}",
                  _fmt(float(np.nanmin(mag))), _fmt(float(np.nanmax(np.abs(R.moment[j])))))
    console.print(t)
    if R.indeterminate:
        console.print("[yellow]note:[/] redundant constraints: the reactions are statically indeterminate; "
                      "minimum-norm values shown", highlight=False)
    for note in fa.notes():
        console.print(f"[yellow]note:[/] {escape(note)}", highlight=False)
    for e in sim.events:
        where = ", ".join(f"{k} = {v:.6g}" for k, v in e["input"].items()) if isinstance(e.get("input"), dict) else ""
        console.print(f"[yellow]{e['kind']}[/] {where}: {escape(e['message'])}", highlight=False)
