"""Serialisation of result objects.

Every result of mechsyn is a dataclass (or pydantic model); :func:`to_jsonable` turns any
of them, with NumPy arrays and scalars inside, into plain JSON types, and
:func:`write_atomic` writes an output file whole or not at all.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import os
import tempfile
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from enum import Enum
from pathlib import Path
from typing import Any

import numpy as np


def counted(n: Any, one: str, many: str | None = None) -> str:
    """``n`` and the word for that many, as a report writes it (no "mobility(ies)").

    Examples
    --------
    >>> counted(1, "idle mobility", "idle mobilities"), counted(3, "redundant constraint")
    ('1 idle mobility', '3 redundant constraints')
    """
    return f"{n} {one if n == 1 else (many or one + 's')}"


def to_jsonable(obj: Any) -> Any:
    """Convert ``obj`` recursively into JSON-compatible Python values.

    Dataclasses (through their ``to_dict`` method when they have one), pydantic models,
    NumPy arrays and scalars, enums, paths, tuples and sets are converted; NaN and
    infinities become ``None`` (JSON has no such numbers).
    """
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, int):
        return obj
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, np.generic):
        return to_jsonable(obj.item())
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, Enum):
        return to_jsonable(obj.value)
    if isinstance(obj, Path):
        return str(obj)
    if hasattr(obj, "to_dict") and callable(obj.to_dict):
        return to_jsonable(obj.to_dict())
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if hasattr(obj, "model_dump"):
        return to_jsonable(obj.model_dump(mode="json"))
    if isinstance(obj, Mapping):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, set, frozenset)):
        return [to_jsonable(v) for v in obj]
    raise TypeError(f"cannot serialise {type(obj).__name__} to JSON")


def dumps(obj: Any, indent: int | None = 2) -> str:
    """JSON text of ``obj`` (see :func:`to_jsonable`)."""
    return json.dumps(to_jsonable(obj), indent=indent, ensure_ascii=False)


#: First characters that make a spreadsheet read a CSV cell as a formula (OWASP, "CSV Injection").
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def csv_cell(text: str) -> str:
    """A text cell of a CSV table, safe to open in a spreadsheet: a cell beginning with
    ``= + - @``, a tab or a carriage return is prefixed with ``'`` so that it stays text
    (the OWASP advice on CSV injection); a number (``-1.5``) is left as it is.

    Examples
    --------
    >>> print(csv_cell('=HYPERLINK("http://x","y")_x'))
    '=HYPERLINK("http://x","y")_x
    >>> csv_cell("B_x"), csv_cell("-1.5")
    ('B_x', '-1.5')
    """
    if not text.startswith(FORMULA_STARTS):
        return text
    try:
        float(text)
        return text
    except ValueError:
        return "'" + text


def csv_table(columns: Mapping[str, Any]) -> str:
    """Named columns of one length as a CSV table: the names as a header row
    (:func:`csv_cell`), floats as their ``repr`` (no digit lost), empty cells where not
    finite, booleans as 0 and 1 (a result's ``columns()``: ``assembled``).

    Examples
    --------
    >>> import numpy as np
    >>> print(csv_table({"x": np.array([1.5, np.nan]), "ok": np.array([True, False])}), end="")
    x,ok
    1.5,1
    ,0
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([csv_cell(h) for h in columns])  # names from the file: no formula reaches a spreadsheet
    cols = [np.asarray(c).astype(int) if np.asarray(c).dtype == bool else c for c in columns.values()]
    for row in zip(*cols):
        w.writerow(["" if (isinstance(v, float) and not np.isfinite(v)) else
                    (repr(float(v)) if isinstance(v, (float, np.floating)) else v) for v in row])
    return buf.getvalue()


def _umask_mode() -> int:
    """The mode a newly created file gets under the process's umask (0o666 & ~umask)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_atomic(path: str | os.PathLike[str], data: str | bytes, permissions: int | None = None) -> None:
    """Write ``data`` to ``path`` whole or not at all (temporary file, then rename).

    The file gets the permissions an ordinary new file would (the umask's), not the
    temporary file's 0600, or ``permissions`` when given (e.g. the replaced file's own).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    mode = "wb" if isinstance(data, bytes) else "w"
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, mode, **({} if mode == "wb" else {"encoding": "utf-8"})) as fh:
            fh.write(data)
        os.chmod(tmp, _umask_mode() if permissions is None else permissions)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


@contextmanager
def atomic_output(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success it replaces ``path`` whole.

    For writers that want a file name (Matplotlib's ``savefig``, animation writers): the
    output appears complete or not at all, with the umask's permissions.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=path.suffix)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, _umask_mode())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def save_figure_atomic(fig: Any, path: str | os.PathLike[str], **kwargs: Any) -> None:
    """Save a Matplotlib figure whole or not at all, format from the file's suffix."""
    with atomic_output(path) as tmp:
        fig.savefig(tmp, **kwargs)
