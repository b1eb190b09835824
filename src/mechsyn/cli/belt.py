"""``mechsyn belt ...``: paper 001's manipulator with a belt on a pulley.

Thin layer over :mod:`mechsyn.belt`: each command parses its options, makes one library
call (:func:`~mechsyn.belt.synthesize_belt`, :func:`~mechsyn.belt.analyze_case`,
:func:`~mechsyn.belt.inverse_input`) and renders the result (``--json``: its ``to_dict()``).
Angles in degrees on the command line; lengths in the user's unit (mm in the paper).

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Any, Optional

import numpy as np
import typer

from mechsyn.belt.case_file import BeltCase, MotionSpec, load_belt_case, motion_law, read_motion_table
from mechsyn.belt.design import BeltDesign
from mechsyn.belt.kinematics import InverseResult, MotionLaw, analyze, inverse_input
from mechsyn.belt.report import BeltReport, analyze_case, phi_range
from mechsyn.belt.synthesis import BeltSynthesis, synthesize_belt
from mechsyn.cli.app import app
from mechsyn.cli.common import Table  # cells fold, numbers never cut
from mechsyn.cli.common import check_animation_target, console, emit_json, is_stdout, one_stdout, parse_floats, parse_range, write_output
from mechsyn.errors import MechsynInputError

belt_app = typer.Typer(
    help="Paper 001's manipulator with a flexible element (belt on a pulley): synthesis, "
         "transfer functions, paths, speeds, accelerations, the inverse problem.",
    no_args_is_help=True,
)
app.add_typer(belt_app, name="belt")

#: library parameters (``MechsynInputError.field``) -> options of these commands
_OPTIONS = {"phi": "--phi", "r": "--r", "a0": "--a0", "h0": "--h0", "hf": "--hf", "a": "--a0",
            "segment": "--segment", "tol": "--tol", "samples": "--samples", "speed": "--speed",
            "point": "--point"}


# ----------------------------------------------------------------------- parsing
def _point(text: str, option: str) -> tuple[float, float]:
    x, y = parse_floats(text, option, count=2)
    if not (math.isfinite(x) and math.isfinite(y)):
        raise MechsynInputError(f"expected finite numbers, got {text!r}", source=option)
    return x, y


def _number(value: float | None, name: str, positive: bool = False) -> float | None:
    if value is None:
        return None
    if not math.isfinite(value):
        raise MechsynInputError(f"must be a finite number, got {value!r}", source=name)
    if positive and value <= 0:
        raise MechsynInputError(f"must be positive, got {value:g}", source=name)
    return value


def _design(a: float | None, c: float | None, h: float | None, r: float | None,
            case: BeltCase | None, source: str | None
            ) -> tuple[BeltDesign, BeltSynthesis | None]:
    """The dimensions from the options, over those of the case file (its design or its
    synthesis data), and the synthesis when the file gives one."""
    synth: BeltSynthesis | None = None
    base: dict[str, float] = {}
    if case is not None and case.design is not None:
        base = case.design.model_dump()
    elif case is not None and case.synthesis is not None:
        s = case.synthesis
        try:
            synth = synthesize_belt(s.h0, s.hf, math.radians(s.phi_of_deg), s.r, A0=s.a0)
        except MechsynInputError as exc:
            raise exc.with_source(source or "file") from None
        base = {"a": synth.design.a, "c": synth.design.c, "h": synth.design.h,
                "r": synth.design.r}
    given = {"a": a, "c": c, "h": h, "r": r}
    for k, v in given.items():
        _number(v, f"--{k}", positive=k != "h")
        if v is not None:
            base[k] = v
    missing = [k for k in ("a", "c", "h", "r") if k not in base]
    if missing:
        raise MechsynInputError(
            "missing dimension(s): " + ", ".join(f"--{k}" for k in missing),
            hint="give --a --c --h --r, or --file examples/belt/paper001.yaml")
    try:
        return BeltDesign(**{k: float(base[k]) for k in ("a", "c", "h", "r")}), synth
    except MechsynInputError as exc:
        raise MechsynInputError(exc.message, source=f"--{exc.field}" if exc.field else None,
                                hint=exc.hint) from None


def _law(law: str, dphi: np.ndarray, omega: float | None, omega_max: float | None,
         accel: float | None, table: Path | None, case: BeltCase | None) -> MotionLaw:
    """The input law from the options, over the case file's ``motion`` block."""
    spec = case.motion if case is not None and case.motion is not None else MotionSpec()
    for value, option in ((omega, "--omega"), (omega_max, "--omega-max"), (accel, "--accel")):
        _number(value, option, positive=True)
    t, phi, src = spec.t, spec.phi_deg, "motion"
    if table is not None:
        (t, phi), src = read_motion_table(table), str(table)
    pick = lambda given, filed: given if given is not None else filed  # noqa: E731
    try:
        return motion_law(law or spec.law, dphi, omega_deg_s=pick(omega, spec.omega_deg_s),
                          omega_max_deg_s=pick(omega_max, spec.omega_max_deg_s),
                          accel_deg_s2=pick(accel, spec.accel_deg_s2), t=t, phi_deg=phi)
    except MechsynInputError as exc:
        if exc.field is not None and exc.field.startswith("table"):
            raise exc.with_source(src if t is not None else "--table") from None
        if exc.field in ("omega_max_deg_s", "accel_deg_s2"):
            raise MechsynInputError("the trapezoidal law needs --omega-max and --accel", source="--law") from None
        raise MechsynInputError(exc.message, source="--law", hint=exc.hint) from None


