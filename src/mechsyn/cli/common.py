"""Helpers shared by the command modules: output, errors, progress."""

from __future__ import annotations

import inspect
import os
import re
import sys
import tempfile
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Optional, TypeVar

import numpy as np
import typer
from rich.console import Console
from rich.table import Table as RichTable
from rich.markup import escape

from mechsyn.errors import MechsynInputError
from mechsyn.io.files import HIDDEN_CHARS, is_mechanism_file
from mechsyn.progress import Progress, ProgressCallback, counter
from mechsyn.results import dumps, write_atomic

T = TypeVar("T")

# Options shared by several commands (the default is given where the option is used).
SeedOpt = Annotated[int, typer.Option("--seed", help="Seed of the reproducible multi-start.")]
TimeLimitOpt = Annotated[float, typer.Option("--time-limit", help="Wall-clock budget in seconds.")]
RestartsOpt = Annotated[int, typer.Option("--restarts", help="Number of restarts (child seeds of --seed).")]
OptimizerOpt = Annotated[str, typer.Option("--optimizer", help="Global optimiser (de | random | registered).")]
WorkersOpt = Annotated[int, typer.Option("--workers", help="Run restarts in N local processes.")]
SchedulerOpt = Annotated[Optional[str], typer.Option(
    "--scheduler", help="Run restarts on a Dask cluster (scheduler address; extra mechsyn[dask]).")]

ForceOpt = Annotated[bool, typer.Option(
    "--force", help="Replace an existing output file even when it is not a mechanism file.")]

#: control characters, and the bidirectional controls and zero-width characters that
#: reorder or hide what a terminal shows (a name could show a μ of 90.0° as "0.09°")
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]|" + HIDDEN_CHARS.pattern)


def strip_control(text: str) -> str:
    """``text`` without control characters (escape sequences, bells, backspaces...) nor
    bidirectional controls and zero-width characters; newlines and tabs are kept.

    >>> strip_control("a\x1b[31mred\x07")
    'a[31mred'
    """
    return _CONTROL.sub("", text)


def safe(text: object, limit: int = 120) -> str:
    r"""Text from a file, fit to print: control characters stripped, rich markup escaped,
    capped at ``limit`` characters (the rest counted).

    >>> print(safe("[link=https://x.example]click[/link]"))
    \[link=https://x.example]click\[/link]
    >>> safe("x" * 130, limit=10)
    'xxxxxxxxxx… (120 more characters)'
    """
    text = strip_control(str(text))
    if len(text) > limit:
        text = f"{text[:limit]}… ({len(text) - limit} more characters)"
    return escape(text)


_TAG = re.compile(r"(?<!\\)\[([a-zA-Z#/@][^\[\]]*)\]")


@lru_cache(maxsize=512)
def _is_style(body: str) -> bool:
    from rich.errors import StyleSyntaxError
    from rich.style import Style

    name = body[1:] if body.startswith("/") else body
    if body == "/" or (body.startswith("/") and not name):
        return True
    if name.startswith("@") or "link" in name.lower():
        return False
    try:
        Style.parse(name)
    except (StyleSyntaxError, ValueError):
        return False
    return True


def guard_markup(text: str) -> str:
    r"""``text`` with every markup tag that is not a plain style escaped: a file's
    link, click or unknown tags (``[link=...]``, ``[@click]``, a link named in brackets)
    print as text; plain styles (bold, red, the closing tag) still style the commands' own
    messages.

    Examples
    --------
    >>> print(guard_markup("[bold]link[/] [crank] [link=https://x.example]x[/link]"))
    [bold]link[/] \[crank] \[link=https://x.example]x\[/link]
    """
    return _TAG.sub(lambda m: m.group(0) if _is_style(m.group(1)) else "\\" + m.group(0), text)


class SafeConsole(Console):
    """A rich Console that never sends a file's control characters to the terminal and
    never turns text into a hyperlink: every string it renders (messages and table cells,
    whatever the command) is stripped of control characters and its ``[link]`` markup is
    shown as text. The commands' own styles ([bold], [red]...) still work."""

    def render_str(self, text: str, *args: Any, **kwargs: Any) -> Any:
        from rich.errors import MarkupError, MissingStyle

        text = guard_markup(strip_control(text))
        try:
            return super().render_str(text, *args, **kwargs)
        except (MarkupError, MissingStyle):  # a file's "[/]" closed a tag: show it all as text
            return super().render_str(text, *args, **{**kwargs, "markup": False})


_NEGATIVE_ZERO = re.compile(r"(?<![\w.])-(0(?:\.0+)?)(?![\w.])")


