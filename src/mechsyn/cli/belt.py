"""``mechsyn belt ...``: paper 001's manipulator with a belt on a pulley.

Thin layer over :mod:`mechsyn.kinematics.belt` and :mod:`mechsyn.synthesis.belt`.
Angles in degrees on the command line; lengths in the user's unit (mm in the paper).

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012); authors, journal and year are not in the project's copy ("paper 001";
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
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import app
from mechsyn.cli.common import console, emit_json, is_stdout, one_stdout, parse_floats, parse_range, write_output
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics import belt as kb
from mechsyn.synthesis.belt import BeltSynthesis, synthesize_belt

belt_app = typer.Typer(
    help="Paper 001's manipulator with a flexible element (belt on a pulley): synthesis, "
         "transfer functions, paths, speeds, accelerations, the inverse problem.",
    no_args_is_help=True,
)
app.add_typer(belt_app, name="belt")

_MAX_POSITIONS = 200_000


# ----------------------------------------------------------------------- helpers
def _point(text: str, option: str) -> tuple[float, float]:
    x, y = parse_floats(text, option, count=2)
    if not (math.isfinite(x) and math.isfinite(y)):
        raise MechsynInputError(f"expected finite numbers, got {text!r}", source=option)
    return x, y


def _grid(start: float, stop: float, step: float, option: str) -> np.ndarray:
    """Δφ grid in degrees, both ends included."""
    if not all(math.isfinite(v) for v in (start, stop, step)) or step == 0:
        raise MechsynInputError("the range needs finite START:STOP:STEP with STEP != 0",
                                source=option)
    if (stop - start) * step < 0:
        raise MechsynInputError(f"step {step:g} does not lead from {start:g} to {stop:g}",
                                source=option)
    n = int(math.floor((stop - start) / step + 1e-9)) + 1
    if n > _MAX_POSITIONS:
        raise MechsynInputError(f"{n} positions is too many (at most {_MAX_POSITIONS})",
                                source=option, hint="use a larger STEP")
    grid = start + step * np.arange(n)
    if n < 2:
        raise MechsynInputError("the range must hold at least 2 positions", source=option)
    return grid


def _number(value: float | None, name: str, positive: bool = False) -> float | None:
    if value is None:
        return None
    if not math.isfinite(value):
        raise MechsynInputError(f"must be a finite number, got {value!r}", source=name)
    if positive and value <= 0:
        raise MechsynInputError(f"must be positive, got {value:g}", source=name)
    return value


def _design(a: float | None, c: float | None, h: float | None, r: float | None,
            case: kb.BeltCase | None, source: str | None
            ) -> tuple[kb.BeltDesign, BeltSynthesis | None]:
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
        return kb.BeltDesign(**{k: float(base[k]) for k in ("a", "c", "h", "r")}), synth
    except MechsynInputError as exc:
        raise MechsynInputError(exc.message, source=f"--{exc.field}" if exc.field else None,
                                hint=exc.hint) from None


def _read_table(path: Path) -> tuple[list[float], list[float]]:
    """Two columns t (s), Δφ (deg); header and # comments allowed; , ; or blanks."""
    from mechsyn.io.files import read_text

    text = read_text(path, "table")
    t: list[float] = []
    phi: list[float] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.split("#", 1)[0].strip()
        if not s:
            continue
        parts = [p for p in s.replace(";", ",").replace("\t", ",").replace(" ", ",").split(",")
                 if p]
        try:
            vals = [float(p) for p in parts]
        except ValueError:
            if not t:          # a header line
                continue
            raise MechsynInputError(f"expected two numbers, got {line.strip()!r}",
                                    source=str(path), line=lineno) from None
        if len(vals) != 2:
            raise MechsynInputError(f"expected two columns (t, dphi_deg), got {len(vals)}",
                                    source=str(path), line=lineno)
        t.append(vals[0])
        phi.append(vals[1])
    return t, phi


