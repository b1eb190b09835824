"""MkDocs hook: the docstrings' Sphinx roles rendered as links.

The docstrings cross-reference as numpydoc does, with roles: ``:func:`mechsyn.simulate```,
``:class:`~mechsyn.structure.rank.RankAnalysis``` (``~``: show the last name only),
``:meth:`Simulation.animate``` (a name relative to where it is written). Rendered as they
are, a page shows ``:func:`` and the name as code. This hook turns each into an
``<autoref optional>`` element, which mkdocs-autorefs resolves to a link to the object's
heading in the API reference (and to the plain name where the object has no page: a
private helper, an object of another package).

A relative name is resolved the way Sphinx does it: against the object whose
documentation it is in (the nearest heading before it), then that object's parents,
then anywhere in mechsyn when one object only has that name.
"""

from __future__ import annotations

import html
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src"

_ROLE = re.compile(r":(?:py:)?(?P<role>func|class|meth|mod|attr|data|obj|exc|const):"
                   r"<code>(?P<tilde>~?)(?P<target>\.?[A-Za-z_][\w.]*?)(?P<call>\(\))?</code>")
_ANCHOR = re.compile(r'id="(?P<path>mechsyn(?:\.[A-Za-z_]\w*)*)"')

#: every object path of mechsyn (aliases included) -> the path of the object it names
_INDEX: dict[str, str] = {}
#: last name -> the canonical paths that end with it
_BY_NAME: dict[str, set[str]] = {}


def build_index() -> dict[str, str]:
    """Every object of the mechsyn package (modules, classes, functions, attributes, and the
    names a module re-exports) -> its canonical path, read from the source by griffe."""
    import griffe

    package = griffe.load("mechsyn", search_paths=[str(SRC)], allow_inspection=False,
                          resolve_aliases=False)
    index: dict[str, str] = {}

    def walk(obj) -> None:
        for member in obj.members.values():
            if member.is_alias:
                target = member.target_path
                if target.startswith("mechsyn"):
                    index[member.path] = target
                continue
            index[member.path] = member.path
            if member.is_module or member.is_class:
                walk(member)

    index[package.path] = package.path
    walk(package)
    return index


def _load() -> None:
    if not _INDEX:
        _INDEX.update(build_index())
        for canonical in set(_INDEX.values()):
            _BY_NAME.setdefault(canonical.rsplit(".", 1)[-1], set()).add(canonical)


def resolve(target: str, context: str | None) -> str | None:
    """The canonical path ``target`` names, written in the documentation of ``context``
    (a dotted path, or None), or None when no mechsyn object has that name.

    Examples
    --------
    >>> resolve("mechsyn.structure.rank.analyze_rank", None)
    'mechsyn.structure.rank.analyze_rank'
    >>> resolve("analyze_rank", "mechsyn.structure.rank")
    'mechsyn.structure.rank.analyze_rank'
    >>> resolve("numpy.ndarray", None) is None
    True
    """
    _load()
    target = target.lstrip(".")  # ``.descriptors``: relative to where it is written
    if target in _INDEX:
        return _INDEX[target]
    scope = context or ""
    while scope:
        if f"{scope}.{target}" in _INDEX:
            return _INDEX[f"{scope}.{target}"]
        scope = scope.rpartition(".")[0]
    if f"mechsyn.{target}" in _INDEX:
        return _INDEX[f"mechsyn.{target}"]
    last = target.rsplit(".", 1)[-1]
    found = [p for p in _BY_NAME.get(last, ()) if p == target or p.endswith("." + target)]
    return found[0] if len(found) == 1 else None


def link_roles(text: str) -> str:
    """``text`` (a page's HTML) with every role replaced by an optional autoref (or, for a
    name that is no mechsyn object, the name as code)."""
    out, pos, context = [], 0, None
    events = sorted([(m.start(), "anchor", m) for m in _ANCHOR.finditer(text)]
                    + [(m.start(), "role", m) for m in _ROLE.finditer(text)], key=lambda e: e[0])
    for start, kind, m in events:
        if kind == "anchor":
            context = m.group("path")
            continue
        target = html.unescape(m.group("target"))
        shown = (target.rsplit(".", 1)[-1] if m.group("tilde") else target) + (m.group("call") or "")
        code = f"<code>{html.escape(shown)}</code>"
        path = resolve(target, context)
        out.append(text[pos:start])
        out.append(f'<autoref identifier="{path}" optional>{code}</autoref>' if path else code)
        pos = m.end()
    out.append(text[pos:])
    return "".join(out)


def on_page_content(html_text, page, config, files):
    return link_roles(html_text)