def _lib(call: Any, *args: Any, **kwargs: Any) -> Any:
    """A library call whose input errors name this command's options."""
    try:
        return call(*args, **kwargs)
    except MechsynInputError as exc:
        if exc.source is None and exc.field in _OPTIONS:
            raise MechsynInputError(exc.message, source=_OPTIONS[exc.field], hint=exc.hint) from None
        raise


def _dphi(phi: str | None, case: BeltCase | None, file: Path | None) -> np.ndarray:
    """Δφ (rad) from --phi, else from the case file's phi_deg."""
    if phi is not None:
        return _lib(phi_range, *parse_range(phi, "--phi", "-73:85:1"))
    if case is not None and case.phi_deg is not None:
        try:
            return phi_range(case.phi_deg.start, case.phi_deg.stop, case.phi_deg.step)
        except MechsynInputError as exc:
            raise exc.with_source(f"{file}: phi_deg") from None
    raise MechsynInputError("missing the range of Δφ", source="--phi", hint="e.g. --phi -73:85:1")


def _analysis_inputs(file: Path | None, dims: tuple[float | None, ...], phi: str | None,
                     segment: str | None, tol: float | None, law_args: tuple[Any, ...]
                     ) -> tuple[tuple[Any, ...], dict[str, Any]]:
    """Parse ``belt analyze``'s options (over the case file's values) into the arguments of
    :func:`mechsyn.belt.analyze_case`."""
    case = load_belt_case(str(file)) if file is not None else None
    design, synth = _design(*dims, case, str(file) if file else None)
    dphi = _dphi(phi, case, file)
    seg = None
    if segment is not None:
        seg = tuple(math.radians(v) for v in parse_floats(segment.replace(":", ","), "--segment", count=2))
    elif case is not None and case.paths.segment_deg is not None:
        seg = tuple(math.radians(v) for v in case.paths.segment_deg)
    tol_deg = tol if tol is not None else (case.paths.translation_tol_deg if case else 3.0)
    _number(tol_deg, "--tol", positive=True)
    kwargs = {"synthesis": synth, "segment": seg, "translation_tol": math.radians(tol_deg),
              "law": _law(law_args[0] or "", dphi, *law_args[1:], case),
              "name": case.name if case else "belt manipulator"}
    return (design, dphi), kwargs


def _write_mechanism(path: Path, data: dict[str, Any]) -> None:
    """Validate a mechanism-file dict against the format, then write it whole."""
    from mechsyn.io import mechanism_from_dict, write_mechanism

    mechanism_from_dict(data)
    write_mechanism(data, path)


def _write_files(rep: BeltReport, csv_out: Path | None, plot: Path | None, animate: Path | None,
                 four_bar_file: Path | None, mechanism_file: Path | None) -> None:
    """The output files of ``belt analyze`` (each written whole or not at all)."""
    from mechsyn.belt.four_bar import belt_mechanism_dict, four_bar_mechanism_dict

    if csv_out is not None:
        write_output(csv_out, _csv_text(rep))
    if plot is not None:
        from mechsyn.cli.common import save_plot
        from mechsyn.plot.belt import plot_belt

        save_plot(plot, plot_belt, rep.design, rep.state, rep.four_bar, rep.motion, title=rep.name, dpi=100)
    if four_bar_file is not None:
        _write_mechanism(four_bar_file, four_bar_mechanism_dict(rep.design))
    if mechanism_file is not None:
        _write_mechanism(mechanism_file, belt_mechanism_dict(rep.design))
    if animate is not None:
        from mechsyn.cli.common import save_animation
        from mechsyn.plot.belt import animate_belt

        save_animation(animate, animate_belt, rep.design, rep.state, title=rep.name, fps=20)


CSV_COLUMNS = ["dphi_deg", "dpsi_deg", "beta_deg", "theta_deg", "b", "d", "psi1", "psi2",
               "xC", "yC", "xH", "yH", "xC1", "yC1", "xC2", "yC2", "xH1", "yH1", "xH2", "yH2"]


