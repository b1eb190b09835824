"""``mechsyn synth path|function|motion``: dimensional synthesis of four-bars."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np
import typer
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import check_output_suffix, check_writable, console, emit_json, err_console, parse_floats, save_plot
from mechsyn.cli.resume import checkpoint_options, stop_if_interrupted
from mechsyn.errors import MechsynInputError


def _pick_case(file: Path, case_id: Optional[str]):
    from mechsyn.synthesis.path import load_cases

    cases = load_cases(file)
    if case_id is None:
        if len(cases) == 1:
            return cases[0]
        raise MechsynInputError(
            f"the file holds {len(cases)} cases", source=str(file),
            hint="choose one with --case " + " | ".join(c.id for c in cases))
    for c in cases:
        if c.id == case_id:
            return c
    raise MechsynInputError(f"no case {case_id!r}", source="--case",
                            hint="one of " + ", ".join(c.id for c in cases))


@synth_app.command("path")
def synth_path(
    case_file: Path = typer.Argument(..., help="Case JSON (schema of synthesis_cases_public.json): one case, or a file of cases with --case."),
    case_id: Optional[str] = typer.Option(None, "--case", help="Case id when the file holds several."),
    seed: int = typer.Option(0, "--seed", help="Seed of the reproducible multi-start."),
    time_limit: float = typer.Option(60.0, "--time-limit", help="Wall-clock budget in seconds."),
    restarts: int = typer.Option(10, "--restarts", help="Number of restarts (child seeds of --seed)."),
    workers: int = typer.Option(1, "--workers", help="Run restarts in N local processes."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Run restarts on a Dask cluster (scheduler address; extra mechsyn[dask])."),
    optimizer: str = typer.Option("de", "--optimizer", help="Global optimiser (de | random | registered)."),
    target_error: Optional[float] = typer.Option(
        None, "--target-error", help="Stop once a design reaches this error (default: the case's "
        "best known error + 1 %, if it has one; 0: use the whole budget)."),
    min_transmission: Optional[float] = typer.Option(
        None, "--min-transmission-angle", help="Smallest transmission angle [deg] allowed over "
        "the motion (default: the case's, else 20; 0: no limit)."),
    fold_margin: Optional[float] = typer.Option(
        None, "--fold-margin", help="Grashof cases: how far [deg] the linkage must stay from "
        "folding flat anywhere in the turn (default: the case's, else 5)."),
    as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Write targets vs achieved path (PNG)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the linkage as a mechanism file (.yaml/.json)."),
    checkpoint: Optional[Path] = typer.Option(None, "--checkpoint", help="Save finished restarts to this file as the run goes."),
    resume: Optional[Path] = typer.Option(None, "--resume", help="Continue the run saved in this checkpoint (same options)."),
) -> None:
    """Path generation: a four-bar whose coupler point passes through the targets."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from mechsyn.parallel import check_parallel_options
    from mechsyn.plot.synthesis import plot_fourbar_path
    from mechsyn.synthesis.export import fourbar_mechanism_dict, write_mechanism_file
    from mechsyn.synthesis.optimize import default_target_error, synthesize_path

    if time_limit <= 0:
        raise MechsynInputError("must be positive", source="--time-limit")
    if restarts < 1:
        raise MechsynInputError("must be at least 1", source="--restarts")
    check_parallel_options(workers, scheduler)
    check_output_suffix(out, (".yaml", ".yml", ".json"), "--out", what=".yaml or .json")
    check_output_suffix(plot, (".png", ".pdf", ".svg"), "--plot")
    ck = checkpoint_options(checkpoint, resume)
    case = _pick_case(case_file, case_id)
    case = _with_margins(case, min_transmission, fold_margin)
    if target_error is None:
        target_error = default_target_error(case)
    elif target_error < 0:
        raise MechsynInputError("must be >= 0 (0: use the whole budget)", source="--target-error")
    target_error = target_error or None
    show = err_console.is_terminal
    if show:
        with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total} restarts"),
                      TextColumn("best error {task.fields[best]}"), TimeElapsedColumn(),
                      console=err_console, transient=True) as prog:
            task = prog.add_task(f"synth path {case.id}", total=restarts, best="-")

            def progress(done, total, best):
                prog.update(task, completed=done, best=f"{best:.6g}" if np.isfinite(best) else "-")

            res = synthesize_path(case, seed=seed, time_limit=time_limit, restarts=restarts, workers=workers,
                                  optimizer=optimizer, progress=progress, scheduler=scheduler,
                                  target_error=target_error, **ck)
    else:
        res = synthesize_path(case, seed=seed, time_limit=time_limit, restarts=restarts, workers=workers,
                              optimizer=optimizer, scheduler=scheduler, target_error=target_error, **ck)
    d = {**case.fixed, **res.design}
    if out is not None:
        if not res.feasible:
            raise MechsynInputError("no feasible design found; nothing written", source="--out",
                                    hint="raise --time-limit or --restarts, or widen the bounds")
        mech = fourbar_mechanism_dict(d["r1"], d["r2"], d["r3"], d["r4"], float(res.theta2[0]), branch=case.branch,
                                      rcx=d["rcx"], rcy=d["rcy"], x0=d["x0"], y0=d["y0"], theta0=d["theta0"],
                                      name=f"Four-bar for path case {case.id}")
        write_mechanism_file(mech, out, header=(
            ("INTERRUPTED (Ctrl-C): the best design found before the interrupt\n" if res.interrupted else "")
            + f"mechsyn synth path {case.id}: error {res.error:.6g} (sum of squared distances), seed {seed}\n"
            f"joint points at target 1 (crank angle {np.degrees(res.theta2[0]):.4f} deg), branch {case.branch}"))
    if plot is not None:
        save_plot(plot, plot_fourbar_path, d, case.targets, res.theta2, case.branch, dpi=120,
                  title=f"{case.id}: error {res.error:.4g}"
                  + (f" (published best {case.best_known:.4g})" if case.best_known else ""))
    if as_json:
        emit_json(res)
        stop_if_interrupted(res, ck)
        return
    t = Table(title=f"Path synthesis {case.id}" + (" (interrupted: best so far)" if res.interrupted else ""))
    t.add_column("variable")
    t.add_column("value", justify="right")
    for k, v in res.design.items():
        t.add_row(k, f"{v:.8g}")
    console.print(t)
    console.print(f"error (sum of squared distances): [bold]{res.error:.8g}[/]"
                  + (f"   published best: {case.best_known:.8g}" if case.best_known else ""))
    console.print(f"feasible: {res.feasible}   assembled at all targets: {res.assembled_at_all_targets}   "
                  f"branch {case.branch}   {res.restarts} restart{'s' if res.restarts != 1 else ''}, {res.seconds:.1f} s"
                  + ("   (target error reached)" if res.target_reached else ""))
    console.print(_transmission_line(res))
    stop_if_interrupted(res, ck)


