"""``mechsyn synth finger``: paper 000's attachment of a group to an adaptive finger.

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

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import Table, console, emit_json  # Table: cells fold, numbers never cut


@synth_app.command("finger")
def finger(
    base: Path = typer.Argument(..., help="Base mechanism of the finger (planar, W0 > A)."),
    actuators: int = typer.Option(1, "--actuators", "-a", min=1, help="Drives A."),
    max_links: int = typer.Option(5, "--max-links", min=1, max=6, help="Largest group n_f."),
    out: Optional[Path] = typer.Option(
        None, "--out", "-o", help="Directory for one mechanism file per result + drawing."),
    json_out: bool = typer.Option(False, "--json", help="Print JSON."),
    separate: bool = typer.Option(
        False, "--separate", help="Attach W0 - A groups of W_f = -1 instead of one group."),
) -> None:
    """Attach a group of links to the finger's free leashes so that it is fully actuated
    with its variable-length links (VLL) locked; list VLL candidates (paper 000)."""
    from mechsyn.io import load_mechanism
    from mechsyn.synthesis.finger.candidates import synthesize_fingers

    mech = load_mechanism(base)
    synth = synthesize_fingers(mech, actuators, max_links, separate=separate)
    if out is not None:
        synth = _write_files(synth, mech, out)
    if json_out:
        emit_json(synth)
        return
    _render(synth)


def _write_files(synth: Any, mech: Any, out: Path) -> Any:
    """One mechanism file per finger and their drawing in ``out``; the results with their files."""
    from dataclasses import replace

    from mechsyn.cli.common import save_plot, say_written
    from mechsyn.io import mechanism_to_dict, write_mechanism
    from mechsyn.plot.finger import plot_fingers

    new = []
    for r in synth.results:
        path = out / f"finger_{r.number:03d}_nf{r.n_f}.yaml"
        write_mechanism(r.mechanism, path)
        new.append(replace(r, file=str(path)))
    say_written(out, f"{len(new)} mechanism files")
    save_plot(out / "fingers.png", plot_fingers, new[:39], mechanism_to_dict(mech),
              f"{mech.name}: W0 = {synth.W0}, A = {synth.actuators}")
    return replace(synth, results=new)


def _render(synth: Any) -> None:
    console.print(f"[bold]{synth.base_name}[/]: W0 = {synth.W0}, A = {synth.actuators}, "
                  f"W_f = -(W0 - A) = {synth.W_f}, m_0 = 2(W0 - 1) = {synth.m_0}", highlight=False)
    console.print(f"base structure: {synth.base_formula}", highlight=False)
    console.print("admissible groups: " + "; ".join(
        f"(n_f={r.n_f}, P_f={r.P_f}, m_f={r.m_f})" for r in synth.groups), highlight=False)
    t = Table(title=f"{len(synth.results)} distinct fingers")
    for col in ("#", "groups (n_f, P_f)", "attached to", "structure (VLL locked)", "VLL candidates",
                "W with VLL free"):
        t.add_column(col)
    for r in synth.results:
        free = "; ".join(f"{'+'.join(c.links)}: {c.underactuated_mobility}"
                         for c in r.vll_combinations if len(c.links) == 1)
        t.add_row(str(r.number), " + ".join(f"({n}, {p})" for n, p in r.groups),
                  ", ".join(f"{k}: {'/'.join(v)}" for k, v in r.attachments.items()),
                  r.structural_formula, ", ".join(r.vll_candidates), free)
    console.print(t)
    for note in synth.notes:
        console.print(f"note: {note}", highlight=False)
