"""The one reader of every input file (mechanism, case, arm, belt, table files).

:func:`read_text` and :func:`parse_data` turn every way a file can be unreadable into
one :class:`~mechsyn.errors.MechsynInputError` naming the file and the fix: missing,
a directory, unreadable, not UTF-8, larger than the limit ``file_bytes``, a syntax
error, nested deeper than ``nesting`` (a RecursionError otherwise) or holding more than
``values`` values (YAML aliases can expand a few lines into billions of items). The
limits are those of :mod:`mechsyn.limits` (see docs/reliability.md).

Examples
--------
>>> parse_data("a: [1, 2]", "case.yaml")
{'a': [1, 2]}
>>> parse_data("a: " + "[" * 300 + "]" * 300, "case.yaml")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mechsyn.errors.MechsynInputError: case.yaml: nested more than 64 levels deep ...
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from typing import Any

import yaml

#: LibYAML's safe parser where PyYAML was built with it (several times faster), else PyYAML's own.
_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)

from mechsyn.errors import MechsynInputError
from mechsyn.limits import limit, limit_hint

__all__ = ["read_text", "parse_data", "read_data", "check_data_size"]

_BRACKETS = re.compile(r"[\[\]{}]")


def read_text(path: str | os.PathLike[str], what: str = "file") -> str:
    """The UTF-8 text of ``path``; :class:`MechsynInputError` when it cannot be read.

    ``what`` names the kind of file in messages (``"case file"``, ``"table"``...).
    """
    from mechsyn.examples import resolve

    try:
        p = resolve(path)  # a bundled example's name stands for its file
        exists = p.exists()
    except OSError as exc:  # e.g. a name longer than the file system allows
        raise MechsynInputError(f"cannot read the {what}: {exc.strerror or exc}", source=str(path)[:200],
                                hint="check the path (each name at most 255 bytes)") from None
    if not exists:
        from mechsyn.examples import missing_hint

        raise MechsynInputError(f"no such {what}", source=str(p), hint=missing_hint(p))
    if p.is_dir():
        raise MechsynInputError(f"is a directory, not a {what}", source=str(p))
    try:
        size = p.stat().st_size
        if size > limit("file_bytes"):
            raise MechsynInputError(
                f"{what} of {size:,} bytes is larger than the limit of {limit('file_bytes'):,}",
                source=str(p), hint=limit_hint("file_bytes"))
        data = p.read_bytes()
    except OSError as exc:
        raise MechsynInputError(f"cannot read the {what}: {exc.strerror or exc}", source=str(p),
                                hint="check the path and its permissions") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise MechsynInputError(
            f"not UTF-8 text ({exc.reason} at byte {exc.start})", source=str(p),
            hint="save the file as UTF-8 text",
        ) from None


def _bracket_depth(text: str) -> int:
    """Upper bound of the flow-style nesting depth (brackets, ignoring quoting)."""
    depth = deepest = 0
    for m in _BRACKETS.finditer(text):
        depth = depth + 1 if m.group() in "[{" else max(depth - 1, 0)
        deepest = max(deepest, depth)
    return deepest


def check_data_size(data: Any, source: str) -> Any:
    """Refuse data nested deeper than the limit ``nesting`` or with more than
    ``values`` values (counted through shared YAML aliases); return ``data``."""
    deepest, budget = limit("nesting"), limit("values")
    stack = [(data, 1)]
    seen = 0
    while stack:
        node, depth = stack.pop()
        seen += 1
        if seen > budget:
            raise MechsynInputError(
                f"more than {budget:,} values (YAML aliases expanding into too many items?)",
                source=source, hint="write the data out without aliases; " + limit_hint("values"))
        if isinstance(node, dict):
            children = list(node.keys()) + list(node.values())
        elif isinstance(node, (list, tuple)):
            children = node
        else:
            continue
        if depth > deepest and children:
            raise _too_deep(source)
        stack.extend((c, depth + 1) for c in children)
    return data


def _too_deep(source: str) -> MechsynInputError:
    return MechsynInputError(
        f"nested more than {limit('nesting')} levels deep", source=source,
        hint="mechsyn files are a few levels deep; check the brackets or indentation")


def parse_data(text: str, source: str, fmt: str | None = None) -> Any:
    """Parse YAML, or JSON (``fmt="json"``, or a source ending in ``.json``), into data.

    Syntax errors name the line; nesting and size beyond the limits are refused.
    """
    if _bracket_depth(text) > limit("nesting"):
        raise _too_deep(source)
    as_json = fmt == "json" or (fmt is None and source.lower().endswith(".json"))
    try:
        if as_json:
            try:
                data = json.loads(text)
            except json.JSONDecodeError as exc:
                raise MechsynInputError(
                    f"JSON syntax error: {exc.msg} (column {exc.colno})", source=source,
                    line=exc.lineno, hint="fix the JSON syntax at that line",
                ) from None
        else:
            try:
                data = yaml.load(text, Loader=_YAML_LOADER)  # noqa: S506 (a safe loader)
            except yaml.MarkedYAMLError as exc:
                mark = exc.problem_mark or exc.context_mark
                line = mark.line + 1 if mark is not None else None
                problem = exc.problem or exc.context or "cannot parse"
                if "nesting depth" in problem:  # PyYAML >= 6.0.3 refuses deep nesting itself
                    raise _too_deep(source) from None
                column = f" (column {mark.column + 1})" if mark is not None else ""
                raise MechsynInputError(
                    f"YAML syntax error: {problem}{column}", source=source, line=line,
                    hint="fix the YAML syntax at that line (indentation, brackets, colons)",
                ) from None
            except yaml.YAMLError as exc:
                raise MechsynInputError(f"YAML syntax error: {exc}", source=source) from None
    except RecursionError:  # block-style nesting (indentation) thousands deep
        raise _too_deep(source) from None
    return check_data_size(data, source)


def read_data(path: str | os.PathLike[str], what: str = "file",
              fmt: str | None = None) -> tuple[Any, str]:
    """Read and parse a YAML or JSON file; return the data with its text."""
    from mechsyn.examples import resolve

    text = read_text(path, what)
    return parse_data(text, str(resolve(path)), fmt), text
