"""Helpers shared by the command modules: output, errors, progress."""

from __future__ import annotations

import inspect
import sys
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, TypeVar

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from mechsyn.errors import MechsynInputError
from mechsyn.results import dumps, write_atomic

T = TypeVar("T")

console = Console()
err_console = Console(stderr=True)


STDOUT = "-"


def is_stdout(path: Path | str | None) -> bool:
    """Whether an output option names standard output (``-o -``)."""
    return path is not None and str(path) == STDOUT


def write_output(out: Path | str, text: str) -> None:
    """Write ``text`` whole to the file ``out``, or to stdout when ``out`` is ``-``."""
    if is_stdout(out):
        sys.stdout.write(text)
        sys.stdout.flush()
    else:
        write_atomic(out, text)


def one_stdout(json_: bool, *outs: Path | str | None) -> None:
    """Refuse two outputs to stdout (``--json`` and a ``-`` file, or two ``-`` files)."""
    if int(bool(json_)) + sum(is_stdout(o) for o in outs) > 1:
        raise MechsynInputError("two outputs to stdout", source="-",
                                hint="send one of them to a file (or drop --json)")


def emit_json(obj: Any, out: Path | None = None) -> None:
    """Print ``obj`` as JSON on stdout, or write it whole to ``out`` (``-``: stdout)."""
    text = dumps(obj)
    write_output(STDOUT if out is None else out, text + "\n")


#: The library's errors name its parameters (``MechsynInputError(field="tol")``); the command
#: line shows them as its options. One table for every command.
PARAMETER_OPTIONS: dict[str, str] = {
    "method": "--method", "tol": "--tol", "inputs": "--input", "points": "--points", "speeds": "--speed",
    "vll": "--vll", "animate": "--animate", "seed": "--seed", "time_limit": "--time-limit",
    "restarts": "--restarts", "workers": "--workers", "optimizer": "--optimizer", "direction": "--direction",
    "point": "--point", "measure": "--measure", "segment": "--segment", "link": "--output",
    "output": "--output", "straight": "--straight", "n_links": "--links", "mobility": "--mobility",
    "actuators": "--actuators", "phi/psi": "--phi/--psi",
}


def option_error(error: MechsynInputError) -> MechsynInputError:
    """``error`` with a library parameter (its ``field``) shown as the command-line option."""
    if error.source is None and error.field in PARAMETER_OPTIONS:
        return MechsynInputError(error.message, source=PARAMETER_OPTIONS[error.field], line=error.line,
                                 hint=error.hint)
    return error


def fail(message: str, hint: str | None = None, source: str | None = None) -> None:
    """Stop the command with one clear message and exit status 2."""
    raise MechsynInputError(message, hint=hint, source=source)


def parse_floats(text: str, option: str, count: int | None = None) -> list[float]:
    """Parse ``"1,2.5,-3"`` into floats, naming ``option`` on error."""
    try:
        values = [float(v) for v in text.split(",") if v.strip() != ""]
    except ValueError:
        raise MechsynInputError(
            f"expected comma-separated numbers, got {text!r}", source=option,
            hint=f"write e.g. {option} 1,0",
        ) from None
    if count is not None and len(values) != count:
        raise MechsynInputError(
            f"expected {count} numbers, got {len(values)} in {text!r}", source=option
        )
    return values


def check_output_suffix(path: Path | None, suffixes: tuple[str, ...], option: str,
                        what: str | None = None) -> None:
    """Refuse an output file whose suffix is not one of ``suffixes`` (before any work).

    ``-`` (standard output) passes for text formats (.csv, .json, .yaml, .md, .pyslvs, .svg).
    """
    if is_stdout(path) and set(suffixes) & {".csv", ".json", ".yaml", ".md", ".pyslvs", ".svg", ".txt"}:
        return
    if path is not None and path.suffix.lower() not in suffixes:
        raise MechsynInputError(f"{path}: expected a {what or ' or '.join(suffixes)} file", source=option)


