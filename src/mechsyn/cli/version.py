"""``mechsyn version`` and ``mechsyn --version``."""

from __future__ import annotations

from typing import Annotated

import typer

from mechsyn.cli.app import app


def _print_version(value: bool) -> None:
    if value:
        version()
        raise typer.Exit()


@app.callback()
def root(
    version: Annotated[bool, typer.Option("--version", callback=_print_version, is_eager=True,
                                          help="Print mechsyn's version and exit.")] = False,
) -> None:
    """Structural analysis, kinematics and synthesis of mechanisms of robots, manipulators and
    grippers."""


@app.command("version")
def version() -> None:
    """Print mechsyn's version."""
    from mechsyn._version import __version__

    typer.echo(f"mechsyn {__version__}")
