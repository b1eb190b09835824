"""Entry point of the ``mechsyn`` console script.

Command modules are imported here for their side effect of registering on the app.
"""

from __future__ import annotations

import sys

from mechsyn.cli.app import app
from mechsyn.errors import MechsynInputError
from mechsyn.interrupt import INTERRUPT_EXIT_CODE

# Command modules (each registers its commands on the app when imported).
from mechsyn.cli import analyze as _analyze  # noqa: F401
from mechsyn.cli import synth_groups as _synth_groups  # noqa: F401
from mechsyn.cli import version as _version  # noqa: F401
from mechsyn.cli import atlas as _atlas  # noqa: F401
from mechsyn.cli import structure as _structure  # noqa: F401
from mechsyn.cli import finger as _finger  # noqa: F401
from mechsyn.cli import capability as _capability  # noqa: F401
from mechsyn.cli import belt as _belt  # noqa: F401
from mechsyn.cli import simulate as _simulate  # noqa: F401
from mechsyn.cli import synth_finger_design as _synth_finger_design  # noqa: F401
from mechsyn.cli import synth_path as _synth_path  # noqa: F401
from mechsyn.cli import synth_mechanism as _synth_mechanism  # noqa: F401
from mechsyn.cli import synth_curve as _synth_curve  # noqa: F401
from mechsyn.cli import curves as _curves  # noqa: F401
from mechsyn.cli import serve as _serve  # noqa: F401
from mechsyn.cli import convert as _convert  # noqa: F401
from mechsyn.cli import export as _export  # noqa: F401


def main(argv: list[str] | None = None) -> int:
    """Run the command line; bad input exits with status 2 and one message.

    Ctrl-C exits with status 130 and prints ``interrupted`` (searches have written their
    best result so far, marked as interrupted, before that).
    """
    from rich.markup import escape

    from mechsyn.cli.common import err_console

    try:
        # typer turns KeyboardInterrupt (and typer.Exit(n) raised by a command) into a
        # returned exit status when standalone_mode is off
        status = app(args=argv, prog_name="mechsyn", standalone_mode=False)
    except KeyboardInterrupt:
        status = INTERRUPT_EXIT_CODE
    except MechsynInputError as error:
        err_console.print(f"[bold red]error:[/] {escape(error.format())}", highlight=False, soft_wrap=True)
        return _exit(2, argv)
    except SystemExit as exc:  # typer.Exit inside commands
        return _exit(int(exc.code or 0), argv)
    except Exception as exc:  # click's (typer's vendored click's) own exceptions
        name = type(exc).__name__
        if name == "Abort":
            err_console.print("aborted")
            return _exit(130, argv)
        if hasattr(exc, "exit_code") and hasattr(exc, "show"):  # UsageError and friends
            exc.show()
            return _exit(int(exc.exit_code), argv)
        if hasattr(exc, "exit_code"):  # Exit
            return _exit(int(exc.exit_code), argv)
        raise
    if isinstance(status, int) and not isinstance(status, bool) and status != 0:
        if status == INTERRUPT_EXIT_CODE:
            err_console.print("interrupted", highlight=False)
        return _exit(status, argv)
    return _exit(0, argv)


def _exit(code: int, argv: list[str] | None) -> int:
    if argv is None:
        sys.exit(code)
    return code


if __name__ == "__main__":
    main()
