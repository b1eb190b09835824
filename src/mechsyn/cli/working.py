"""A spinner on stderr while a long step without its own progress runs (reading a big
file, decomposing a large mechanism): the user sees the step and the time, never a
silent terminal. Nothing is shown when stderr is not a terminal."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from mechsyn.cli.common import err_console, safe

#: Input files above this size take about a second or more to read and check.
BIG_FILE_BYTES = 200_000
#: Mechanisms with this many joints take seconds to analyse.
LARGE_JOINTS = 1000


def big_file(path: Path) -> bool:
    """Whether ``path`` is large enough that reading it takes a second or more."""
    try:
        return Path(path).stat().st_size >= BIG_FILE_BYTES
    except OSError:
        return False  # the reader reports it


@contextmanager
def working(what: str, enabled: bool = True) -> Iterator[None]:
    """Show ``what`` with a spinner and the elapsed time while the block runs."""
    if not enabled or not err_console.is_terminal:
        yield
        return
    with err_console.status(what):
        yield


@contextmanager
def reading(path: Path) -> Iterator[None]:
    """:func:`working` while a big input file is read and checked."""
    with working(f"reading {safe(Path(path).name)} ({Path(path).stat().st_size if big_file(path) else 0:,} bytes)",
                 big_file(path)):
        yield
