"""``--checkpoint FILE`` / ``--resume FILE`` of the long searches, and their Ctrl-C ending."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from mechsyn.cli.common import check_writable, err_console, safe
from mechsyn.cli.common import stop_if_interrupted as _stop
from mechsyn.errors import MechsynInputError
from mechsyn.io.files import existing_regular

CheckpointOpt = Annotated[Optional[Path], typer.Option(
    "--checkpoint", help="Save finished restarts to this file as the run goes.")]
ResumeOpt = Annotated[Optional[Path], typer.Option(
    "--resume", help="Continue the run saved in this checkpoint (same options).")]


def checkpoint_options(checkpoint: Path | None, resume: Path | None) -> dict[str, Any]:
    """The library's ``checkpoint=``/``resume=`` arguments of the two options, checked
    before any work (one of them; the file writable)."""
    if checkpoint is not None and resume is not None:
        raise MechsynInputError("give --checkpoint or --resume, not both", source="--resume",
                                hint="--resume FILE continues the run in FILE and keeps saving to it")
    if resume is not None:
        if not existing_regular(resume, "checkpoint file"):
            raise MechsynInputError("no such checkpoint file", source=str(resume),
                                    hint="give the file written by --checkpoint (or start with --checkpoint FILE)")
        check_writable(resume, "--resume")
        return {"checkpoint": resume, "resume": True}
    check_writable(checkpoint, "--checkpoint")
    return {"checkpoint": checkpoint, "resume": False} if checkpoint is not None else {}


def stop_if_interrupted(result: Any, options: dict[str, Any] | None = None) -> None:
    """Exit 130 when Ctrl-C ended ``result``, saying how to continue from the checkpoint."""
    if getattr(result, "interrupted", False) and options and options.get("checkpoint") is not None:
        name = safe(options["checkpoint"])
        err_console.print(f"checkpoint saved: {name} (continue with --resume {name})", highlight=False,
                          soft_wrap=True)
    _stop(result)