def _law(law: str, grid_deg: np.ndarray, omega: float | None, omega_max: float | None,
         accel: float | None, table: Path | None, case: kb.BeltCase | None) -> kb.MotionLaw:
    spec = case.motion if case is not None else None
    law = law or (spec.law if spec is not None else "constant")
    start, stop = math.radians(grid_deg[0]), math.radians(grid_deg[-1])
    try:
        if law == "constant":
            w = omega if omega is not None else (spec.omega_deg_s if spec and spec.omega_deg_s
                                                 else 60.0)
            _number(w, "--omega", positive=True)
            return kb.ConstantSpeedLaw(start, stop, math.radians(w))
        if law == "trapezoidal":
            wm = omega_max if omega_max is not None else (spec.omega_max_deg_s if spec else None)
            ac = accel if accel is not None else (spec.accel_deg_s2 if spec else None)
            if wm is None or ac is None:
                raise MechsynInputError("the trapezoidal law needs --omega-max and --accel",
                                        source="--law")
            _number(wm, "--omega-max", positive=True)
            _number(ac, "--accel", positive=True)
            return kb.TrapezoidalLaw(start, stop, math.radians(wm), math.radians(ac))
        if law == "table":
            if table is not None:
                t, phi = _read_table(table)
                src = str(table)
            elif spec is not None and spec.t is not None and spec.phi_deg is not None:
                t, phi, src = spec.t, spec.phi_deg, "motion"
            else:
                raise MechsynInputError("the table law needs --table FILE (t, dphi_deg)",
                                        source="--law")
            try:
                return kb.TableLaw(tuple(t), tuple(math.radians(p) for p in phi))
            except MechsynInputError as exc:
                raise exc.with_source(src) from None
    except MechsynInputError as exc:
        if exc.source:
            raise
        raise exc.with_source(f"--{exc.field}" if exc.field else "--law") from None
    raise MechsynInputError(f"unknown law {law!r}", source="--law",
                            hint="constant, trapezoidal or table")


def _fmt(v: Any, nd: int = 3) -> str:
    if v is None:
        return "—"
    if isinstance(v, float) and not math.isfinite(v):
        return "nan"
    return f"{v:.{nd}f}"


CSV_COLUMNS = ["dphi_deg", "dpsi_deg", "beta_deg", "theta_deg", "b", "d", "psi1", "psi2",
               "xC", "yC", "xH", "yH", "xC1", "yC1", "xC2", "yC2", "xH1", "yH1", "xH2", "yH2"]


def _csv_text(state: kb.BeltState) -> str:
    cols = np.column_stack([
        np.degrees(state.dphi), np.degrees(state.dpsi), np.degrees(state.beta),
        np.degrees(state.theta), state.b, state.d, state.psi1, state.psi2,
        state.C, state.H, state.C1, state.C2, state.H1, state.H2,
    ])
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for row in cols:
        w.writerow(["" if not math.isfinite(v) else repr(float(v)) for v in row])
    return buf.getvalue()


