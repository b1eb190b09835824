"""``mechsyn synth groups``: paper 000's tables of groups to attach to a finger.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg; journal, volume and year are
   not in the project's copy ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer
from mechsyn.cli.common import Table  # cells fold, numbers never cut

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import console, emit_json
from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism
from mechsyn.structure.analysis import analyze_structure
from mechsyn.synthesis.finger.groups import group_table


@synth_app.command("groups")
def groups(
    base_mobility: Annotated[Optional[int], typer.Option("--base-mobility", "-w", help="W0 of the base mechanism.")] = None,
    base: Annotated[Optional[Path], typer.Option("--base", help="Base mechanism file (W0 from Chebyshev's formula).")] = None,
    actuators: Annotated[int, typer.Option("--actuators", "-a", min=1, help="Drives of the finger (A).")] = 1,
    max_links: Annotated[int, typer.Option("--max-links", min=1, max=50, help="Largest group size n_f.")] = 5,
    json_out: Annotated[bool, typer.Option("--json", help="Print JSON.")] = False,
) -> None:
    """Groups (n_f links, P_f pairs, m_f free leashes) that make a finger of mobility W0
    fully actuated by A drives with its variable-length links locked (paper 000, steps 1-6)."""
    if (base_mobility is None) == (base is None):
        raise MechsynInputError("give exactly one of --base-mobility and --base", source="synth groups",
                                hint="e.g. --base-mobility 2")
    w0 = base_mobility
    if base is not None:
        mech = load_mechanism(base)
        if mech.kind != "planar":
            raise MechsynInputError("paper 000's count is for planar fingers", source=str(base))
        w0 = int(analyze_structure(mech).formulas["chebyshev"].value)
    assert w0 is not None
    if w0 <= actuators:
        raise MechsynInputError(f"W0 = {w0} is not larger than the {actuators} drive(s): the finger is "
                                "already fully actuated, nothing to attach", source="--base-mobility")
    table = group_table(w0, actuators, max_links)
    if json_out:
        emit_json(table)
        return
    console.print(f"W0 = {table.W0}, A = {table.actuators}: W_f = -(W0 - A) = {table.W_f}; "
                  f"the base needs m_0 = 2(W0 - 1) = {table.m_0} free leashes", highlight=False)
    t = Table(title="Groups to attach (paper 000)")
    t.add_column("n_f", justify="right")
    t.add_column("P_f", justify="right")
    t.add_column("m_f", justify="right")
    t.add_column("conditions")
    by_n = {r.n_f: r for r in table.rows}
    for n in range(1, max_links + 1):
        r = by_n.get(n)
        if r is None:
            t.add_row(str(n), "-", "-", "no integer P_f")
        else:
            t.add_row(str(n), str(r.P_f), str(r.m_f),
                      "met" if r.meets_conditions else f"not met (needs P_f >= {2 * (w0 - 1) + n - 1}, m_f >= {table.m_0})")
    console.print(t)
