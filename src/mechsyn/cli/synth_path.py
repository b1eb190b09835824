"""``mechsyn synth path|function|motion``: dimensional synthesis of four-bars."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import (ForceOpt, OptimizerOpt, RestartsOpt, SchedulerOpt, SeedOpt, Table, TimeLimitOpt, WorkersOpt,
                                check_output_suffix, check_overwrite, check_writable, console, emit_json, parse_floats,
                                progress_bar, save_plot, say_written)
from mechsyn.cli.resume import CheckpointOpt, ResumeOpt, checkpoint_options, stop_if_interrupted
from mechsyn.errors import MechsynInputError

TargetErrorOpt = Annotated[Optional[float], typer.Option(
    "--target-error", help="Stop once a design reaches this error (default: the case's best known error + 1 %, "
    "if it has one; 0: use the whole budget).")]
MinTransmissionOpt = Annotated[Optional[float], typer.Option(
    "--min-transmission-angle", help="Smallest transmission angle [deg] allowed over the motion (default: the "
    "case's, else 20; 0: no limit).")]
MaxSizeOpt = Annotated[Optional[float], typer.Option(
    "--max-size", help="Pivots and pin circles within this many target diagonals of the targets' centre "
    "(default: the case's options.max_size, else none: the case's variable bounds are its design space; 0: no bound).")]
FoldMarginOpt = Annotated[Optional[float], typer.Option(
    "--fold-margin", help="Grashof cases: how far [deg] the linkage must stay from folding flat anywhere in the "
    "turn (default: the case's, else 5).")]


@synth_app.command("path")
def synth_path(
    case_file: Path = typer.Argument(..., help="Case JSON (schema of synthesis_cases_public.json): one case, or a file of cases with --case."),
    case_id: Optional[str] = typer.Option(None, "--case", help="Case id when the file holds several."),
    seed: SeedOpt = 0,
    time_limit: TimeLimitOpt = 60.0,
    restarts: RestartsOpt = 10,
    workers: WorkersOpt = 1,
    scheduler: SchedulerOpt = None,
    optimizer: OptimizerOpt = "de",
    target_error: TargetErrorOpt = None,
    min_transmission: MinTransmissionOpt = None,
    fold_margin: FoldMarginOpt = None,
    max_size: MaxSizeOpt = None,
    as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Write targets vs achieved path (PNG)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the linkage as a mechanism file (.yaml/.json)."),
    force: ForceOpt = False,
    checkpoint: CheckpointOpt = None,
    resume: ResumeOpt = None,
) -> None:
    """Path generation: a four-bar whose coupler point passes through the targets."""
    from mechsyn.cli.render import render_path_synthesis
    from mechsyn.parallel import check_parallel_options
    from mechsyn.synthesis.path import load_cases
    from mechsyn.synthesis.reports import path_synthesis, select_case

    check_parallel_options(workers, scheduler)
    _check_outputs(out, plot, force)
    ck = checkpoint_options(checkpoint, resume)
    case = select_case(load_cases(case_file), case_id, source=str(case_file))
    with progress_bar(f"synth path {case.id}", restarts) as progress:
        res = path_synthesis(case, seed=seed, time_limit=time_limit, restarts=restarts, workers=workers,
                             scheduler=scheduler, optimizer=optimizer, target_error=target_error,
                             min_transmission=min_transmission, fold_margin=fold_margin, max_size=max_size, progress=progress, **ck)
    _write_path_files(case, res, out, plot)
    if as_json:
        emit_json(res.to_dict())
    else:
        render_path_synthesis(case, res)
    stop_if_interrupted(res, ck)


def _check_outputs(out: Optional[Path], plot: Optional[Path], force: bool) -> None:
    """``--out`` and ``--plot`` checked before any work (suffix, writable, not replacing
    a file that is not a mechanism file without ``--force``)."""
    check_output_suffix(out, (".yaml", ".yml", ".json"), "--out", what=".yaml or .json")
    check_overwrite(out, "--out", force)
    check_output_suffix(plot, (".png", ".pdf", ".svg"), "--plot")


def _write_path_files(case, res, out: Optional[Path], plot: Optional[Path]) -> None:
    from mechsyn.synthesis.export import write_mechanism_file
    from mechsyn.synthesis.reports import path_mechanism_dict

    if out is not None:
        try:
            mech, header = path_mechanism_dict(case, res)
        except MechsynInputError as exc:
            raise exc.with_source("--out") from None
        write_mechanism_file(mech, out, header=header)
        say_written(out)
    if plot is not None:
        from mechsyn.plot.synthesis import plot_fourbar_path

        save_plot(plot, plot_fourbar_path, {**case.fixed, **res.design}, case.targets, res.theta2, case.branch,
                  dpi=120, title=f"{case.id}: error {res.error:.4g}"
                  + (f" (published best {case.best_known:.4g})" if case.best_known else ""))


@synth_app.command("function")
def synth_function(
    phi: str = typer.Option(..., "--phi", help="Three crank angles [deg]: the crank's direction from its frame pivot A, "
                            "counter-clockwise from the ground line (+x, from A to the rocker's pivot D), e.g. 30,60,90."),
    psi: str = typer.Option(..., "--psi", help="Three rocker angles [deg]: the rocker's direction from its frame pivot D "
                            "(D to C), counter-clockwise from the same ground line, e.g. 100,120,135."),
    ground: float = typer.Option(1.0, "--ground", help="Ground link length."),
    as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
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
    if out is not None:
        write_mechanism_file(fourbar_mechanism_dict(r.r1, r.r2, r.r3, r.r4, float(r.phi[0]), branch=r.branch,
                                                    name="Four-bar function generator (Freudenstein)"), out)
    if as_json:
        emit_json(r.to_dict())
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
    as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Centre-point curve / solution plot (PNG)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the best linkage as a mechanism file."),
) -> None:
    """Motion generation by Burmester theory (3, 4 or 5 poses), each linkage verified by simulation."""
    from mechsyn.cli.render import render_motion
    from mechsyn.synthesis.export import write_mechanism_file
    from mechsyn.synthesis.reports import motion_mechanism_dict, motion_report

    check_writable(out, "--out")
    check_writable(plot, "--plot")
    P = _read_poses(poses_file, poses)
    cp = np.array(parse_floats(circle_points, "--circle-points", 4)).reshape(2, 2) if circle_points else None
    mp = np.array(parse_floats(center_points, "--center-points", 4)).reshape(2, 2) if center_points else None
    report = motion_report(P, circle_points=cp, center_points=mp, top=top)
    if out is not None:
        mech, header = motion_mechanism_dict(report)
        write_mechanism_file(mech, out, header=header)
    if plot is not None:
        save_plot(plot, lambda ax: report.plot(ax=ax), dpi=120)
    if as_json:
        emit_json(report.to_dict())
        return
    render_motion(report)
