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
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml

_FAST_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
_MERGE = "tag:yaml.org,2002:merge"


class _StrictLoader(_FAST_LOADER):  # type: ignore[misc, valid-type]
    """The safe loader refusing a key written twice in one mapping (PyYAML keeps the last)."""

    def construct_mapping(self, node: Any, deep: bool = False) -> Any:
        if isinstance(node, yaml.MappingNode):
            seen: set[tuple[str, str]] = set()
            for key, _ in node.value:
                if isinstance(key, yaml.ScalarNode) and key.tag != _MERGE:
                    if (key.tag, key.value) in seen:
                        raise yaml.constructor.ConstructorError(
                            None, None, f"duplicate key {key.value[:80]!r}", key.start_mark)
                    seen.add((key.tag, key.value))
        return super().construct_mapping(node, deep)


#: LibYAML's safe parser where PyYAML was built with it (several times faster), else
#: PyYAML's own; a key written twice in one mapping is refused.
_YAML_LOADER = _StrictLoader

from mechsyn.errors import MechsynInputError
from mechsyn.limits import limit, limit_hint

__all__ = ["is_mechanism_file", "resolve_path", "read_text", "read_limited", "parse_data", "read_data", "check_data_size", "loads_json",
           "check_id_text", "existing_regular", "read_json_lines", "id_skeleton", "confusable_id", "visible_text"]

#: Bidirectional controls and zero-width characters: they make two ids that look alike
#: differ, or reorder what a terminal shows ("Trojan Source", CVE-2021-42574).
HIDDEN_CHARS = re.compile("[\u061c\u200b-\u200f\u202a-\u202e\u2060-\u2064\u2066-\u2069\ufeff]")
_SURROGATE = re.compile("[\ud800-\udfff]")
#: Keys whose strings are free text, shown with hidden characters stripped; every other
#: string of a file (ids, references, keys) refuses them.
FREE_TEXT_KEYS = frozenset({"name", "title", "description", "notes", "note", "comment", "label", "text"})

_BRACKETS = re.compile(r"[\[\]{}]")


def resolve_path(path: str | os.PathLike[str]) -> Path:
    """``path`` itself when it exists, else the bundled example it names (a stem such as
    ``fourbar``, a file name or ``folder/file.ext``): every reader's one way to accept a
    bundled example's name (:func:`mechsyn.examples.resolve`).

    >>> resolve_path("fourbar").name
    'fourbar.yaml'
    """
    from mechsyn.examples import resolve

    return resolve(path)


