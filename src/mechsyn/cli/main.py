"""Entry point of the ``mechsyn`` console script.

Commands are registered lazily: :data:`COMMANDS` names each command's module and its
one-line help, so ``mechsyn --help`` and ``mechsyn version`` import no command module (nor
NumPy, SciPy or Matplotlib), and ``mechsyn simulate ...`` imports only ``cli/simulate.py``.
A command module registers itself on :data:`mechsyn.cli.app.app` (or a sub-app) when
imported; a module imported eagerly here is picked up the same way.
"""

from __future__ import annotations

import time


def _process_age() -> float:
    """Seconds since this process started (Linux: ``/proc``; elsewhere 0: since now)."""
    import os

    try:
        with open("/proc/self/stat") as f:
            started = int(f.read().rsplit(")", 1)[1].split()[19]) / os.sysconf("SC_CLK_TCK")
        with open("/proc/uptime") as f:
            return max(0.0, float(f.read().split()[0]) - started)
    except (OSError, ValueError, IndexError, AttributeError):
        return 0.0


#: ``time.perf_counter()`` when the process started (where the system tells, else when the
#: command line began loading), or when :func:`main` was called in-process with ``argv``: a
#: command's time limit (``synth curve --time-limit``) counts from here, the interpreter's
#: start and every import included.
STARTED = time.perf_counter() - _process_age()

import importlib  # noqa: E402
import re  # noqa: E402
import signal  # noqa: E402
import sys  # noqa: E402
import threading  # noqa: E402
from typing import Any  # noqa: E402

import typer  # noqa: E402
from typer.core import TyperCommand  # noqa: E402

from mechsyn.cli import version as _version  # noqa: F401, E402  (the root callback: --version)
from mechsyn.cli.app import app  # noqa: E402
from mechsyn.errors import MechsynInputError  # noqa: E402

#: command -> (module(s) under mechsyn.cli, one-line help shown by ``mechsyn --help``)
COMMANDS: dict[str, tuple[tuple[str, ...], str]] = {
    "analyze": (("analyze",), "Structural analysis: mobility by the classic formulas and the rank method, "
                "redundant constraints, idle mobilities, drives, remedies."),
    "schema": (("analyze",), "Print the JSON Schema of mechanism files."),
    "structure": (("structure",), "Input links, Assur groups, structural formula and class of a planar "
                  "mechanism."),
    "simulate": (("simulate",), "Positions, velocities and accelerations of a planar mechanism over its "
                 "input."),
    "forces": (("simulate",), "Joint reactions and the balancing moment/force at each driven joint over "
               "the input."),
    "capability": (("capability",), "Largest tool speed along a direction under joint speed limits "
                   "(paper 004), at a point or over a grid."),
    "atlas": (("atlas",), "All non-isomorphic planar kinematic chains with N links and mobility F, and "
              "their mechanisms."),
    "belt": (("belt",), "Paper 001's manipulator with a belt on a pulley: synthesis, paths, speeds, "
             "accelerations, the inverse problem."),
    "synth": (("synth_groups", "finger", "synth_finger_design", "synth_path", "synth_mechanism",
               "synth_curve"),
              "Synthesis: structural (groups, fingers), dimensional (path, function, motion) and "
              "curve to mechanism."),
    "curves": (("curves",), "The local database of coupler curves used by synth curve: build or extend it."),
    "serve": (("serve",), "mechsyn studio: draw, drag, analyse and synthesise mechanisms in the browser "
              "(local server)."),
    "convert": (("convert",), "Convert Pyslvs mechanism expressions to mechanism files and back."),
    "export": (("export",), "Export a mechanism: DXF or SVG plates to cut, an SVG drawing at a pose."),
    "examples": (("examples",), "List the bundled example files by folder, or those a word finds; a name "
                 "works wherever a file is taken."),
}