# ---------------------------------------------------------------------- synthesize
@belt_app.command("synthesize")
def synthesize_cmd(
    h0: str = typer.Option(..., "--h0", help="design position of H: X,Y"),
    hf: str = typer.Option(..., "--hf", help="final position of H: X,Y"),
    phi: float = typer.Option(..., "--phi", help="rotation φ_of of lever 1 from H0 to Hf, deg"),
    r: float = typer.Option(..., "--r", help="pulley radius"),
    a0: str = typer.Option("0,0", "--a0", help="base point A0: X,Y (machine frame)"),
    json_out: bool = typer.Option(False, "--json", help="print JSON"),
) -> None:
    """Synthesise a, c, h (primary chain) and b0, l0, α0 (belt) from the working scene.

    Example: mechsyn belt synthesize --h0 -350,600 --hf 324.62,597.49 --phi -60 --r 75
    """
    H0, Hf, A0 = _point(h0, "--h0"), _point(hf, "--hf"), _point(a0, "--a0")
    _number(phi, "--phi")
    _number(r, "--r", positive=True)
    try:
        res = synthesize_belt(H0, Hf, math.radians(phi), r, A0=A0)
    except MechsynInputError as exc:
        opt = {"phi": "--phi", "r": "--r", "a0": "--a0", "h0": "--h0", "hf": "--hf",
               "a": "--a0"}.get(exc.field or "", None)
        raise MechsynInputError(exc.message, source=opt, hint=exc.hint) from None
    if json_out:
        emit_json(res)
        return
    d = res.to_dict()
    t = Table(title="belt manipulator synthesis (paper 001), A0's frame")
    t.add_column("quantity")
    t.add_column("value", justify="right")
    for k in ("a", "c", "h", "r", "b0", "l0", "alpha0_deg", "k_m", "min_d_minus_r",
              "Hf_miss"):
        t.add_row(k, _fmt(d[k], 6) if d[k] is not None else "∞")
    for k in ("A", "B0", "H0", "Hf", "Hf1", "M", "H_at_phi_of"):
        t.add_row(k, ", ".join(f"{v:.4f}" for v in d[k]))
    console.print(t)
    for k, ok in res.checks.items():
        console.print(f"  [{'green' if ok else 'yellow'}]{'ok ' if ok else 'NO '}[/] {k}")
    for note in res.notes:
        console.print(f"  note: {note}")


