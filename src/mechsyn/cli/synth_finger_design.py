"""``mechsyn synth finger-design CASE``: paper 000's parametric synthesis of a finger with VLL.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import typer
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import ForceOpt, check_output_suffix, check_overwrite, console, emit_json, progress_bar
from mechsyn.cli.resume import CheckpointOpt, ResumeOpt, checkpoint_options, stop_if_interrupted
from mechsyn.errors import MechsynInputError


@synth_app.command("finger-design")
def finger_design(
    case_file: Path = typer.Argument(..., help="Case YAML/JSON: mechanism with VLL, variables, targets, region."),
    seed: int = typer.Option(0, "--seed", help="Seed of the differential evolution (reproducible)."),
    time_limit: float = typer.Option(60.0, "--time-limit", help="Seconds for the optimisation stages (the final checks still run)."),
    json_out: bool = typer.Option(False, "--json", help="Print JSON on stdout."),
    plot: Optional[Path] = typer.Option(None, "--plot", help="PNG: both modes' motion and the region."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the design as a mechanism file (.yaml/.json)."),
    force: ForceOpt = False,
    checkpoint: CheckpointOpt = None,
    resume: ResumeOpt = None,
) -> None:
    """Optimise a finger's link lengths on discrete positions with its VLL locked, find
    each VLL's length range keeping the paths in the working region, minimise joint
    reactions and input moment in both modes; best VLL combination (paper 000, steps 8-13)."""
    from mechsyn.synthesis.finger.cases import load_case
    from mechsyn.synthesis.finger.design import design_finger

    if time_limit <= 0:
        raise MechsynInputError("--time-limit must be positive", source="--time-limit")
    check_output_suffix(plot, (".png",), "--plot")
    check_output_suffix(out, (".yaml", ".yml", ".json"), "--out", what=".yaml or .json")
    check_overwrite(out, "--out", force)
    ck = checkpoint_options(checkpoint, resume)
    case = load_case(case_file)
    with progress_bar("finger design", enabled=not json_out) as progress:  # the stage and the best so far
        res = design_finger(case, seed=seed, time_limit=time_limit, **ck, progress=progress)
    _write(case, res, out, plot)
    if json_out:
        emit_json(res)
    else:
        _render(case_file.name, res, time_limit, out, plot)
    stop_if_interrupted(res, ck)


def _write(case: Any, res: Any, out: Optional[Path], plot: Optional[Path]) -> None:
    """The best design as a mechanism file (``--out``) and the three-panel plot (``--plot``)."""
    if out is not None:
        from mechsyn.io import write_mechanism

        mech = dict(res.best_variant.mechanism)
        mech["name"] = (f"{mech.get('name', 'finger')} (finger-design, seed {res.seed}"
                        + (", interrupted: best so far)" if res.interrupted else ")"))
        write_mechanism(mech, out)
        from mechsyn.cli.common import say_written

        say_written(out)
    if plot is not None:
        from mechsyn.cli.common import save_plot
        from mechsyn.plot.finger import plot_finger_design

        save_plot(plot, plot_finger_design, case, res)


def _render(name: str, res: Any, time_limit: float, out: Optional[Path], plot: Optional[Path]) -> None:
    best = res.best_variant
    t = Table(title=f"Finger design: {name} (seed {res.seed}, {res.seconds:.1f} s"
              + (", interrupted: best so far)" if res.interrupted else ")"))
    for col in ("VLL", "stage-1 RMS err (deg)", "final RMS / max err (deg)", "VLL range",
                "peak |R| (joint) stage 1 -> final", "peak |M_in| stage 1 -> final"):
        t.add_column(col)
    for k, v in enumerate(res.variants):
        fa = v.forces
        t.add_row(("* " if k == res.best else "") + "+".join(v.combination), f"{v.stage1_error_rms:.4g}",
                  f"{v.error_rms:.4g} / {v.error_max:.4g}",
                  ", ".join(f"{j}: [{a:.4g}, {b:.4g}]" for j, (a, b) in v.vll_ranges.items()),
                  f"{v.stage1_forces['peak_reaction']:.4g} ({v.stage1_forces['peak_joint']}) -> "
                  f"{fa['peak_reaction']:.4g} ({fa['peak_joint']})",
                  f"{v.stage1_forces['peak_input_moment']:.4g} -> {fa['peak_input_moment']:.4g}")
    console.print(t)
    d = Table(title="Best design (drawn, open configuration)")
    for col in ("variable", "stage 1", "final"):
        d.add_column(col)
    for var, val in best.design.items():
        d.add_row(var, f"{best.stage1_design[var]:.5g}", f"{val:.5g}")
    console.print(d)
    _render_targets(res)
    if not best.force_stage_improved:
        console.print("force stage: no design found with lower reactions and input moment at the same accuracy; "
                      "the stage-1 design is kept", highlight=False)
    for note in res.notes:
        console.print(f"note: {note}", highlight=False)
    if res.stopped_by_time_limit:
        console.print(f"note: stopped by the time limit ({time_limit:g} s)", highlight=False)


def _render_targets(res: Any) -> None:
    best = res.best_variant
    tg = Table(title="Targets: phalanx rotation (deg) at crank rotation (deg)")
    tg.add_column("crank")
    for link in best.achieved:
        tg.add_column(f"{link} target")
        tg.add_column(f"{link} achieved")
    for k, th in enumerate(res.targets["inputs"]):
        row = [f"{th:g}"]
        for link, ach in best.achieved.items():
            row += [f"{res.targets['rotations'][link][k]:.4g}", f"{ach[k]:.4g}"]
        tg.add_row(*row)
    console.print(tg)
