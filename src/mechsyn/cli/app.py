"""The Typer application objects that every command module registers on."""

from __future__ import annotations

import typer

app = typer.Typer(
    name="mechsyn",
    help=(
        "Structural analysis, kinematics and synthesis of mechanisms of robots, "
        "manipulators and grippers."
    ),
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    add_completion=True,  # mechsyn --install-completion / --show-completion (docs/python.md)
    context_settings={"help_option_names": ["-h", "--help"]},
)

synth_app = typer.Typer(
    help="Synthesis: structural (groups, fingers), dimensional (path, function, motion) and "
         "curve to mechanism.",
    rich_markup_mode=None,
    no_args_is_help=True,
    add_completion=False,
)  # reached through mechsyn.cli.main's lazy table, not add_typer (see there)
