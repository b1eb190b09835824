"""``mechsyn synth mechanism CASE``: path / motion synthesis of any planar mechanism file."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import check_output_suffix, console, emit_json, err_console
from mechsyn.cli.resume import checkpoint_options, stop_if_interrupted
from mechsyn.errors import MechsynInputError


@synth_app.command("mechanism")
def synth_mechanism(
    case_file: Path = typer.Argument(..., help="Case YAML/JSON: mechanism file, input values, targets or poses, variables."),
    seed: int = typer.Option(0, "--seed", help="Seed of the reproducible multi-start."),
    time_limit: float = typer.Option(30.0, "--time-limit", help="Wall-clock budget in seconds."),
    restarts: int = typer.Option(3, "--restarts", help="Number of restarts (child seeds of --seed)."),
    optimizer: str = typer.Option("de", "--optimizer", help="Global optimiser (de | random | registered)."),
    workers: int = typer.Option(1, "--workers", help="Run restarts in N local processes."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Run restarts on a Dask cluster (scheduler address; extra mechsyn[dask])."),
    as_json: bool = typer.Option(False, "--json", help="Print the result as JSON."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="Write targets vs achieved path (PNG)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the design as a mechanism file (.yaml/.json)."),
    checkpoint: Optional[Path] = typer.Option(None, "--checkpoint", help="Save finished restarts to this file as the run goes."),
    resume: Optional[Path] = typer.Option(None, "--resume", help="Continue the run saved in this checkpoint (same options)."),
) -> None:
    """Move chosen joint / point coordinates and VLL lengths of a planar mechanism file so
    a point follows target positions (or a link target poses) at given input angles."""
    from mechsyn.parallel import check_parallel_options
    from mechsyn.synthesis.general import load_case, synthesize_mechanism

    check_parallel_options(workers, scheduler)
    if not time_limit > 0:
        raise MechsynInputError("must be positive", source="--time-limit")
    if restarts < 1:
        raise MechsynInputError("must be at least 1", source="--restarts")
    check_output_suffix(plot, (".png",), "--plot")
    check_output_suffix(out, (".yaml", ".yml", ".json"), "--out", what=".yaml or .json")
    ck = checkpoint_options(checkpoint, resume)
    case = load_case(case_file)
    if err_console.is_terminal and not as_json:
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total} restarts"),
                      TextColumn("best {task.fields[best]}"), TimeElapsedColumn(),
                      console=err_console, transient=True) as prog:
            task = prog.add_task("synth mechanism", total=restarts, best="-")

            def progress(done: int, total: int, best: float) -> None:
                prog.update(task, completed=done, best=f"{best:.6g}")

            res = synthesize_mechanism(case, seed=seed, time_limit=time_limit, restarts=restarts,
                                       optimizer=optimizer, progress=progress, workers=workers,
                                       scheduler=scheduler, **ck)
    else:
        res = synthesize_mechanism(case, seed=seed, time_limit=time_limit, restarts=restarts,
                                   optimizer=optimizer, workers=workers, scheduler=scheduler, **ck)
    if (out is not None or plot is not None) and not res.feasible:
        raise MechsynInputError("no feasible design found; nothing written", source=str(case_file),
                                hint="raise --time-limit or --restarts, or widen the variable bounds")
    if out is not None:
        from mechsyn.io import write_mechanism

        write_mechanism(res.mechanism, out)
    if plot is not None:
        from mechsyn.cli.common import save_plot
        from mechsyn.plot.synthesis import plot_mechanism_synthesis

        save_plot(plot, plot_mechanism_synthesis, case, res, dpi=120)
    if as_json:
        emit_json(res)
        stop_if_interrupted(res, ck)
        return
    t = Table(title=f"{case.problem.capitalize()} synthesis: {case.name}"
              + (" (interrupted: best so far)" if res.interrupted else ""))
    t.add_column("variable")
    t.add_column("start", justify="right")
    t.add_column("design", justify="right")
    for k, v in res.design.items():
        t.add_row(k, f"{res.start_design[k]:.6g}", f"{v:.8g}")
    console.print(t)
    se = "infeasible" if res.start_error is None else f"{res.start_error:.6g}"
    console.print(f"error ({'sum of squared distances' if case.problem == 'path' else 'pose error'}): "
                  f"[bold]{res.error:.8g}[/]   (start design: {se})")
    console.print(f"feasible: {res.feasible}   evaluation: {res.method}   {res.restarts} restarts, "
                  f"{res.nfev} evaluations, {res.seconds:.1f} s"
                  + ("   (time limit reached)" if res.stopped_by_time_limit else ""))
    if not res.feasible:
        console.print(f"[bold red]no feasible design found[/]: {res.reason}")
    stop_if_interrupted(res, ck)