def no_negative_zero(text: str) -> str:
    """``text`` with every number shown as a negative zero (``-0``, ``-0.0000``: float noise
    rounded) written without its sign.

    >>> no_negative_zero("-0.0000, -1, 0, -0.5, x-0")
    '0.0000, -1, 0, -0.5, x-0'
    """
    return _NEGATIVE_ZERO.sub(r"\1", text)


class Table(RichTable):
    """A rich Table whose cells wrap (fold) instead of being cut with an ellipsis: at 80
    columns a number is never shown truncated (1.60e-15 never becomes "1.60e…"); a number
    rounded to a negative zero (``-0.0000``) is shown as ``0.0000`` in every cell."""

    def add_column(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("overflow", "fold")
        super().add_column(*args, **kwargs)

    def add_row(self, *cells: Any, **kwargs: Any) -> None:
        super().add_row(*(no_negative_zero(c) if isinstance(c, str) else c for c in cells), **kwargs)


def fmt_number(value: Any, spec: str = ".6g", scale: float = 1.0) -> str:
    """A number for a table: ``—`` when missing or not finite, 0 for float noise (below
    1e-12 times ``scale``, e.g. -1.38778e-15 for a fixed pivot's velocity).

    >>> fmt_number(-1.38778e-15), fmt_number(2.5e-3), fmt_number(float("nan"))
    ('0', '0.0025', '—')
    """
    if value is None:
        return "—"
    v = float(value)
    if not np.isfinite(v):
        return "—"
    if abs(v) <= 1e-12 * abs(scale):
        v = 0.0
    return no_negative_zero(format(v, spec))


console = SafeConsole()
err_console = SafeConsole(stderr=True)


STDOUT = "-"


def is_stdout(path: Path | str | None) -> bool:
    """Whether an output option names standard output (``-o -``)."""
    return path is not None and str(path) == STDOUT


def say_written(path: Path | str, what: str = "") -> None:
    """``wrote PATH`` on stderr: every file a command writes is named (stdout stays the report's)."""
    err_console.print(f"wrote {escape(str(path))}{f' ({what})' if what else ''}", highlight=False, soft_wrap=True)


def write_output(out: Path | str, text: str) -> None:
    """Write ``text`` whole to the file ``out`` and say so on stderr, or to stdout when ``out`` is ``-``."""
    if is_stdout(out):
        sys.stdout.write(text)
        sys.stdout.flush()
    else:
        write_atomic(out, text)
        say_written(out)


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
    "point": "--point", "measure": "--measure", "segment": "--segment", "link": "--output", "folder": "--folder",
    "output": "--output", "straight": "--straight", "n_links": "--links", "mobility": "--mobility",
    "actuators": "--actuators", "phi/psi": "--phi/--psi", "case_id": "--case", "target_error": "--target-error",
    "min_transmission": "--min-transmission-angle", "fold_margin": "--fold-margin", "top": "--top",
    "circle_points": "--circle-points", "max_links": "--max-links", "max_link_ratio": "--max-link-ratio",
    "crank": "--crank", "database": "--database", "scheduler": "--scheduler", "pose": "--pose", "paths": "--path",
    "sweep": "--sweep", "width": "--width", "hole_diameter": "--hole", "clearance": "--clearance",
    "width/hole_diameter/clearance": "--width/--hole/--clearance", "dxf": "--dxf", "vll_modes": "--vll",
    "per_topology": "--per-topology", "interpolate": "--interpolate", "z": "--z", "grid": "--grid",
    "base_mobility": "--base-mobility", "base": "--base",
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
    """Refuse, before any work, an output file whose suffix is not one of ``suffixes`` or
    that cannot be written (see :func:`check_writable`).

    ``-`` (standard output) passes for text formats (.csv, .json, .yaml, .md, .pyslvs, .svg).
    """
    if is_stdout(path) and set(suffixes) & {".csv", ".json", ".yaml", ".md", ".pyslvs", ".svg", ".txt"}:
        return
    if path is not None and path.suffix.lower() not in suffixes:
        raise MechsynInputError(f"{path}: expected a {what or ' or '.join(suffixes)} file", source=option)
    check_writable(path, option)


def check_writable(path: Path | None, option: str, directory: bool = False) -> None:
    """Refuse, before any work, an output ``path`` that could not be written.

    Its folder is created (as the writer would) and a temporary file is created and
    removed in it: the real test, whatever the user's privileges. ``directory``: the path
    is a folder to write files into.
    """
    if path is None or is_stdout(path):
        return
    path = Path(path)
    if path.exists() and path.is_dir() != directory:
        raise MechsynInputError(f"{path} is {'not ' if directory else ''}a directory", source=option,
                                hint="give another path")
    if not directory and path.exists() and not path.is_file():  # a device, FIFO or socket: never replaced
        raise MechsynInputError(f"{path} is not a regular file (a device, FIFO or socket)", source=option,
                                hint="give the path of a file")
    folder = path if directory else path.absolute().parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=".mechsyn-write-test.")
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise MechsynInputError(f"cannot write {path}: {exc.strerror or exc}", source=option,
                                hint="give a path in a folder you can write to") from None


