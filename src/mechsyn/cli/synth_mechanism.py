"""``mechsyn synth mechanism CASE``: path / motion synthesis of any planar mechanism file."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import (ForceOpt, OptimizerOpt, RestartsOpt, SchedulerOpt, SeedOpt, TimeLimitOpt, WorkersOpt,
                                check_output_suffix, check_overwrite, emit_json, progress_bar)
from mechsyn.cli.resume import CheckpointOpt, ResumeOpt, checkpoint_options, stop_if_interrupted
from mechsyn.errors import MechsynInputError


def _write_files(case_file: Path, case, res, out: Optional[Path], plot: Optional[Path]) -> None:
    if (out is not None or plot is not None) and not res.feasible:
        raise MechsynInputError("no feasible design found; nothing written", source=str(case_file),
                                hint="raise --time-limit or --restarts, or widen the variable bounds")
    if out is not None:
        from mechsyn.io import write_mechanism

        write_mechanism(res.mechanism, out)
        from mechsyn.cli.common import say_written

        say_written(out)
    if plot is not None:
        from mechsyn.cli.common import save_plot
        from mechsyn.plot.synthesis import plot_mechanism_synthesis

        save_plot(plot, plot_mechanism_synthesis, case, res, dpi=120)


@synth_app.command("mechanism")
def synth_mechanism(
    case_file: Path = typer.Argument(..., help="Case YAML/JSON: mechanism file, input values, targets or poses, variables."),
    seed: SeedOpt = 0,
    time_limit: TimeLimitOpt = 30.0,
    restarts: RestartsOpt = 3,
    optimizer: OptimizerOpt = "de",
    workers: WorkersOpt = 1,
    scheduler: SchedulerOpt = None,
    as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Write targets vs achieved path (PNG)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the design as a mechanism file (.yaml/.json)."),
    force: ForceOpt = False,
    checkpoint: CheckpointOpt = None,
    resume: ResumeOpt = None,
) -> None:
    """Move chosen joint / point coordinates and VLL lengths of a planar mechanism file so
    a point follows target positions (or a link target poses) at given input angles."""
    from mechsyn.cli.render import render_mechanism_synthesis
    from mechsyn.parallel import check_parallel_options
    from mechsyn.synthesis.general import load_mechanism_case
    from mechsyn.synthesis.reports import mechanism_synthesis

    check_parallel_options(workers, scheduler)
    check_output_suffix(plot, (".png",), "--plot")
    check_output_suffix(out, (".yaml", ".yml", ".json"), "--out", what=".yaml or .json")
    check_overwrite(out, "--out", force)
    ck = checkpoint_options(checkpoint, resume)
    case = load_mechanism_case(case_file)
    with progress_bar("synth mechanism", restarts, enabled=not as_json) as progress:
        res = mechanism_synthesis(case, seed=seed, time_limit=time_limit, restarts=restarts, optimizer=optimizer,
                                  workers=workers, scheduler=scheduler, progress=progress, **ck)
    _write_files(case_file, case, res, out, plot)
    if as_json:
        emit_json(res.to_dict())
    else:
        render_mechanism_synthesis(case, res)
    stop_if_interrupted(res, ck)