def save_plot(path: Path, draw: Any, *args: Any, dpi: int = 110, figsize: tuple[float, float] = (7, 6),
              **kwargs: Any) -> None:
    """Draw with a ``mechsyn.plot`` function on a bare Figure (no pyplot, no backend) and write
    it whole to ``path``. ``draw`` takes ``fig=`` (it sizes the figure) or ``ax=``."""
    from matplotlib.figure import Figure

    from mechsyn.results import save_figure_atomic

    fig = Figure(figsize=figsize)
    if "fig" in inspect.signature(draw).parameters:
        draw(*args, fig=fig, **kwargs)
    else:
        draw(*args, ax=fig.add_subplot(), **kwargs)
        fig.tight_layout()
    save_figure_atomic(fig, path, dpi=dpi)


def check_animation_target(path: Path, option: str = "--animate") -> Path:
    """Raise MechsynInputError unless a GIF can be written to ``path`` (before any work)."""
    from matplotlib.animation import PillowWriter

    if not PillowWriter.isAvailable():
        raise MechsynInputError(f"{option} needs the pillow package", hint="pip install pillow", source=option)
    if path.suffix.lower() != ".gif":
        raise MechsynInputError(f"the animation is a GIF: use a .gif file name, not {path.name}", source=option)
    return path


def save_animation(path: Path, animate: Any, *args: Any, fps: int = 15, dpi: int = 80,
                   option: str = "--animate", **kwargs: Any) -> None:
    """Build an animation with a ``mechsyn.plot`` function on a bare Figure and write it to
    ``path`` as a GIF, whole or not at all."""
    from matplotlib.animation import PillowWriter
    from matplotlib.figure import Figure

    from mechsyn.results import atomic_output

    check_animation_target(path, option)
    fig = Figure()
    try:
        anim = animate(*args, fig=fig, **kwargs)
    except MechsynInputError as exc:
        raise exc.with_source(option) from None
    with atomic_output(path) as tmp:
        anim.save(str(tmp), writer=PillowWriter(fps=fps), dpi=dpi)


def parse_range(text: str, option: str, example: str = "0:360:1") -> tuple[float, float, float]:
    """Parse ``START:STOP:STEP`` (all three numbers) naming ``option`` on error.

    ``example`` is what the fix suggests writing after the option (e.g. ``A=0:360:1``).
    """
    parts = text.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        start, stop, step = (float(p) for p in parts)
    except ValueError:
        raise MechsynInputError(
            f"expected START:STOP:STEP, got {text!r}", source=option,
            hint=f"write e.g. {option} {example}",
        ) from None
    if step == 0 or (stop - start) * step < 0:
        raise MechsynInputError(
            f"step {step:g} does not lead from {start:g} to {stop:g}", source=option
        )
    return start, stop, step


@contextmanager
def progress_bar(description: str, total: int | None, enabled: bool = True) -> Iterator[Any]:
    """A rich progress bar on stderr (silent when ``enabled`` is false or not a TTY).

    Yields a callable ``advance(n=1)``.
    """
    if not enabled or not err_console.is_terminal:
        yield lambda n=1: None
        return
    with Progress(
        TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
        TimeRemainingColumn(), console=err_console, transient=True,
    ) as progress:
        task = progress.add_task(description, total=total)
        yield lambda n=1: progress.advance(task, n)


def track(items: Iterable[T], description: str, total: int | None = None) -> Iterator[T]:
    """Iterate with a progress bar on stderr when it is a terminal."""
    with progress_bar(description, total) as advance:
        for item in items:
            yield item
            advance()


def stop_if_interrupted(result: Any) -> None:
    """Exit with status 130 (``interrupted``) when ``result`` says Ctrl-C ended it.

    Called by a search command after it has written and shown its best result so far.
    """
    if getattr(result, "interrupted", False):
        from mechsyn.interrupt import INTERRUPT_EXIT_CODE

        raise typer.Exit(INTERRUPT_EXIT_CODE)


def exit_with(error: MechsynInputError) -> None:
    err_console.print(f"[bold red]error:[/] {escape(error.format())}", highlight=False, soft_wrap=True)
    raise typer.Exit(2)