def read_text(path: str | os.PathLike[str], what: str = "file", cap: int | None = None) -> str:
    """The UTF-8 text of ``path``; :class:`MechsynInputError` when it cannot be read.

    ``what`` names the kind of file in messages (``"case file"``, ``"table"``...); ``cap``
    is a smaller size limit than ``file_bytes`` for a kind of file that is always small.
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
    data = read_limited(p, what, cap)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise MechsynInputError(
            f"not UTF-8 text ({exc.reason} at byte {exc.start})", source=str(p),
            hint="save the file as UTF-8 text",
        ) from None


def read_limited(path: str | os.PathLike[str], what: str = "file", cap: int | None = None) -> bytes:
    """The bytes of ``path``: a regular file (not a device such as ``/dev/zero``, a FIFO or
    a socket, refused at once) of at most ``file_bytes`` bytes, or ``cap`` when that is
    smaller (the size is checked before reading and the read stops one byte past the
    limit, so a file growing meanwhile is refused too).

    >>> read_limited("/dev/zero")
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: /dev/zero: not a regular file (a device, FIFO or socket) (fix: give the path of a file)
    """
    general = int(limit("file_bytes"))
    hint = limit_hint("file_bytes") if cap is None or cap >= general else f"a {what} is far smaller"
    cap = general if cap is None else min(int(cap), general)
    too_big = f"{what} larger than the limit of {cap:,} bytes"
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise MechsynInputError("not a regular file (a device, FIFO or socket)", source=str(path),
                                    hint="give the path of a file")
        if info.st_size > cap:
            raise MechsynInputError(f"{what} of {info.st_size:,} bytes is larger than the limit of {cap:,}",
                                    source=str(path), hint=hint)
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO swapped in never blocks
        with os.fdopen(fd, "rb") as fh:
            if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
                raise MechsynInputError("not a regular file (a device, FIFO or socket)", source=str(path),
                                        hint="give the path of a file")
            data = fh.read(cap + 1)
    except OSError as exc:
        raise MechsynInputError(f"cannot read the {what}: {exc.strerror or exc}", source=str(path),
                                hint="check the path and its permissions") from None
    if len(data) > cap:
        raise MechsynInputError(too_big, source=str(path), hint=hint)
    return data


def existing_regular(path: str | os.PathLike[str], what: str = "file") -> bool:
    """Whether ``path`` exists, refusing (:class:`MechsynInputError`) one that exists and is
    not a regular file: a directory, a device such as ``/dev/zero``, a FIFO (opening it
    would block) or a socket, which must be neither read as a file nor replaced by one.

    >>> existing_regular("/dev/zero", "chain stream")
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: /dev/zero: the chain stream is not a regular file (a directory, device, FIFO or socket) (fix: give the path of a file)
    """
    try:
        info = os.stat(path)
    except FileNotFoundError:
        return False
    except OSError as exc:
        raise MechsynInputError(f"cannot read the {what}: {exc.strerror or exc}", source=str(path)[:200],
                                hint="check the path and its permissions") from None
    if not stat.S_ISREG(info.st_mode):
        raise MechsynInputError(f"the {what} is not a regular file (a directory, device, FIFO or socket)",
                                source=str(path), hint="give the path of a file")
    return True


def read_json_lines(path: str | os.PathLike[str], what: str = "file",
                    line_bytes: int = 1 << 20) -> Iterator[tuple[int, Any]]:
    """``(number, value)`` of each line of a JSON-lines file, each line read with at most
    ``line_bytes`` characters and parsed with the nesting limit (a line of 10,000 nested
    brackets is refused, not a RecursionError); a line that is not JSON gives
    ``(number, None)`` (a torn last line of an interrupted run is dropped by the caller)."""
    if not existing_regular(path, what):
        raise MechsynInputError(f"no such {what}", source=str(path))
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    with os.fdopen(fd, encoding="utf-8", errors="strict") as fh:
        number = 0
        while True:
            number += 1
            try:
                line = fh.readline(line_bytes + 1)
            except UnicodeDecodeError as exc:
                raise MechsynInputError(f"not UTF-8 text ({exc.reason})", source=str(path), line=number,
                                        hint="delete the file (or give another) and run again") from None
            if not line:
                return
            if len(line) > line_bytes:
                raise MechsynInputError(f"a line longer than {line_bytes:,} characters", source=str(path),
                                        line=number, hint="delete the file (or give another) and run again")
            if _bracket_depth(line) > limit("nesting"):
                raise MechsynInputError(f"nested more than {limit('nesting')} levels deep", source=str(path),
                                        line=number, hint="delete the file (or give another) and run again")
            try:
                yield number, json.loads(line)
            except ValueError:  # a syntax error, or an integer of thousands of digits
                yield number, None


def _bracket_depth(text: str) -> int:
    """Upper bound of the flow-style nesting depth (brackets, ignoring quoting)."""
    depth = deepest = 0
    for m in _BRACKETS.finditer(text):
        depth = depth + 1 if m.group() in "[{" else max(depth - 1, 0)
        deepest = max(deepest, depth)
    return deepest


def check_data_size(data: Any, source: str, hidden: bool = True) -> Any:
    """Refuse data nested deeper than the limit ``nesting`` or with more than
    ``values`` values (counted through shared YAML aliases), and strings that are not text
    (lone surrogates) or, with ``hidden``, ids holding invisible characters
    (:func:`check_id_text`); return ``data``."""
    deepest, budget = limit("nesting"), limit("values")
    stack: list[tuple[Any, int, str]] = [(data, 1, "")]
    seen = 0
    while stack:
        node, depth, key = stack.pop()
        seen += 1
        if seen > budget:
            raise MechsynInputError(
                f"more than {budget:,} values (YAML aliases expanding into too many items?)",
                source=source, hint="write the data out without aliases; " + limit_hint("values"))
        if isinstance(node, str):
            check_id_text(node, source, key, free=not hidden or key in FREE_TEXT_KEYS)
            continue
        if isinstance(node, dict):
            children = [(k, depth + 1, key) for k in node] + [(v, depth + 1, str(k)) for k, v in node.items()]
        elif isinstance(node, (list, tuple)):
            children = [(c, depth + 1, key) for c in node]
        else:
            continue
        if depth > deepest and children:
            raise _too_deep(source)
        stack.extend(children)
    return data


def check_id_text(text: str, source: str, field: str = "", free: bool = False) -> str:
    r"""Refuse a lone surrogate (not text: it cannot be printed or written as UTF-8) and, unless
    ``free`` (a name shown with them stripped), bidirectional controls and zero-width characters.

    >>> check_id_text("A\u200b", "m.yaml", "joints")
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: m.yaml: joints: 'A\u200b' holds the invisible character U+200B (fix: type the id again without it; ids may not hold bidirectional controls or zero-width characters)
    """
    if text.isascii():
        return text
    if _SURROGATE.search(text):
        raise MechsynInputError(f"{text[:40]!r} holds a lone surrogate (not text)", source=source,
                                field=field or None, hint="save the file as UTF-8 text")
    if free:
        return text
    hidden = HIDDEN_CHARS.search(text)
    if hidden:
        raise MechsynInputError(f"{text[:40]!r} holds the invisible character U+{ord(hidden.group()):04X}",
                                source=source, field=field or None,
                                hint="type the id again without it; ids may not hold bidirectional "
                                     "controls or zero-width characters")
    import unicodedata

    if len(text) <= 1000 and unicodedata.normalize("NFKC", text) != text:
        raise MechsynInputError(f"{text[:40]!r} is not in its normal form (NFKC)", source=source, field=field or None,
                                hint=f"write it as {unicodedata.normalize('NFKC', text)[:40]!r}")
    scripts = _scripts(text)
    if len(scripts) > 1 and text.translate(_CONFUSABLE) != text:  # e.g. "Аlpha": a Cyrillic А in Latin
        look = next(ch for ch in text if ch.translate(_CONFUSABLE) != ch)
        raise MechsynInputError(f"{text[:40]!r} mixes the scripts {', '.join(sorted(scripts)).lower()}: "
                                f"U+{ord(look):04X} looks like the Latin {look.translate(_CONFUSABLE)!r}",
                                source=source, field=field or None,
                                hint="write each id in one script")
    return text


#: Non-Latin letters drawn like Latin ones (Cyrillic and Greek capitals and small letters
#: of Unicode's confusables.txt that map to one ASCII letter): the part of a TR39 skeleton
#: that matters for ids typed in files.
_CONFUSABLE = str.maketrans(
    "АВЕЅІЈКМНОРСТХУҮѴԜԚԌаеіјоѕрсхуԁԛԝһӏѵ"    # Cyrillic
    "ΑΒΕΖΗΙΚΜΝΟΡΤΥΧοινρυχκ",                   # Greek
    "ABESIJKMHOPCTXYYVWQGaeijospcxydqwhlv"
    "ABEZHIKMNOPTYXoivpuxk")
#: scripts written together (Japanese, Korean): one script for the mixing check
_ONE_SCRIPT = {"HIRAGANA": "CJK", "KATAKANA": "CJK", "HANGUL": "CJK"}


def id_skeleton(text: str) -> str:
    """What an id looks like: its NFKC form with Cyrillic and Greek look-alikes of Latin
    letters replaced by them (a small TR39 skeleton). Two ids with the same skeleton
    cannot be told apart on screen.

    >>> id_skeleton("А") == id_skeleton("A")  # Cyrillic A, Latin A
    True
    >>> id_skeleton("Ａ₂")  # fullwidth A, subscript two
    'A2'
    """
    import unicodedata

    return text if text.isascii() else unicodedata.normalize("NFKC", text).translate(_CONFUSABLE)


def confusable_id(text: str, seen: dict[str, str]) -> str | None:
    """The id in ``seen`` (skeleton -> id, filled as ids are read) that ``text`` looks like
    without being it, else ``None`` (and ``text`` is recorded).

    >>> seen = {}
    >>> confusable_id("A", seen), confusable_id("B", seen), confusable_id("А", seen)
    (None, None, 'A')
    """
    key = id_skeleton(text)
    other = seen.setdefault(key, text)
    return other if other != text else None


def _scripts(text: str) -> set[str]:
    """The scripts of the letters of ``text`` (the first word of each letter's Unicode
    name: LATIN, CYRILLIC, GREEK...; CJK ideographs count as one)."""
    import unicodedata

    out = set()
    for ch in text:
        if ch.isalpha() and not ch.isascii():
            word = unicodedata.name(ch, "UNKNOWN").split()[0]
            out.add(_ONE_SCRIPT.get(word, word))
        elif ch.isalpha():
            out.add("LATIN")
    return out


def visible_text(text: str, mark: bool = False) -> str:
    r"""``text`` fit to show: bidirectional controls and zero-width characters removed, or
    with ``mark`` written out as ``<U+202E>`` (for a page or a status line; a right-to-left
    override would otherwise reorder what follows it).

    >>> visible_text("four‮bar"), visible_text("four‮bar", mark=True)
    ('fourbar', 'four<U+202E>bar')
    """
    if text.isascii():
        return text
    return HIDDEN_CHARS.sub((lambda m: f"<U+{ord(m.group()):04X}>") if mark else "", text)


class _JSONDuplicate(ValueError):
    pass


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise _JSONDuplicate(k)
        out[k] = v
    return out


class _JSONConstant(ValueError):
    pass


def _refuse_constant(name: str) -> Any:
    raise _JSONConstant(name)


def _finite_float(text: str) -> float:
    value = float(text)
    if value in (float("inf"), float("-inf")):
        raise _JSONConstant(text[:40])
    return value


def loads_json(text: str | bytes, source: str, finite: bool = False) -> Any:
    r"""Parse JSON: a key written twice in one object refused (with its line), numbers over
    4,300 digits and nesting beyond ``nesting`` refused, and with ``finite`` also ``NaN``
    and ``Infinity``; every problem a :class:`MechsynInputError` naming ``source``.

    >>> loads_json('{"a": 1,\n "a": 2}', "case.json")
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: case.json:2: the key 'a' is written twice (fix: keep one of them)
    """
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise MechsynInputError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", source=source,
                                    hint="send UTF-8 text") from None
    if _bracket_depth(text) > limit("nesting"):
        raise _too_deep(source)
    try:
        return json.loads(text, object_pairs_hook=_no_duplicates, parse_constant=_refuse_constant if finite else None,
                          parse_float=_finite_float if finite else None)
    except json.JSONDecodeError as exc:
        raise MechsynInputError(f"JSON syntax error: {exc.msg} (column {exc.colno})", source=source,
                                line=exc.lineno, hint="fix the JSON syntax at that line") from None
    except _JSONConstant as exc:
        raise MechsynInputError(f"{exc.args[0]} is not a number mechsyn takes", source=source,
                                hint="give a finite number") from None
    except _JSONDuplicate as exc:
        word = str(exc.args[0])
        at = [m.start() for m in re.finditer(re.escape(json.dumps(word)) + r"\s*:", text)]
        line = text.count("\n", 0, at[-1]) + 1 if at else None
        raise MechsynInputError(f"the key {word[:80]!r} is written twice", source=source, line=line,
                                hint="keep one of them") from None
    except ValueError as exc:  # an integer of more than 4,300 digits (CVE-2020-10735 guard)
        raise MechsynInputError(f"a number too long to read ({str(exc)[:80]})", source=source,
                                hint="write numbers with at most a few dozen digits") from None
    except RecursionError:
        raise _too_deep(source) from None


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
            data = loads_json(text, source)
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
                if problem.startswith("duplicate key"):
                    raise MechsynInputError(f"{problem} in one mapping{column}", source=source, line=line,
                                            hint="keep one of them (YAML would silently use the last)") from None
                raise MechsynInputError(
                    f"YAML syntax error: {problem}{column}", source=source, line=line,
                    hint="fix the YAML syntax at that line (indentation, brackets, colons)",
                ) from None
            except yaml.YAMLError as exc:
                raise MechsynInputError(f"YAML syntax error: {exc}", source=source) from None
            except ValueError as exc:  # an integer of more than 4,300 digits
                raise MechsynInputError(f"a number too long to read ({str(exc)[:80]})", source=source,
                                        hint="write numbers with at most a few dozen digits") from None
    except RecursionError:  # block-style nesting (indentation) thousands deep
        raise _too_deep(source) from None
    return check_data_size(data, source)


def read_data(path: str | os.PathLike[str], what: str = "file",
              fmt: str | None = None) -> tuple[Any, str]:
    """Read and parse a YAML or JSON file; return the data with its text."""
    from mechsyn.examples import resolve

    text = read_text(path, what)
    return parse_data(text, str(resolve(path)), fmt), text


def is_mechanism_file(path: Path) -> bool:
    """Whether ``path`` holds what a mechsyn command writes as a mechanism: an empty
    file, a YAML/JSON mapping with ``links`` and ``joints``, or a Pyslvs expression
    (``M[...]`` after ``#`` comment lines, for ``.pyslvs``/``.txt``). Anything
    unreadable is not."""
    try:
        if path.stat().st_size == 0:
            return True
        text = read_text(path)
        if path.suffix.lower() in (".pyslvs", ".txt"):  # comment lines (#), then M[...]
            expr = "".join(ln for ln in text.splitlines() if not ln.lstrip().startswith("#")).strip()
            return expr.startswith("M[") and expr.endswith("]")
        data = parse_data(text, str(path))
    except (MechsynInputError, OSError):
        return False
    return isinstance(data, dict) and isinstance(data.get("links"), list) and isinstance(data.get("joints"), list)
