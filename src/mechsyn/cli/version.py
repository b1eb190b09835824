"""``mechsyn version``."""

from __future__ import annotations

import typer

from mechsyn import __version__
from mechsyn.cli.app import app


@app.command("version")
def version() -> None:
    """Print mechsyn's version."""
    typer.echo(f"mechsyn {__version__}")