def _with_margins(case, min_transmission: Optional[float], fold_margin: Optional[float]):
    from dataclasses import replace

    for value, option in ((min_transmission, "--min-transmission-angle"), (fold_margin, "--fold-margin")):
        if value is not None and not 0.0 <= value < 90.0:
            raise MechsynInputError("must be an angle in degrees in [0, 90)", source=option)
    if min_transmission is not None:
        case = replace(case, transmission_angle_min_deg=min_transmission)
    if fold_margin is not None:
        case = replace(case, fold_margin_deg=fold_margin)
    return case


def _transmission_line(res) -> str:
    mu = res.worst_transmission_angle_deg
    text = (f"worst transmission angle over the motion: {mu:.2f} deg"
            + (f" (limit {res.transmission_angle_min_deg:g})" if res.transmission_angle_min_deg else ""))
    if res.fold_distance_deg is not None:
        text += f"\nnearest approach to folding flat: {res.fold_distance_deg:.2f} deg"
        text += f" (limit {res.fold_margin_deg:g})" if res.fold_margin_deg else ""
    return text


@synth_app.command("function")
def synth_function(
    phi: str = typer.Option(..., "--phi", help="Three crank angles [deg], from the ground line, e.g. 30,60,90."),
    psi: str = typer.Option(..., "--psi", help="Three rocker angles [deg], e.g. 100,120,135."),
    ground: float = typer.Option(1.0, "--ground", help="Ground link length."),
    as_json: bool = typer.Option(False, "--json"),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the linkage as a mechanism file."),
) -> None:
    """Function generation by Freudenstein's equation (3 precision positions), verified by simulation."""
    from mechsyn.synthesis.exact import freudenstein_synthesis
    from mechsyn.synthesis.export import fourbar_mechanism_dict, write_mechanism_file

    check_writable(out, "--out")
    ph = np.radians(parse_floats(phi, "--phi", 3))
    ps = np.radians(parse_floats(psi, "--psi", 3))
    if not ground > 0:
        raise MechsynInputError("must be positive", source="--ground")
    r = freudenstein_synthesis(ph, ps, ground)
    data = {"design": r.design, "K": r.K, "branch": r.branch, "phi_deg": np.degrees(r.phi),
            "psi_deg": np.degrees(r.psi), "psi_simulated_deg": np.degrees(r.psi_simulated),
            "max_error_deg": np.degrees(r.max_error), "branch_defect": r.branch_defect,
            "order_defect": r.order_defect, "grashof": r.grashof, "notes": r.notes,
            "verified": bool(r.max_error < 1e-8 and not r.branch_defect and not r.order_defect)}
    if out is not None:
        write_mechanism_file(fourbar_mechanism_dict(r.r1, r.r2, r.r3, r.r4, float(r.phi[0]), branch=r.branch,
                                                    name="Four-bar function generator (Freudenstein)"), out)
    if as_json:
        emit_json(data)
        return
    t = Table(title="Freudenstein 3-position function generation")
    for c in ("position", "phi [deg]", "psi required", "psi simulated"):
        t.add_column(c, justify="right")
    for i in range(3):
        t.add_row(str(i + 1), f"{np.degrees(r.phi[i]):.4f}", f"{np.degrees(r.psi[i]):.4f}",
                  f"{np.degrees(r.psi_simulated[i]):.4f}")
    console.print(t)
    console.print("K1, K2, K3 = " + ", ".join(f"{k:.6g}" for k in r.K))
    console.print(f"ground {r.r1:.6g}, crank {r.r2:.6g}, coupler {r.r3:.6g}, rocker {r.r4:.6g}  ({r.grashof}), branch {r.branch}")
    console.print(f"branch defect: {r.branch_defect}   order defect: {r.order_defect}")
    for n in r.notes:
        console.print(f"note: {n}")