def _load(name: str) -> Any:
    """Import the modules of command ``name`` and return its click command."""
    modules, _ = COMMANDS[name]
    for m in modules:
        importlib.import_module(f"mechsyn.cli.{m}")
    if name == "synth":
        from mechsyn.cli.app import synth_app

        return typer.main.get_command(synth_app)
    group = typer.main.get_command(app)
    return group.commands[name]  # type: ignore[attr-defined]


class _LazyCommand(TyperCommand):
    """Stands for a command whose module is not imported yet: lists itself with its help and
    hands parsing and running to the real command."""

    def __init__(self, name: str, help: str) -> None:
        super().__init__(name, help=help, short_help=help, add_help_option=False)

    def make_context(self, info_name: str | None, args: list[str], parent: Any = None, **extra: Any) -> Any:
        return _load(self.name).make_context(info_name, args, parent=parent, **extra)  # type: ignore[arg-type]

    def to_info_dict(self, ctx: Any) -> dict[str, Any]:
        return _load(self.name).to_info_dict(ctx)  # type: ignore[arg-type]


def build_cli() -> Any:
    """The root click group: eagerly registered commands plus the lazy ones."""
    group = typer.main.get_command(app)
    for name, (_, text) in COMMANDS.items():
        if name not in group.commands:  # type: ignore[attr-defined]
            group.add_command(_LazyCommand(name, text))  # type: ignore[attr-defined]
    return group  # type: ignore[return-value]