def _csv(header: list[str], columns: list[np.ndarray]) -> str:
    """CSV text: one row per position, full precision, empty cells where undefined."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for row in np.column_stack(columns):
        w.writerow(["" if not math.isfinite(v) else repr(float(v)) for v in row])
    return buf.getvalue()


def _csv_text(rep: BeltReport) -> str:
    s = rep.state
    deg = np.degrees
    return _csv(CSV_COLUMNS, [deg(s.dphi), deg(s.dpsi), deg(s.beta), deg(s.theta), s.b, s.d, s.psi1,
                              s.psi2, s.C, s.H, s.C1, s.C2, s.H1, s.H2])


# ----------------------------------------------------------------------- rendering
def _table(t: Any, rows: list[int] | None = None) -> Table:
    """A report's :class:`mechsyn.belt.report.Table` as a rich Table (``rows``: those shown)."""
    out = Table(title=t.title, caption=t.caption or None)
    for i, col in enumerate(t.columns):
        out.add_column(col, justify="left" if i == 0 and t.labels else "right")
    for k in range(len(t.rows)) if rows is None else rows:
        out.add_row(*t.rows[k])
    return out


def _render_belt(rep: BeltReport) -> None:
    """``belt analyze``'s tables on the console; the tables by position show at most 25
    evenly spaced positions (all of them with --json or --csv), as ``simulate`` does."""
    from mechsyn.cli.render import say_rows_shown, table_rows

    console.print(f"[bold]{rep.headline()}[/]")
    for w in rep.warnings:
        console.print(f"[yellow]warning:[/] {w}")
    n = rep.state.dphi.size
    rows = table_rows(n)
    for t in rep.tables():
        console.print(_table(t, rows if len(t.rows) == n else None))
    say_rows_shown(len(rows), n)
    console.print(rep.motion_line())


def _render_synthesis(res: BeltSynthesis) -> None:
    console.print(_table(res.table()))
    for k, ok in res.checks.items():
        console.print(f"  [{'green' if ok else 'yellow'}]{'ok ' if ok else 'NO '}[/] {k}")
    for note in res.notes:
        console.print(f"  note: {note}")
    if not res.feasible:
        console.print(f"[yellow]not feasible:[/] {res.reason}")


def _render_inverse(res: InverseResult, speed: float, accel: float) -> None:
    t = Table(title=f"servo input for {res.point} at speed {speed:g}, tangential accel {accel:g}")
    for col in ("Δφ°", "t (s)", "φ̇ (°/s)", "φ̈ (°/s²)"):
        t.add_column(col, justify="right")
    for i in range(res.dphi.size):
        t.add_row(*(f"{v:.{nd}f}" for v, nd in ((math.degrees(res.dphi[i]), 2), (float(res.t[i]), 4),
                                                (math.degrees(res.phid[i]), 3),
                                                (math.degrees(res.phidd[i]), 3))))
    console.print(t)
    d = res.to_dict()
    console.print(f"duration {d['duration']:.4g} s; max |φ̇| {d['max_phid_deg_s']:.4g} °/s, "
                  f"max |φ̈| {d['max_phidd_deg_s2']:.4g} °/s²")


# ----------------------------------------------------------------------- commands
Opt = typer.Option
OptPath = Optional[Path]
OptFloat = Optional[float]
OptStr = Optional[str]


@belt_app.command("synthesize")
def synthesize_cmd(
    h0: str = Opt(..., "--h0", help="design position of H: X,Y"),
    hf: str = Opt(..., "--hf", help="final position of H: X,Y"),
    phi: float = Opt(..., "--phi", help="rotation φ_of of lever 1 from H0 to Hf, deg"),
    r: float = Opt(..., "--r", help="pulley radius"),
    a0: str = Opt("0,0", "--a0", help="base point A0: X,Y (machine frame)"),
    json_out: bool = Opt(False, "--json", help="print JSON"),
) -> None:
    """Synthesise a, c, h (primary chain) and b0, l0, α0 (belt) from the working scene.

    Example: mechsyn belt synthesize --h0 -350,600 --hf 324.62,597.49 --phi -60 --r 75
    """
    H0, Hf, A0 = _point(h0, "--h0"), _point(hf, "--hf"), _point(a0, "--a0")
    _number(phi, "--phi")
    _number(r, "--r", positive=True)
    res = _lib(synthesize_belt, H0, Hf, math.radians(phi), r, A0=A0)
    if json_out:
        emit_json(res)
    else:
        _render_synthesis(res)