# ------------------------------------------------------------------------- analyze
@belt_app.command("analyze")
def analyze_cmd(
    file: Optional[Path] = typer.Option(
        None, "--file", "-f", help="case file (YAML/JSON), e.g. examples/belt/paper001.yaml"),
    a: Optional[float] = typer.Option(None, "--a", help="lever length |A0 A|"),
    c: Optional[float] = typer.Option(None, "--c", help="x offset of C left of A"),
    h: Optional[float] = typer.Option(None, "--h", help="height of H above C"),
    r: Optional[float] = typer.Option(None, "--r", help="pulley radius"),
    phi: Optional[str] = typer.Option(None, "--phi", help="Δφ range START:STOP:STEP, deg"),
    segment: Optional[str] = typer.Option(
        None, "--segment", help="Δφ segment LO:HI (deg) judged for straightness "
                                "(default: range start to the design position)"),
    tol: Optional[float] = typer.Option(None, "--tol",
                                        help="translation tolerance on θ, deg (default 3)"),
    law: Optional[str] = typer.Option(
        None, "--law", help="input law: constant, trapezoidal, table"),
    omega: Optional[float] = typer.Option(
        None, "--omega", help="constant input speed, deg/s (60)"),
    omega_max: Optional[float] = typer.Option(
        None, "--omega-max", help="trapezoidal top speed, deg/s"),
    accel: Optional[float] = typer.Option(
        None, "--accel", help="trapezoidal acceleration, deg/s²"),
    table: Optional[Path] = typer.Option(
        None, "--table", help="table law: CSV of t (s), dphi (deg)"),
    samples: int = typer.Option(201, "--samples", help="time samples of the motion"),
    json_out: bool = typer.Option(False, "--json", help="print JSON"),
    csv_out: Optional[Path] = typer.Option(None, "--csv", help="write the table of positions (- for stdout)"),
    plot: Optional[Path] = typer.Option(None, "--plot", help="write the figure (PNG/SVG/PDF)"),
    animate: Optional[Path] = typer.Option(None, "--animate", help="write an animation (.gif, .mp4 or .html)"),
    four_bar_file: Optional[Path] = typer.Option(
        None, "--four-bar-file", help="write the equivalent four-bar A0-A-B-B0 as a mechanism "
                                      "file (YAML, or JSON by suffix)"),
    mechanism_file: Optional[Path] = typer.Option(
        None, "--mechanism-file", help="write the belt mechanism itself (with a belt pair) as a "
                                       "mechanism file for `mechsyn simulate` (YAML, or JSON by suffix)"),
) -> None:
    """Transfer functions, paths of C and H, path straightness, speeds and accelerations.

    Example: mechsyn belt analyze --a 500 --c 350 --h 100 --r 75 --phi -73:85:1 --json
    """
    case = kb.load_belt_case(str(file)) if file is not None else None
    design, synth = _design(a, c, h, r, case, str(file) if file else None)
    if phi is not None:
        grid_deg = _grid(*parse_range(phi, "--phi", "-73:85:1"), "--phi")
    elif case is not None and case.phi_deg is not None:
        grid_deg = _grid(case.phi_deg.start, case.phi_deg.stop, case.phi_deg.step,
                         f"{file}: phi_deg")
    else:
        raise MechsynInputError("missing the range of Δφ", source="--phi",
                                hint="e.g. --phi -73:85:1")
    seg = None
    if segment is not None:
        lo_s, hi_s = parse_floats(segment.replace(":", ","), "--segment", count=2)
        seg = (math.radians(lo_s), math.radians(hi_s))
    elif case is not None and case.paths.segment_deg is not None:
        seg = tuple(math.radians(v) for v in case.paths.segment_deg)  # type: ignore[assignment]
    tol_deg = tol if tol is not None else (case.paths.translation_tol_deg if case else 3.0)
    _number(tol_deg, "--tol", positive=True)
    if samples < 2 or samples > _MAX_POSITIONS:
        raise MechsynInputError(f"--samples must be 2..{_MAX_POSITIONS}", source="--samples")

    motion_law = _law(law or "", grid_deg, omega, omega_max, accel, table, case)
    if animate is not None:
        from mechsyn.cli.common import check_animation_target

        check_animation_target(animate)
    dphi = np.radians(grid_deg)
    state = kb.analyze(design, dphi)
    if not np.any(state.valid):
        raise MechsynInputError("the belt is slack or crosses the pulley (d <= r) over the "
                                "whole range", source="--phi", hint="check r and the range")
    rng = (float(dphi.min()), float(dphi.max()))
    try:
        quality = {p: kb.path_quality(design, rng, p, seg, math.radians(tol_deg))
                   for p in ("C", "H")}
    except MechsynInputError as exc:
        raise exc.with_source("--segment" if exc.field == "segment" else "--phi") from None
    four_bar = kb.equivalent_four_bar(design, dphi)
    comparison = kb.compare_with_four_bar(design, rng, math.radians(tol_deg))
    mres = kb.motion(design, motion_law, samples)

    result: dict[str, Any] = {
        "name": case.name if case else "belt manipulator",
        "design": design.to_dict(),
        "b0": design.b0, "l0": design.l0, "alpha0_deg": math.degrees(design.alpha0),
        "B0": design.B0,
        "synthesis": synth,
        "valid_positions": int(np.count_nonzero(state.valid)),
        "rows": state.rows(),
        "paths": quality,
        "four_bar_comparison": comparison,
        "motion": {"law": type(motion_law).__name__, **mres.to_dict()},
    }
    one_stdout(json_out, csv_out)
    if csv_out is not None:
        write_output(csv_out, _csv_text(state))
    if plot is not None:
        from mechsyn.cli.common import save_plot
        from mechsyn.plot.belt import plot_belt

        save_plot(plot, plot_belt, design, state, four_bar, mres, title=result["name"], dpi=100)
    if four_bar_file is not None:
        from mechsyn.io import mechanism_from_dict, write_mechanism

        fb_dict = kb.four_bar_mechanism_dict(design)
        mechanism_from_dict(fb_dict)  # validate against the file format before writing
        write_mechanism(fb_dict, four_bar_file)
    if mechanism_file is not None:
        from mechsyn.io import mechanism_from_dict, write_mechanism

        bm_dict = kb.belt_mechanism_dict(design)
        mechanism_from_dict(bm_dict)  # validate against the file format before writing
        write_mechanism(bm_dict, mechanism_file)
    if animate is not None:
        from mechsyn.cli.common import save_animation
        from mechsyn.plot.belt import animate_belt

        save_animation(animate, animate_belt, design, state, title=result["name"], fps=20)
    if is_stdout(csv_out):
        return
    if json_out:
        emit_json(result)
        return
    _print_analysis(result, state, quality, comparison, mres)


