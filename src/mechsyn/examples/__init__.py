"""The example files shipped with mechsyn: mechanisms of the papers and the textbooks, arm
files, belt, synthesis and finger-design cases.

>>> import mechsyn as ms
>>> "crank_rocker" in ms.examples.names()
True
>>> m = ms.examples.load("crank_rocker")
>>> m.name
'Crank-rocker four-bar'
>>> ms.examples.path("paper001").name
'paper001.yaml'

``list()`` gives a table of them all (name, folder, kind, title). The command line
accepts an example's name where it takes a file: ``mechsyn analyze fourbar``.

In a wheel the files live in this package's ``data`` folder (copied there from the
repository's ``examples/`` when the wheel is built, see ``setup.py``); in a source checkout
they are read from ``examples/`` itself.
"""

from __future__ import annotations

import builtins
import functools
from pathlib import Path
from typing import Any, NamedTuple

from mechsyn.errors import MechsynInputError

__all__ = ["Example", "list", "load", "names", "path", "resolve", "root", "did_you_mean", "missing_hint", "search"]

_SUFFIXES = (".yaml", ".yml", ".json", ".urdf")


def root() -> Path:
    """The folder that holds the example files."""
    here = Path(__file__).resolve().parent
    shipped = here / "data"
    if shipped.is_dir():
        return shipped
    return here.parents[2] / "examples"  # a source checkout: src/mechsyn/examples -> examples/


class Example(NamedTuple):
    """One example file: its ``name`` (the file stem), ``folder``, ``kind`` (``mechanism``,
    ``arm``, ``belt case``, ``synthesis case``, ``finger-design case``) and ``title``."""

    name: str
    folder: str
    kind: str
    title: str
    path: Path


class Catalogue(builtins.list):  # type: ignore[type-arg]
    """A list of :class:`Example` that prints as a table."""

    def __str__(self, width: int = 80) -> str:
        w = max((len(e.name) for e in self), default=4)
        k = max((len(e.kind) for e in self), default=4)
        room = max(12, width - w - k - 4)

        def cut(t: str) -> str:
            return t if len(t) <= room else t[:room - 1] + "…"

        rows = [f"{'name':<{w}}  {'kind':<{k}}  title"]
        rows += [f"{e.name:<{w}}  {e.kind:<{k}}  {cut(e.title)}" for e in self]
        return "\n".join(rows)

    __repr__ = __str__

    def _repr_markdown_(self) -> str:
        rows = ["| name | folder | kind | title |", "|---|---|---|---|"]
        rows += [f"| {e.name} | {e.folder} | {e.kind} | {e.title} |" for e in self]
        return "\n".join(rows)


def _kind(p: Path, data: Any) -> tuple[str, str]:
    if p.suffix == ".urdf":
        return "arm", p.stem
    if not isinstance(data, dict):
        return "file", p.stem
    title = str(data.get("name") or data.get("title") or data.get("description") or p.stem)
    title = title.strip().splitlines()[0] if title.strip() else p.stem
    if "joints" in data and "links" in data and "ground" in data:
        return "mechanism", title
    if p.parent.name == "capability" or "type" in data and data.get("type") in ("planar_serial", "dh", "urdf"):
        return "arm", title
    if p.parent.name == "belt":
        return "belt case", title
    if p.parent.name == "fingers":
        return "finger-design case", title
    return "synthesis case", title


@functools.lru_cache(maxsize=1)
def _catalogue() -> Catalogue:
    from mechsyn.io.load import safe_load_yaml

    base = root()
    files = sorted((p for p in base.rglob("*") if p.suffix in _SUFFIXES and p.is_file()),
                   key=lambda p: (p.parent.as_posix(), p.stem, p.suffix == ".urdf", p.suffix))
    out = Catalogue()
    for p in files:
        try:
            data = safe_load_yaml(p.read_text(encoding="utf-8")) if p.suffix != ".urdf" else None
        except Exception:  # noqa: BLE001 -- a catalogue lists what it cannot parse too
            data = None
        kind, title = _kind(p, data)
        out.append(Example(p.stem, p.parent.relative_to(base).as_posix(), kind, title, p))
    return out


def list() -> Catalogue:  # noqa: A001 -- ms.examples.list() reads as the field's catalogues do
    """Every example file, as a table (name, folder, kind, title).

    Examples
    --------
    >>> import mechsyn as ms
    >>> table = ms.examples.list()
    >>> sorted({e.kind for e in table})[:3]
    ['arm', 'belt case', 'finger-design case']
    """
    seen: set[tuple[str, str]] = set()
    out = Catalogue()
    for e in _catalogue():  # one example in two files (paper004_3r.yaml and .urdf): listed once, as path() finds it
        if (e.folder, e.name) not in seen:
            seen.add((e.folder, e.name))
            out.append(e)
    return out


