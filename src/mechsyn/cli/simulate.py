"""``mechsyn simulate FILE`` (planar kinematics) and ``mechsyn forces FILE`` (kinetostatics).

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any, Optional

import numpy as np
import typer
from mechsyn.cli.app import app
from mechsyn.cli.common import (check_animation_target, check_output_suffix, emit_json, is_stdout, one_stdout,
                                parse_range, progress_bar, save_animation, save_plot, write_output)
from mechsyn.errors import MechsynInputError, OverActuatedError
from mechsyn.io import load_mechanism

InputOpt = Annotated[list[str], typer.Option(
    "--input", "-i", metavar="J=A:B:S", help="Driven joint and its values: J=START:STOP:STEP or J=V1,V2,... "
                          "R, H: deg (planar: the driven link's angle; spatial: from the joint's zero, else from the "
                          "drawn pose); P: length. Spatial C: J= slide, J/turn= angle; U: J=, J/2= angles. Repeat "
                          "for several inputs (same number of values).")]
SpeedOpt = Annotated[Optional[list[str]], typer.Option(
    "--speed", metavar="J=V", help="Input rate J=V (rad/s for R, length/s for P; default 1).")]
VllOpt = Annotated[Optional[list[str]], typer.Option(
    "--vll", metavar="J=MODE", help="Variable-length link mode J=locked|free|active (paper 000's two modes).")]
MethodOpt = Annotated[str, typer.Option(
    "--method", help="auto | assur | an engine: regular-pass, tracked-chain, tracked-groups, newton, spatial "
                     "(a planar file of R and P pairs in 3-D)")]
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


@contextmanager
def _over_actuation_in_cli_words(inputs: dict[str, np.ndarray]):
    """The library's over-actuation error with the command line's fix: ``--input`` for the
    drive in excess, or drop its ``actuated: true``."""
    try:
        yield
    except OverActuatedError as err:
        held = ", ".join(d for d in err.check.excess if d not in inputs)
        raise MechsynInputError(err.check.text(f"give --input for {held} or drop `actuated: true` on {held}"),
                                source=err.source) from None


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


def _parse_straight(items: list[str] | None) -> dict[str, tuple[float, float]]:
    out: dict[str, tuple[float, float]] = {}
    for item in items or []:
        if "=" not in item or item.count(":") != 1:
            raise MechsynInputError(f"expected P=START:STOP, got {item!r}", source="--straight")
        pname, rng = item.split("=", 1)
        try:
            a, b = (float(x) for x in rng.split(":"))
        except ValueError:
            raise MechsynInputError(f"expected numbers in {rng!r}", source="--straight") from None
        out[pname] = (a, b)
    return out


def _check_outputs(plot: Path | None, csv_out: Path | None, json_: bool, animate: Path | None = None,
                   method: str = "auto") -> None:
    _check_method(method)
    check_output_suffix(plot, (".png", ".pdf", ".svg"), "--plot")
    if animate is not None:
        check_animation_target(animate)
    check_output_suffix(csv_out, (".csv",), "--csv")
    one_stdout(json_, csv_out)


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
        "--straight", metavar="P=A:B", help="Straightness of a path segment: P=START:STOP (input values).")] = None,
    json_: JsonOpt = False,
    csv_out: CsvOpt = None,
    plot: PlotOpt = None,
    animate: Annotated[Optional[Path], typer.Option("--animate", help="Write an animation: .gif, .mp4 (the video extra) or .html (a self-contained player).")] = None,
) -> None:
    """Positions, velocities and accelerations (spatial files: link poses, joint values) over the inputs."""
    from mechsyn.cli.render import render_simulation
    from mechsyn.kinematics.report import simulation_report

    _check_outputs(plot, csv_out, json_, animate, method)
    mech, inputs = load_mechanism(file), _parse_inputs(input)
    names = [p.strip() for p in points.split(",") if p.strip()] if points else None
    if mech.kind == "spatial" or method == "spatial":  # the spatial engine's result renders itself
        _planar_only(file, mech.kind, vll=vll, method=method not in ("auto", "spatial"), output=output,
                     straight=straight)
        return _simulate_spatial(mech, inputs, names, speed, json_, csv_out, plot, animate, method)
    with (_over_actuation_in_cli_words(inputs),
          progress_bar("simulating", n := len(next(iter(inputs.values()))), enabled=n >= 200) as progress):
        report = simulation_report(mech, inputs, speeds=_parse_pairs(speed, "--speed", True), points=names,
                                   vll=_parse_pairs(vll, "--vll", False), method=method, output=output,
                                   straight=_parse_straight(straight), progress=progress)
    _write_simulation_files(report.simulation, csv_out, plot, animate)
    if is_stdout(csv_out):
        return
    if json_:
        emit_json(report.to_dict())
        return
    render_simulation(report)


def _planar_only(file: Path, kind: str, **given: Any) -> None:
    """Refuse the options that only planar files take (exit 2) on a spatial file, naming them."""
    bad = [f"--{k}" for k, v in given.items() if v] if kind == "spatial" else []
    if bad:
        raise MechsynInputError(f"{', '.join(bad)} applies to planar files only; {file} is spatial", source=bad[0],
                                hint=f"remove {', '.join(bad)}")


def _check_method(method: str) -> None:
    """``--method``: auto, assur or the name of an engine."""
    if method in ("auto", "assur"):
        return
    from mechsyn.kinematics.engines import engine_named

    try:
        engine_named(method)
    except MechsynInputError as exc:
        raise MechsynInputError(exc.message, source="--method", hint=exc.hint) from None


def _simulate_spatial(mech: Any, inputs: dict[str, np.ndarray], names: list[str] | None, speed: list[str] | None,
                      json_: bool, csv_out: Optional[Path], plot: Optional[Path], animate: Optional[Path],
                      method: str = "auto") -> None:
    """``mechsyn simulate`` on a spatial file: one call of the spatial engine, its result's own
    summary, events and table (``--json``: its ``to_dict()``)."""
    import shutil
    import textwrap

    from mechsyn.kinematics.analysis import simulate
    from mechsyn.plot.spatial import animate_spatial, plot_spatial

    n = len(next(iter(inputs.values())))
    with progress_bar("simulating", n, enabled=n >= 200) as progress:
        sim = simulate(mech, inputs, speeds=_parse_pairs(speed, "--speed", True), points=names, progress=progress,
                       method=method)
    if csv_out is not None:
        write_output(csv_out, sim.csv())
    if plot is not None:
        save_plot(plot, plot_spatial, sim)
    if animate is not None:
        save_animation(animate, animate_spatial, sim, dpi=100)
    if is_stdout(csv_out):
        return
    if json_:
        emit_json(sim.to_dict())
        return
    width = shutil.get_terminal_size().columns
    lines = str(sim).splitlines() + [f"{e['kind']} at {', '.join(f'{j} = {v:.10g}' for j, v in e['input'].items())}: "
                                     f"{e['message']}" for e in sim.events]
    for line in lines:
        typer.echo(textwrap.fill(line, width, subsequent_indent=" " * 13))
    typer.echo(sim.table(width=width))


def _write_simulation_files(sim, csv_out: Optional[Path], plot: Optional[Path], animate: Optional[Path]) -> None:
    if plot is not None:  # (first: a range where nothing assembles is refused before any file is written)
        from mechsyn.plot.kinematics import plot_simulation

        save_plot(plot, plot_simulation, sim)
    if animate is not None:
        from mechsyn.plot.kinematics import animate_simulation

        save_animation(animate, animate_simulation, sim, dpi=100)
    if csv_out is not None:
        write_output(csv_out, sim.csv())


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
    from mechsyn.cli.render import render_forces
    from mechsyn.kinetostatics import forces

    _check_outputs(plot, csv_out, json_)
    if not np.isfinite(gravity):
        raise MechsynInputError("gravity must be a finite number", source="--gravity")
    mech = load_mechanism(file)
    inputs = _parse_inputs(input)
    n = len(next(iter(inputs.values())))
    with _over_actuation_in_cli_words(inputs), progress_bar("force analysis", n, enabled=n >= 200) as progress:
        fa = forces(mech, inputs, speeds=_parse_pairs(speed, "--speed", True), gravity=(0.0, -gravity),
                    static=static, vll=_parse_pairs(vll, "--vll", False), method=method, progress=progress)
    if plot is not None:  # (first: nothing assembled is refused before any file is written)
        from mechsyn.plot.kinematics import plot_forces
        save_plot(plot, plot_forces, fa)
    if csv_out is not None:
        write_output(csv_out, fa.csv())
    if is_stdout(csv_out):
        return
    if json_:
        emit_json(fa.to_dict())
        return
    render_forces(fa)