#: exit status of Ctrl-C (128 + SIGINT), as :data:`mechsyn.interrupt.INTERRUPT_EXIT_CODE`
_INTERRUPTED = 130
#: exit status of SIGTERM (128 + 15), handled like Ctrl-C
_TERMINATED = 143


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where Ctrl-C's KeyboardInterrupt would be: every search keeps its
    best so far, temporary files are removed, and the command exits with 143."""


_term = {"seen": False}


def _on_sigterm(signum: int, frame: Any) -> None:
    _term["seen"] = True
    raise Terminated()


def handle_sigterm() -> Any:
    """Handle SIGTERM like SIGINT (main thread only; elsewhere a no-op): the handler it
    replaced, for :func:`main` to restore."""
    _term["seen"] = False
    if threading.current_thread() is threading.main_thread():
        return signal.signal(signal.SIGTERM, _on_sigterm)
    return None


def main(argv: list[str] | None = None) -> int:
    """Run the command line; bad input exits with status 2 and one message.

    Ctrl-C exits with status 130 and prints ``interrupted``, SIGTERM the same with status
    143 and ``terminated`` (searches have written their best result so far, marked as
    interrupted, before that).
    """
    global STARTED
    if argv is not None:  # called in-process (not as the console script): its time counts from now
        STARTED = time.perf_counter()
    try:
        previous = handle_sigterm()
        try:
            return _main(argv)
        finally:
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)
    except (KeyboardInterrupt, Exception) as exc:
        if not interrupted(exc):
            raise
        from mechsyn.cli.common import err_console

        err_console.print("interrupted", highlight=False)
        return _exit(_INTERRUPTED, argv)


def interrupted(exc: BaseException | None) -> bool:
    """``exc`` is a KeyboardInterrupt or was raised while one was handled: Ctrl-C during a
    lazy import can surface as a RuntimeError or an ImportError whose cause or context is it.

    Examples
    --------
    >>> try:
    ...     try:
    ...         raise KeyboardInterrupt
    ...     except KeyboardInterrupt as ki:
    ...         raise RuntimeError("module failed to import") from ki
    ... except RuntimeError as err:
    ...     interrupted(err), interrupted(RuntimeError("a bug"))
    (True, False)
    """
    seen: set[int] = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def _main(argv: list[str] | None) -> int:
    try:
        status = build_cli().main(args=argv, prog_name="mechsyn", standalone_mode=False)
    except KeyboardInterrupt:
        status = _INTERRUPTED
    except MechsynInputError as error:
        from rich.markup import escape

        from mechsyn.cli.common import err_console, option_error

        err_console.print(f"[bold red]error:[/] {escape(option_error(error).format())}", highlight=False,
                          soft_wrap=True)
        return _exit(2, argv)
    except ModuleNotFoundError as exc:  # an optional feature's package: one line naming its extra
        return _exit(_missing_extra(exc), argv)
    except SystemExit as exc:  # typer.Exit inside commands
        return _exit(int(exc.code or 0), argv)
    except OSError as exc:  # a file the checks before the work could not foresee (disk full...)
        from mechsyn.cli.common import err_console, safe

        where = f"{safe(exc.filename)}: " if exc.filename else ""
        err_console.print(f"[bold red]error:[/] {where}{safe(exc.strerror or exc)} (fix: check the path, its "
                          "folder's permissions and the free space)", highlight=False, soft_wrap=True)
        return _exit(2, argv)
    except Exception as exc:  # click's (typer's vendored click's) own exceptions
        if type(exc).__name__ != "Abort":  # Abort: click's wrapping of Ctrl-C
            return _exit(_click_error(exc), argv)
        status = _INTERRUPTED
    if isinstance(status, int) and not isinstance(status, bool) and status != 0:
        if status == _INTERRUPTED:  # searches wrote their best so far before this
            from mechsyn.cli.common import err_console

            status = _TERMINATED if _term["seen"] else status
            err_console.print("terminated" if _term["seen"] else "interrupted", highlight=False)
        return _exit(status, argv)
    return _exit(0, argv)


def _missing_extra(exc: ModuleNotFoundError) -> int:
    """Show a missing optional package as one line naming its extra (status 2); re-raise a
    missing module that no extra installs (a broken install: the traceback helps)."""
    from mechsyn._extras import extra_for, missing

    if extra_for(exc.name or "") is None:
        raise exc
    from rich.markup import escape

    from mechsyn.cli.common import err_console

    err_console.print(f"[bold red]error:[/] {escape(missing(exc.name or '', 'this command').format())}",
                      highlight=False, soft_wrap=True)
    return 2


def _click_error(exc: Exception) -> int:
    """Show one of click's exceptions (usage errors in one line: where, what, the fix) and
    return its exit status; re-raise anything else."""
    if hasattr(exc, "exit_code") and hasattr(exc, "show"):  # UsageError and friends
        if type(exc).__name__ == "NoArgsIsHelpError" or not hasattr(exc, "format_message"):
            exc.show()  # the help text itself
        else:
            from rich.markup import escape

            from mechsyn.cli.common import err_console

            ctx = getattr(exc, "ctx", None)
            where = ctx.command_path if ctx is not None else "mechsyn"
            err_console.print(f"[bold red]error:[/] {escape(where)}: {escape(_suggested(exc, ctx))} "
                              f"(fix: see '{escape(where)} -h')", highlight=False, soft_wrap=True)
        return int(exc.exit_code)
    if hasattr(exc, "exit_code"):  # Exit
        return int(exc.exit_code)
    raise exc


def _suggested(exc: Exception, ctx) -> str:
    """click's message, with "Did you mean ...?" for a mistyped command where this click
    does not add it itself (click < 8.3 suggests only in some versions)."""
    import difflib

    message = exc.format_message()
    found = re.match(r"No such command '(.+)'\.?$", message)
    if found is None or "Did you mean" in message or ctx is None or not hasattr(ctx.command, "list_commands"):
        return message
    close = difflib.get_close_matches(found.group(1), ctx.command.list_commands(ctx), n=1)
    return f"{message.rstrip('.')}. Did you mean '{close[0]}'?" if close else message


def _exit(code: int, argv: list[str] | None) -> int:
    if argv is None:
        # the process ends here: no cyclic collection at the interpreter's teardown (its passes
        # over every object took 1 s after a curve search under load, past the time limit)
        import gc

        gc.disable()
        gc.freeze()
        sys.exit(code)
    return code


if __name__ == "__main__":
    main()