def search(word: str | None = None, folder: str | None = None) -> Catalogue:
    """The examples whose name, folder, kind or title holds ``word`` (any case), in
    ``folder`` when given (``kinematics``, ``textbook``...: :func:`list` names them).

    Examples
    --------
    >>> [e.name for e in search("bennett")]
    ['bennett_tilted', 'bennett', 'bennett_4dp']
    >>> search(folder="nowhere")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: folder: no example folder 'nowhere' (fix: folders: belt, capability, ...)
    """
    every = list()
    folders = sorted({e.folder for e in every})
    if folder is not None and folder.strip("/") not in folders:
        close = did_you_mean(folder, folders)
        raise MechsynInputError(f"no example folder {folder!r}", field="folder",
                                hint=(f"did you mean {close[0]!r}? " if close else "") + "folders: "
                                + ", ".join(folders))
    w = (word or "").lower()
    return Catalogue(e for e in every if (folder is None or e.folder == folder.strip("/"))
                     and (not w or any(w in t.lower() for t in (e.name, e.folder, e.kind, e.title))))


def did_you_mean(name: str, choices: builtins.list[str] | None = None) -> builtins.list[str]:
    """The example names (or ``choices``) closest to a mistyped ``name``, best first.

    Examples
    --------
    >>> did_you_mean("fourbarr")
    ['fourbar']
    """
    import difflib

    return difflib.get_close_matches(str(name), choices if choices is not None else names(), n=3, cutoff=0.75)


def missing_hint(file: str | Path) -> str:
    """The fix of a "no such file" message: the example names close to ``file``, if any.

    Examples
    --------
    >>> missing_hint("fourbarr")
    "did you mean the example 'fourbar'? (`mechsyn examples` lists them all)"
    """
    p = Path(file)
    close = did_you_mean(p.stem) if len(p.parts) == 1 and p.suffix in ("", *_SUFFIXES) else []
    if close:
        return ("did you mean the example " + " or ".join(repr(c) for c in close)
                + "? (`mechsyn examples` lists them all)")
    return "check the path (`mechsyn examples` lists the bundled examples)"


def names() -> builtins.list[str]:
    """The examples' names (file stems), sorted.

    Examples
    --------
    >>> import mechsyn as ms
    >>> "fourbar" in ms.examples.names()
    True
    """
    return sorted({e.name for e in _catalogue()})


def path(name: str) -> Path:
    """The file of example ``name`` (its stem, or ``folder/file.ext`` where stems repeat;
    a YAML file is preferred to a URDF of the same stem).

    Examples
    --------
    >>> import mechsyn as ms
    >>> ms.examples.path("paper004_3r").suffix, ms.examples.path("capability/paper004_3r.urdf").suffix
    ('.yaml', '.urdf')
    """
    for e in _catalogue():
        rel = f"{e.folder}/{e.path.name}"
        if name in (rel, e.path.name, f"{e.folder}/{e.name}"):
            return e.path
    shipped = root() / name  # folder/file.ext of a file outside the catalogue (a .pyslvs)
    if len(Path(name).parts) == 2 and ".." not in Path(name).parts and shipped.is_file():
        return shipped
    same = [e for e in _catalogue() if e.name == name]
    if same:
        return min(same, key=lambda e: e.path.suffix == ".urdf").path
    close = did_you_mean(name)
    raise MechsynInputError(f"no example {name!r}", field="name",
                            hint=(f"did you mean {' or '.join(map(repr, close))}? " if close else "")
                            + "`mechsyn examples` lists them (in Python: mechsyn.examples.names()), e.g. "
                            + ", ".join(names()[:4]))


def resolve(file: str | Path) -> Path:
    """``file`` itself when it exists, else the bundled example it names when there is one
    (a stem, a file name or ``folder/file.ext``: how the command line accepts
    ``mechsyn analyze fourbar`` and ``mechsyn convert pyslvs/jansen.pyslvs``).

    Examples
    --------
    >>> import mechsyn as ms
    >>> ms.examples.resolve("fourbar").name
    'fourbar.yaml'
    >>> ms.examples.resolve("pyslvs/jansen.pyslvs").parent.name
    'pyslvs'
    """
    p = Path(file)
    if p.exists() or p.is_absolute() or len(p.parts) > 2:
        return p
    try:  # a stem, a file name or folder/file of a bundled example
        return path(p.as_posix())
    except MechsynInputError:
        return p


def load(name: str) -> Any:
    """Example ``name`` as a :class:`~mechsyn.model.Mechanism` (mechanism files), or a
    :class:`~mechsyn.capability.arm.SerialArm` (arm files).

    Examples
    --------
    >>> import mechsyn as ms
    >>> ms.examples.load("fourbar").n_moving
    3
    >>> ms.examples.load("paper004_3r").n
    3
    """
    p = path(name)
    kind = next(e.kind for e in _catalogue() if e.path == p)
    if kind == "mechanism":
        from mechsyn.io.load import load_mechanism

        return load_mechanism(p)
    if kind == "arm":
        from mechsyn.capability.arm_file import load_arm

        return load_arm(p)
    raise MechsynInputError(f"example {name!r} is a {kind}, not a mechanism or an arm", field="name",
                            hint=f"read it with its own loader from mechsyn.examples.path({name!r})")
