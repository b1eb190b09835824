"""Converting mechanism files between mechsyn's format and other tools' (Pyslvs).

The direction follows the file names: a ``.pyslvs`` (or ``.txt``) expression becomes a
``.yaml``/``.json`` mechanism file and the reverse.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from mechsyn.errors import MechsynInputError
from mechsyn.io.files import read_text, resolve_path
from mechsyn.io.load import load_mechanism, mechanism_from_dict, mechanism_text, mechanism_to_dict
from mechsyn.io.pyslvs import pyslvs_text, read_pyslvs
from mechsyn.model.mechanism import Mechanism

__all__ = ["Conversion", "convert_file", "load_any", "MECHSYN_SUFFIXES", "PYSLVS_SUFFIXES"]

MECHSYN_SUFFIXES = (".yaml", ".yml", ".json")
PYSLVS_SUFFIXES = (".pyslvs", ".txt")


@dataclass
class Conversion:
    """The converted file's text, its format and the notes on what was chosen or dropped."""

    source: str
    target_format: str
    text: str
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, object]:
        return {"source": self.source, "format": self.target_format, "notes": self.notes, "text": self.text}


def load_any(path: str | os.PathLike[str]) -> Mechanism:
    """A mechanism from a mechanism file (.yaml, .json) or a Pyslvs expression (.pyslvs, .txt)."""
    p = resolve_path(path)  # a bundled example's name stands for its file
    if p.suffix.lower() not in PYSLVS_SUFFIXES:
        return load_mechanism(p)
    data, _ = read_pyslvs(read_text(p, "Pyslvs file"), str(p))  # regular file, size limit (issue 27)
    return mechanism_from_dict(data, str(p))


def convert_file(path: str | os.PathLike[str], to: str, inputs: list[tuple[int, int]] | None = None,
                 name: str | None = None) -> Conversion:
    """Convert the file at ``path`` into the format of suffix ``to`` (``.yaml``, ``.json``, ``.pyslvs``).

    A Pyslvs expression is checked by building the mechanism (the same checks as any
    mechanism file); ``inputs`` are Pyslvs input pairs ``(base, drive)``.

    Examples
    --------
    >>> c = convert_file("examples/pyslvs/crank_rocker.pyslvs", ".yaml")  # doctest: +SKIP
    >>> c.text.splitlines()[0]  # doctest: +SKIP
    'name: crank_rocker'
    """
    p = resolve_path(path)  # a bundled example's name stands for its file
    src, to = p.suffix.lower(), to.lower()
    if src in PYSLVS_SUFFIXES and to in MECHSYN_SUFFIXES:
        text = read_text(p, "Pyslvs file")  # regular file, size limit, UTF-8 (issue 27)
        data, notes = read_pyslvs(text, str(p), inputs, name)
        mech = mechanism_from_dict(data, str(p))
        return Conversion(str(p), to.lstrip("."), mechanism_text(mech, to == ".json"), notes)
    if src in MECHSYN_SUFFIXES and to in PYSLVS_SUFFIXES:
        if inputs:
            raise MechsynInputError("input pairs apply to Pyslvs files being read", field="inputs",
                                    hint="mark the driven joints `actuated: true` in the mechanism file")
        text, notes = pyslvs_text(mechanism_to_dict(load_mechanism(p)), str(p))
        return Conversion(str(p), "pyslvs", text, notes)
    raise MechsynInputError(
        f"cannot convert {src or 'a file without suffix'} to {to or 'a file without suffix'}", source=str(p),
        hint="convert .pyslvs to .yaml/.json, or .yaml/.json to .pyslvs")
