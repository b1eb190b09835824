"""File access of mechsyn studio, confined to the directory the server was started in.

A request names a file by a relative path. :func:`resolve_inside` refuses absolute
paths, drive letters, ``..`` components, hidden names and anything that resolves
(through symlinks) outside the root or to a hidden name inside it, with a
:class:`~mechsyn.errors.MechsynInputError` naming the field and the fix. Symlink loops
are refused as such (:func:`resolve_inside`) and skipped by the list.
"""

from __future__ import annotations

import os
from pathlib import Path, PurePosixPath

from mechsyn.errors import MechsynInputError

MECHANISM_SUFFIXES = (".yaml", ".yml", ".json")
READABLE_SUFFIXES = MECHANISM_SUFFIXES + (".pyslvs",)  # opened, not written
MAX_LISTED = 500
MAX_NAME = 1024  # characters of a relative path (a part: 255 bytes, the usual file-system limit)
SKIPPED_DIRS = ("node_modules", "__pycache__")


def resolve_inside(root: Path, name: object, field: str = "path") -> Path:
    """``root / name`` when it stays inside ``root`` (symlinks resolved), else an input error.

    >>> import tempfile
    >>> d = Path(tempfile.mkdtemp())
    >>> resolve_inside(d, "a.yaml") == d.resolve() / "a.yaml"
    True
    >>> resolve_inside(d, "../etc/passwd")
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: path: '..' is not allowed (fix: name a file inside the start directory)
    """
    if not isinstance(name, str) or not name.strip():
        raise MechsynInputError("a relative file name is needed", field=field, hint="e.g. mechanism.yaml")
    if len(name) > MAX_NAME or any(len(part.encode("utf-8", "surrogatepass")) > 255 for part in name.split("/")):
        raise MechsynInputError(f"the name is too long (at most {MAX_NAME} characters, 255 bytes a part)",
                                field=field, hint="give a shorter name")
    if "\x00" in name or "\\" in name or any("\ud800" <= c <= "\udfff" for c in name):
        raise MechsynInputError("the name has a forbidden character", field=field, hint="use / between folders")
    p = PurePosixPath(name)
    if p.is_absolute() or (len(name) > 1 and name[1] == ":"):
        raise MechsynInputError("absolute paths are not allowed", field=field,
                                hint="name a file inside the start directory")
    if any(part == ".." for part in p.parts):
        raise MechsynInputError("'..' is not allowed", field=field, hint="name a file inside the start directory")
    if any(part.startswith(".") for part in p.parts):
        raise MechsynInputError("hidden files are not served", field=field, hint="name a visible file")
    base = root.resolve()
    try:
        target = (base / p).resolve()
    except (OSError, RuntimeError):  # a symlink loop
        raise MechsynInputError("the path is a symlink loop", field=field, hint="name a file") from None
    if target != base and base not in target.parents:
        raise MechsynInputError("the path leads outside the start directory (symlink)", field=field,
                                hint="name a file inside the start directory")
    if any(part.startswith(".") for part in target.relative_to(base).parts):
        raise MechsynInputError("the path leads to a hidden file (symlink)", field=field, hint="name a visible file")
    return target


#: Characters a name for Save or an upload may not hold besides the unprintable ones: markup.
MARKUP = "<>"


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot name a file the studio writes or shows (None when it can):
    printable text only (no newline, tab or other control character, no bidi override or
    other format character such as U+202E, no line separator) and no markup (``<``, ``>``).

    >>> name_problem("four-bar (v2).yaml") is None
    True
    >>> name_problem("evil\u202eLMY.yaml")
    'the name holds U+202E, an invisible or control character: file names are printable text'
    >>> name_problem("<img src=x>.yaml")
    "the name holds '<': file names hold no markup"
    """
    for c in name:
        if not c.isprintable():
            return f"the name holds U+{ord(c):04X}, an invisible or control character: file names are printable text"
        if c in MARKUP:
            return f"the name holds {c!r}: file names hold no markup"
    return None


def mechanism_suffix(path: Path, field: str = "path", suffixes: tuple[str, ...] = MECHANISM_SUFFIXES) -> str:
    """The suffix of a mechanism file name, or an input error."""
    if path.suffix.lower() not in suffixes:
        raise MechsynInputError(f"{path.name}: not a mechanism file name", field=field,
                                hint="end it in .yaml, .yml or .json")
    return path.suffix.lower()


def list_mechanism_files(root: Path) -> list[str]:
    """Relative names of the YAML/JSON/Pyslvs files under ``root``: regular files whose
    resolved path stays inside ``root`` and is not hidden (symlink loops and dangling links
    skipped, symlinked folders not followed)."""
    base = root.resolve()
    out: list[str] = []
    for dirpath, dirnames, filenames in os.walk(base, onerror=lambda err: None):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d not in SKIPPED_DIRS)
        for f in sorted(filenames):
            if f.startswith(".") or Path(f).suffix.lower() not in READABLE_SUFFIXES:
                continue
            full = Path(dirpath) / f
            if _listable(base, full):
                out.append(full.relative_to(base).as_posix())
                if len(out) >= MAX_LISTED:
                    return out
    return out


def _listable(base: Path, full: Path) -> bool:
    """A regular file whose resolved path is inside ``base`` and not hidden there."""
    try:
        real = full.resolve(strict=True)
        if not real.is_file():
            return False
    except (OSError, RuntimeError):  # dangling link, symlink loop, no permission
        return False
    if base not in real.parents:
        return False
    return not any(part.startswith(".") for part in real.relative_to(base).parts)


def may_replace(path: Path, field: str = "path") -> int | None:
    """Before Save replaces ``path``: its permission bits to keep, or None for a new
    file; an input error unless it is a regular file holding a mechanism
    (:func:`mechsyn.io.files.is_mechanism_file`): a ``package.json`` or a
    ``docker-compose.yml`` is not replaced."""
    import stat

    from mechsyn.io.files import is_mechanism_file

    try:
        info = path.lstat()
    except FileNotFoundError:
        return None
    if not stat.S_ISREG(path.stat().st_mode) or not is_mechanism_file(path):
        raise MechsynInputError(f"{path.name} exists and is not a mechanism file; not replaced", field=field,
                                hint="save under another name")
    return stat.S_IMODE(path.stat().st_mode if stat.S_ISLNK(info.st_mode) else info.st_mode)
