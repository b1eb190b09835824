"""``mechsyn synth groups``: paper 000's tables of groups to attach to a finger.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from mechsyn.cli.app import synth_app
from mechsyn.cli.common import emit_json
from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism


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
    from mechsyn.cli.render import render_groups
    from mechsyn.synthesis.reports import finger_groups

    if (base_mobility is None) == (base is None):
        raise MechsynInputError("give exactly one of --base-mobility and --base", source="synth groups",
                                hint="e.g. --base-mobility 2")
    mech = None if base is None else load_mechanism(base)
    try:
        table = finger_groups(actuators, max_links, base_mobility=base_mobility, base=mech)
    except MechsynInputError as exc:
        raise exc.with_source(str(base)) if exc.field == "base" else exc from None
    if json_out:
        emit_json(table)
        return
    render_groups(table, max_links)
