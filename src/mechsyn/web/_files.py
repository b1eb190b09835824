"""File access of mechsyn studio, confined to the directory the server was started in.

A request names a file by a relative path. :func:`resolve_inside` refuses absolute
paths, drive letters, ``..`` components, hidden names and anything that resolves
(through symlinks) outside the root, with a :class:`~mechsyn.errors.MechsynInputError`
naming the field and the fix.
"""

from __future__ import annotations

import os
from pathlib import Path, PurePosixPath

from mechsyn.errors import MechsynInputError

MECHANISM_SUFFIXES = (".yaml", ".yml", ".json")
READABLE_SUFFIXES = MECHANISM_SUFFIXES + (".pyslvs",)  # opened, not written
MAX_LISTED = 500


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
    if "\x00" in name or "\\" in name:
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
    target = (base / p).resolve()
    if target != base and base not in target.parents:
        raise MechsynInputError("the path leads outside the start directory (symlink)", field=field,
                                hint="name a file inside the start directory")
    return target


def mechanism_suffix(path: Path, field: str = "path", suffixes: tuple[str, ...] = MECHANISM_SUFFIXES) -> str:
    """The suffix of a mechanism file name, or an input error."""
    if path.suffix.lower() not in suffixes:
        raise MechsynInputError(f"{path.name}: not a mechanism file name", field=field,
                                hint="end it in .yaml, .yml or .json")
    return path.suffix.lower()


def list_mechanism_files(root: Path) -> list[str]:
    """Relative names of the YAML/JSON/Pyslvs files under ``root`` (not following symlinks out, no hidden)."""
    base = root.resolve()
    out: list[str] = []
    for dirpath, dirnames, filenames in os.walk(base):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d not in ("node_modules", "__pycache__"))
        for f in sorted(filenames):
            if f.startswith(".") or Path(f).suffix.lower() not in READABLE_SUFFIXES:
                continue
            full = Path(dirpath) / f
            if full.resolve() != full and base not in full.resolve().parents:
                continue
            out.append(full.relative_to(base).as_posix())
            if len(out) >= MAX_LISTED:
                return out
    return out