def _read_poses(file: Optional[Path], poses: Optional[str]) -> np.ndarray:
    if file is not None:
        from mechsyn.io.files import read_data

        data, _ = read_data(file, "poses file", fmt="json")
        items = data.get("poses") if isinstance(data, dict) else data
        try:
            P = np.array([[float(p[0]), float(p[1]), float(p[2])] for p in items])
        except (TypeError, ValueError, IndexError, KeyError):
            raise MechsynInputError("poses must be [x, y, angle_deg] triples", source=str(file), field="poses") from None
    elif poses is not None:
        vals = parse_floats(poses, "--poses")
        if len(vals) % 3:
            raise MechsynInputError("expected x,y,angle triples", source="--poses")
        P = np.array(vals).reshape(-1, 3)
    else:
        raise MechsynInputError("give the poses", source="poses", hint="--poses x1,y1,a1,x2,y2,a2,... or a JSON file")
    if not 3 <= len(P) <= 5:
        raise MechsynInputError(f"need 3, 4 or 5 poses, got {len(P)}", source="poses")
    P[:, 2] = np.radians(P[:, 2])
    return P


@synth_app.command("motion")
def synth_motion(
    poses_file: Optional[Path] = typer.Argument(None, help="JSON file {\"poses\": [[x, y, angle_deg], ...]} (3-5 poses)."),
    poses: Optional[str] = typer.Option(None, "--poses", help="Poses inline: x1,y1,a1,x2,y2,a2,... (angles in deg)."),
    circle_points: Optional[str] = typer.Option(None, "--circle-points", help="3 poses: two moving pivots in the coupler frame: x1,y1,x2,y2."),
    center_points: Optional[str] = typer.Option(None, "--center-points", help="3 poses: two ground pivots: x1,y1,x2,y2."),
    top: int = typer.Option(5, "--top", help="How many solutions to list."),
    as_json: bool = typer.Option(False, "--json"),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Centre-point curve / solution plot (PNG)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the best linkage as a mechanism file."),
) -> None:
    """Motion generation by Burmester theory (3, 4 or 5 poses), each linkage verified by simulation."""
    from mechsyn.plot.synthesis import plot_motion_synthesis
    from mechsyn.synthesis.exact import motion_synthesis, to_jsonable_motion
    from mechsyn.synthesis.export import fourbar_mechanism_dict, write_mechanism_file

    check_writable(out, "--out")
    check_writable(plot, "--plot")
    P = _read_poses(poses_file, poses)
    cp = np.array(parse_floats(circle_points, "--circle-points", 4)).reshape(2, 2) if circle_points else None
    mp = np.array(parse_floats(center_points, "--center-points", 4)).reshape(2, 2) if center_points else None
    if (cp is not None or mp is not None) and len(P) != 3:
        raise MechsynInputError("circle/centre points are chosen only for 3 poses", source="--circle-points")
    sols = motion_synthesis(P, circle_points=cp, center_points=mp)
    if not sols:
        raise MechsynInputError("no linkage found for these poses", source="poses")
    best = sols[0]
    if out is not None:
        d = best.design()
        write_mechanism_file(fourbar_mechanism_dict(
            d["r1"], d["r2"], d["r3"], d["r4"], float(best.theta2[0]), branch=best.branch, rcx=d["rcx"], rcy=d["rcy"],
            x0=d["x0"], y0=d["y0"], theta0=d["theta0"], name="Four-bar motion generator (Burmester)"), out,
            header="coupler point P = origin of the guided body's frame; joints at pose 1")
    if plot is not None:
        save_plot(plot, plot_motion_synthesis, P, sols, dpi=120)
    if as_json:
        emit_json({"solutions": [to_jsonable_motion(s) for s in sols[:top]], "count": len(sols),
                   "verified_count": sum(s.ok for s in sols)})
        return
    t = Table(title=f"Burmester motion generation, {len(P)} poses ({sum(s.ok for s in sols)} of {len(sols)} verified)")
    for c in ("O2", "O4", "r1", "r2", "r3", "r4", "type", "min mu [deg]", "defects", "pos. error"):
        t.add_column(c, justify="right")
    for s in sols[:top]:
        defects = ", ".join(k for k, v in (("branch", s.branch_defect), ("order", s.order_defect)) if v) or "none"
        t.add_row(f"({s.O2[0]:.4g}, {s.O2[1]:.4g})", f"({s.O4[0]:.4g}, {s.O4[1]:.4g})", f"{s.r1:.4g}", f"{s.r2:.4g}",
                  f"{s.r3:.4g}", f"{s.r4:.4g}", s.grashof, f"{s.min_transmission_deg:.1f}", defects, f"{s.position_error:.2e}")
    console.print(t)