def _print_analysis(result: dict[str, Any], state: kb.BeltState,
                    quality: dict[str, kb.PathQuality], comparison: dict[str, Any],
                    mres: kb.MotionResult) -> None:
    d = result["design"]
    console.print(f"[bold]{result['name']}[/]: a = {d['a']:g}, c = {d['c']:g}, h = {d['h']:g}, "
                  f"r = {d['r']:g}  ->  b0 = {d['b0']:.3f}, l0 = {d['l0']:.3f}, "
                  f"α0 = {d['alpha0_deg']:.3f}°")
    deg = math.degrees
    n_slack = int(np.count_nonzero(~state.valid))
    if n_slack:
        console.print(f"[yellow]warning:[/] at {n_slack} of {state.dphi.size} positions the "
                      "belt is slack or crosses the pulley (d <= r): shown as nan")
    t = Table(title="transfer functions (derivatives w.r.t. Δφ in rad)")
    for col in ("Δφ°", "Δψ°", "β°", "b", "d", "ψ'", "ψ''"):
        t.add_column(col, justify="right")
    p = Table(title="paths of C and H; |C'|, |H'|: speed per unit input speed (rad/s)")
    for col in ("Δφ°", "xC", "yC", "xH", "yH", "|C'|", "|H'|"):
        p.add_column(col, justify="right")
    for i in range(state.dphi.size):
        t.add_row(_fmt(deg(state.dphi[i]), 2), _fmt(deg(state.dpsi[i]), 3),
                  _fmt(deg(state.beta[i]), 3), _fmt(state.b[i], 3), _fmt(state.d[i], 3),
                  _fmt(state.psi1[i], 4), _fmt(state.psi2[i], 4))
        p.add_row(_fmt(deg(state.dphi[i]), 2), *(_fmt(v, 2) for v in (
            state.C[i, 0], state.C[i, 1], state.H[i, 0], state.H[i, 1],
            float(np.hypot(*state.C1[i])), float(np.hypot(*state.H1[i])))))
    console.print(t)
    console.print(p)
    q = Table(title="straight-line quality of the paths")
    q.add_column("")
    q.add_column("C", justify="right")
    q.add_column("H", justify="right")
    for key, label in (("extent_x", "horizontal extent"), ("extent_y", "vertical extent"),
                       ("segment_span", "segment length along the design tangent"),
                       ("max_positive_deviation", "max deviation above the tangent"),
                       ("max_negative_deviation", "max deviation below the tangent"),
                       ("best_line_deviation", "max deviation from the best (minimax) line"),
                       ("translation_length", "travel with |θ| ≤ tol")):
        q.add_row(label, _fmt(getattr(quality["C"], key)), _fmt(getattr(quality["H"], key)))
    qc = quality["C"]
    q.caption = (f"segment Δφ = {qc.segment_deg[0]:g}…{qc.segment_deg[1]:g}°, tol = "
                 f"{qc.translation_tol_deg:g}° (Δφ {qc.translation_dphi_deg[0]:.2f}…"
                 f"{qc.translation_dphi_deg[1]:.2f}°)")
    console.print(q)
    f = Table(title="belt mechanism vs. its equivalent four-bar A0-A-B-B0")
    for col in ("", "assembles over Δφ°", "C above line (machine side)",
                "C above line (other side)", "H travel |θ| ≤ tol"):
        f.add_column(col, justify="right")
    for name in ("belt", "four_bar"):
        e = comparison[name]
        rng = e["assembled_dphi_deg"]

        def side(p: str, s: str) -> str:
            v = e[p][s]
            return _fmt(v["max_positive_deviation"]) if v else "—"
        f.add_row(name, f"{rng[0]:.1f} … {rng[1]:.1f}" if rng else "—",
                  side("C", "machine_side"), side("C", "other_side"),
                  _fmt(e["H"]["translation_length"]))
    console.print(f)
    mx = mres.to_dict()["max"]
    console.print(f"input law {result['motion']['law']}: duration {mres.t[-1]:.4g} s; max "
                  f"speed C {mx['C_speed']:.4g}, H {mx['H_speed']:.4g}; max |a| C "
                  f"{mx['C_accel']:.4g}, H {mx['H_accel']:.4g} (unit/s, unit/s²)")