@belt_app.command("analyze")
def analyze_cmd(
    file: OptPath = Opt(None, "--file", "-f", help="case file (YAML/JSON), e.g. examples/belt/paper001.yaml"),
    a: OptFloat = Opt(None, "--a", help="lever length |A0 A|"),
    c: OptFloat = Opt(None, "--c", help="x offset of C left of A"),
    h: OptFloat = Opt(None, "--h", help="height of H above C"),
    r: OptFloat = Opt(None, "--r", help="pulley radius"),
    phi: OptStr = Opt(None, "--phi", help="Δφ range START:STOP:STEP, deg"),
    segment: OptStr = Opt(None, "--segment", help="Δφ segment LO:HI (deg) judged for straightness "
                                                   "(default: range start to the design position)"),
    tol: OptFloat = Opt(None, "--tol", help="translation tolerance on θ, deg (default 3)"),
    law: OptStr = Opt(None, "--law", help="input law: constant, trapezoidal, table"),
    omega: OptFloat = Opt(None, "--omega", help="constant input speed, deg/s (60)"),
    omega_max: OptFloat = Opt(None, "--omega-max", help="trapezoidal top speed, deg/s"),
    accel: OptFloat = Opt(None, "--accel", help="trapezoidal acceleration, deg/s²"),
    table: OptPath = Opt(None, "--table", help="table law: CSV of t (s), dphi (deg)"),
    samples: int = Opt(201, "--samples", help="time samples of the motion"),
    json_out: bool = Opt(False, "--json", help="print JSON"),
    csv_out: OptPath = Opt(None, "--csv", help="write the table of positions (- for stdout)"),
    plot: OptPath = Opt(None, "--plot", help="write the figure (PNG/SVG/PDF)"),
    animate: OptPath = Opt(None, "--animate", help="write an animation (.gif, .mp4 or .html)"),
    four_bar_file: OptPath = Opt(None, "--four-bar-file", help="write the equivalent four-bar A0-A-B-B0 "
                                 "as a mechanism file (YAML, or JSON by suffix)"),
    mechanism_file: OptPath = Opt(None, "--mechanism-file", help="write the belt mechanism itself (with a "
                                  "belt pair) as a mechanism file for `mechsyn simulate` (YAML, or JSON by suffix)"),
) -> None:
    """Transfer functions, paths of C and H, path straightness, speeds and accelerations.

    Example: mechsyn belt analyze --a 500 --c 350 --h 100 --r 75 --phi -73:85:1 --json
    """
    args, kwargs = _analysis_inputs(file, (a, c, h, r), phi, segment, tol, (law, omega, omega_max, accel, table))
    one_stdout(json_out, csv_out)
    if animate is not None:
        check_animation_target(animate)
    rep = _lib(analyze_case, *args, samples=samples, **kwargs)
    _write_files(rep, csv_out, plot, animate, four_bar_file, mechanism_file)
    if json_out:
        emit_json(rep)
    elif not is_stdout(csv_out):
        _render_belt(rep)


@belt_app.command("inverse")
def inverse_cmd(
    file: OptPath = Opt(None, "--file", "-f", help="case file (YAML/JSON)"),
    a: OptFloat = Opt(None, "--a", help="lever length |A0 A|"),
    c: OptFloat = Opt(None, "--c", help="x offset of C left of A"),
    h: OptFloat = Opt(None, "--h", help="height of H above C"),
    r: OptFloat = Opt(None, "--r", help="pulley radius"),
    phi: OptStr = Opt(None, "--phi", help="Δφ range START:STOP:STEP, deg, in the direction of the motion"),
    speed: float = Opt(..., "--speed", help="required speed of the point along its path (unit/s)"),
    accel: float = Opt(0.0, "--accel", help="required tangential acceleration (unit/s²)"),
    point: str = Opt("H", "--point", help="H or C"),
    json_out: bool = Opt(False, "--json", help="print JSON"),
    csv_out: OptPath = Opt(None, "--csv", help="write the table (- for stdout)"),
) -> None:
    """Inverse problem: servo input speed and acceleration for a required path speed.

    Example: mechsyn belt inverse --a 500 --c 350 --h 100 --r 75 --phi -73:0:1 --speed 1000
    """
    case = load_belt_case(str(file)) if file is not None else None
    design, _ = _design(a, c, h, r, case, str(file) if file else None)
    _number(speed, "--speed", positive=True)
    _number(accel, "--accel")
    dphi = _dphi(phi, case, file)
    one_stdout(json_out, csv_out)
    res = _lib(inverse_input, analyze(design, dphi), speed, accel, point)
    if csv_out is not None:
        write_output(csv_out, _csv(["dphi_deg", "t", "phid_deg_s", "phidd_deg_s2", "speed", "accel_tangential"],
                                   [np.degrees(res.dphi), res.t, np.degrees(res.phid), np.degrees(res.phidd),
                                    res.speed, res.accel_tangential]))
    if json_out:
        emit_json(res)
    elif not is_stdout(csv_out):
        _render_inverse(res, speed, accel)