def check_overwrite(path: Path | str | None, option: str, force: bool = False) -> None:
    """Refuse, before any work, to replace an existing file that is not a mechanism file
    (:func:`is_mechanism_file`: a case file, notes, an image...) unless ``force``
    (``--force``). A mechanism file, e.g. the previous run's output, is replaced."""
    if path is None or force or is_stdout(path):
        return
    path = Path(path)
    if path.is_file() and not is_mechanism_file(path):
        raise MechsynInputError(f"{path} exists and is not a mechanism file; not overwritten", source=option,
                                hint="give another file, or add --force to replace it")


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
    say_written(path)


def check_animation_target(path: Path, option: str = "--animate") -> Path:
    """Raise MechsynInputError unless an animation can be written to ``path`` (before any work):
    .gif (Pillow), .mp4 (imageio-ffmpeg) or .html (a self-contained player)."""
    import importlib.util

    suffix = path.suffix.lower()
    if suffix not in (".gif", ".mp4", ".html"):
        raise MechsynInputError(f"animations are .gif, .mp4 or .html files, not {path.name}", source=option)
    need = {"gif": "PIL", "html": "PIL", "mp4": "imageio_ffmpeg"}[suffix[1:]]
    if importlib.util.find_spec(need) is None:
        extra = "pip install 'mechsyn[video]'" if suffix == ".mp4" else "pip install pillow"
        raise MechsynInputError(f"{option} {path.name} needs {need}", hint=extra, source=option)
    return path


def save_animation(path: Path, animate: Any, *args: Any, fps: int = 15, dpi: int = 80,
                   option: str = "--animate", **kwargs: Any) -> None:
    """Build an animation with a ``mechsyn.plot`` function on a bare Figure and write it to
    ``path`` as GIF, MP4 or HTML (by its suffix), whole or not at all."""
    from matplotlib.figure import Figure

    from mechsyn.export.movie import write_animation
    from mechsyn.plot.frames import animation_frames

    check_animation_target(path, option)
    fig = Figure()
    try:
        anim = animate(*args, fig=fig, **kwargs)
    except MechsynInputError as exc:
        raise exc.with_source(option) from None
    title = kwargs.get("title") or getattr(args[0], "mechanism", None) or "mechsyn animation"
    write_animation(animation_frames(anim, dpi), path, fps=fps, title=str(title))
    say_written(path)


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
def progress_bar(description: str, total: float | None = None, enabled: bool = True,
                 best: str = "best {:.6g}") -> Iterator[ProgressCallback | None]:
    """The command line's one view of a long computation's progress: a rich progress bar
    on stderr drawn from each :class:`mechsyn.progress.Progress` (``done`` of ``total``,
    the stage and message beside ``description``, the best so far formatted by ``best``,
    the time elapsed). Yields the ``progress`` callable to hand to the library call, or
    None (nothing to report) when ``enabled`` is false or stderr is not a terminal.
    ``total`` is used until a state gives its own.
    """
    if not enabled or not err_console.is_terminal:
        yield None
        return
    from rich.progress import BarColumn, TextColumn, TimeElapsedColumn
    from rich.progress import Progress as Bar

    with Bar(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[count]}"),
             TextColumn("{task.fields[best]}"), TimeElapsedColumn(), console=err_console, transient=True) as bar:
        task = bar.add_task(escape(description), total=total, count="", best="")

        def progress(state: Progress) -> None:
            of = state.total if state.total is not None else total
            words = ": ".join(w for w in (description, state.stage, state.message) if w)
            bar.update(task, description=escape(words), completed=state.done, total=of,
                       count=f"{state.done:g}/{of:g}" if of else "",
                       best="" if state.best is None else best.format(state.best))

        yield progress


def track(items: Iterable[T], description: str, total: int | None = None) -> Iterator[T]:
    """Iterate with a progress bar on stderr when it is a terminal."""
    with progress_bar(description, total) as progress:
        advance = counter(progress, total)
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