# ------------------------------------------------------------------------- inverse
@belt_app.command("inverse")
def inverse_cmd(
    file: Optional[Path] = typer.Option(None, "--file", "-f", help="case file (YAML/JSON)"),
    a: Optional[float] = typer.Option(None, "--a", help="lever length |A0 A|"),
    c: Optional[float] = typer.Option(None, "--c", help="x offset of C left of A"),
    h: Optional[float] = typer.Option(None, "--h", help="height of H above C"),
    r: Optional[float] = typer.Option(None, "--r", help="pulley radius"),
    phi: Optional[str] = typer.Option(None, "--phi",
                                      help="Δφ range START:STOP:STEP, deg, in the direction "
                                           "of the motion"),
    speed: float = typer.Option(..., "--speed", help="required speed of the point along its "
                                                     "path (unit/s)"),
    accel: float = typer.Option(0.0, "--accel", help="required tangential acceleration "
                                                     "(unit/s²)"),
    point: str = typer.Option("H", "--point", help="H or C"),
    json_out: bool = typer.Option(False, "--json", help="print JSON"),
    csv_out: Optional[Path] = typer.Option(None, "--csv", help="write the table (- for stdout)"),
) -> None:
    """Inverse problem: servo input speed and acceleration for a required path speed.

    Example: mechsyn belt inverse --a 500 --c 350 --h 100 --r 75 --phi -73:0:1 --speed 1000
    """
    case = kb.load_belt_case(str(file)) if file is not None else None
    design, _ = _design(a, c, h, r, case, str(file) if file else None)
    if point not in ("H", "C"):
        raise MechsynInputError(f"unknown point {point!r}", source="--point", hint="H or C")
    _number(speed, "--speed", positive=True)
    _number(accel, "--accel")
    if phi is not None:
        grid_deg = _grid(*parse_range(phi, "--phi", "-73:85:1"), "--phi")
    elif case is not None and case.phi_deg is not None:
        grid_deg = _grid(case.phi_deg.start, case.phi_deg.stop, case.phi_deg.step, "phi_deg")
    else:
        raise MechsynInputError("missing the range of Δφ", source="--phi")
    state = kb.analyze(design, np.radians(grid_deg))
    if not np.all(state.valid):
        raise MechsynInputError("the belt goes slack (d <= r) inside the range",
                                source="--phi", hint="narrow the range")
    res = kb.inverse_input(state, speed, accel, point)  # type: ignore[arg-type]
    out = {"design": design.to_dict(), "point": point, **res.to_dict()}
    one_stdout(json_out, csv_out)
    if csv_out is not None:
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["dphi_deg", "t", "phid_deg_s", "phidd_deg_s2", "speed", "accel_tangential"])
        for row in zip(np.degrees(res.dphi), res.t, np.degrees(res.phid),
                       np.degrees(res.phidd), res.speed, res.accel_tangential):
            w.writerow([repr(float(v)) for v in row])
        write_output(csv_out, buf.getvalue())
    if is_stdout(csv_out):
        return
    if json_out:
        emit_json(out)
        return
    t = Table(title=f"servo input for {point} at speed {speed:g}, tangential accel {accel:g}")
    for col in ("Δφ°", "t (s)", "φ̇ (°/s)", "φ̈ (°/s²)"):
        t.add_column(col, justify="right")
    for i in range(res.dphi.size):
        t.add_row(_fmt(math.degrees(res.dphi[i]), 2), _fmt(float(res.t[i]), 4),
                  _fmt(math.degrees(res.phid[i]), 3), _fmt(math.degrees(res.phidd[i]), 3))
    console.print(t)
    console.print(f"duration {res.t[-1]:.4g} s; max |φ̇| {out['max_phid_deg_s']:.4g} °/s, "
                  f"max |φ̈| {out['max_phidd_deg_s2']:.4g} °/s²")
