"""Pyslvs mechanism expressions: reading them into mechanism files and writing them back.

Pyslvs-UI users keep and share planar linkages as *mechanism expressions*::

    M[
      J[R, color[Green], P[0.0, 0.0], L[ground, link_1]],
      J[R, color[Blue], P[10.0, 0.0], L[link_1, link_2]],
      J[RP, A[30.0], color[Orange], P[40.0, 0.0], L[ground, link_2]],
    ]

Each ``J[...]`` is a point (Pyslvs numbers them 0, 1, 2, ... in order) with a type, for
sliders the slot angle ``A[deg]`` (from the x axis), an optional colour, its position
``P[x, y]`` and the links ``L[...]`` it joins (``ground`` is the frame), in that order,
Pyslvs' grammar ``J[type (, A[deg])? (, color[...])?, P[x, y], L[links]]`` [1]_. The slot
angle is also read after ``P[...]`` (mechsyn wrote it there before); it is written where
Pyslvs writes it. A slider without ``A[...]`` gets Pyslvs' default 0, with a note.

* ``R``: a pin shared by every listed link (one link: a point fixed on that link; no
  link: a free point);
* ``P``: the second link slides along the first without turning (a prismatic pair);
* ``RP``: a pin that slides along the first listed link and turns in the others
  (a slider block turning on the pin).

This module is written from that grammar as documented by Pyslvs (not from its code).
Pyslvs keeps the driven inputs beside the expression as point pairs ``(base, drive)``:
the link through both points is turned about ``base``. Here they are given as
``inputs`` (or a ``# inputs: (0, 1)`` comment line in the file); without them the
converter chooses ground cranks, as many as the mobility.

Mapping to mechsyn's model (every pair joins two links):

* an R point shared by ``k`` links becomes ``k - 1`` R joints ``P<i>``, ``P<i>_2``, ...
  from the frame (or the first link) to each of the others;
* an R point on one link becomes a named point ``P<i>`` of that link;
* an RP point becomes a block link ``block<i>`` with a P joint ``P<i>`` along the first
  link and an R joint ``P<i>_1`` to the second; a third, fourth... link turns on the same
  pin, joined to the second by R joints ``P<i>_2``, ``P<i>_3``, ... (a block with two pins
  at one point would be a link of zero length);
* a P point with two links becomes a P joint ``P<i>``.

Writing back recognises those blocks (a link ``block<i>`` with one P joint and R
joints at one point) and coincident R joints that share links, so expression -> file -> expression
gives the same expression. Colours (``color[...]``) are kept in the file's ``colors``
block, keyed by the joint or point ``P<i>`` made from point ``i``, and written back;
:func:`color_rgb` reads them for the plots.

References
----------
.. [1] Chang, Y. (KmolYuan), *Pyslvs-UI: open source planar linkage mechanism
   simulation and mechanical synthesis system*, documentation, "Mechanism expression",
   https://pyslvs-ui.readthedocs.io (2016-2021).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from typing import Any

import networkx as nx
import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.limits import limit, limit_hint

__all__ = [
    "PyslvsJoint", "PyslvsMechanism", "parse_expression", "format_expression",
    "expression_to_data", "data_to_expression", "read_pyslvs", "pyslvs_text", "color_rgb",
]

FRAME = "ground"
_TYPES = ("RP", "R", "P")


@dataclass(frozen=True)
class PyslvsJoint:
    """One ``J[...]`` of an expression: type, position, slot angle (deg), links, colour."""

    type: str
    x: float
    y: float
    links: tuple[str, ...]
    angle: float | None = None
    color: str | None = None


@dataclass
class PyslvsMechanism:
    """A parsed expression with its inputs ``(base, drive)`` (point indices)."""

    joints: list[PyslvsJoint]
    inputs: list[tuple[int, int]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


# --------------------------------------------------------------------------- grammar
_TOKEN = re.compile(r"\s*(?:(?P<sym>[\[\],()])|(?P<word>[^\s\[\],()]+))")


class _Parser:
    """Recursive descent over the tokens of an expression, with line/column errors."""

    def __init__(self, text: str, source: str) -> None:
        self.text = text
        self.source = source
        self.tokens: list[tuple[str, int]] = []
        pos = 0
        while pos < len(text):
            m = _TOKEN.match(text, pos)
            if m is None or m.end() == pos:
                break
            tok = m.group("sym") or m.group("word")
            if tok is None:
                break
            self.tokens.append((tok, m.start("sym") if m.group("sym") else m.start("word")))
            pos = m.end()
        self.i = 0
        self.notes: list[str] = []
        self.count = 0  # joints read so far
        self.link_names: set[str] = {FRAME}  # every link named so far (the limit counted as they come)
        self.max_links, self.max_joints = limit("links"), limit("joints")

    def error(self, message: str, hint: str | None = None) -> MechsynInputError:
        pos = self.tokens[self.i][1] if self.i < len(self.tokens) else len(self.text)
        line = self.text.count("\n", 0, pos) + 1
        col = pos - (self.text.rfind("\n", 0, pos) + 1) + 1
        return MechsynInputError(f"{message} (column {col})", source=self.source, line=line,
                                 hint=hint or "write M[J[R, P[x, y], L[ground, link_1]], ...]")

    def peek(self) -> str | None:
        return self.tokens[self.i][0] if self.i < len(self.tokens) else None

    def take(self, expected: str | None = None) -> str:
        tok = self.peek()
        if tok is None:
            raise self.error(f"expression ends early, expected {expected!r}" if expected
                             else "expression ends early")
        if expected is not None and tok != expected:
            raise self.error(f"expected {expected!r}, found {tok!r}")
        self.i += 1
        return tok

    def number(self) -> float:
        tok = self.take()
        try:
            v = float(tok)
        except ValueError:
            self.i -= 1
            raise self.error(f"expected a number, found {tok!r}") from None
        if not math.isfinite(v):
            self.i -= 1
            raise self.error(f"{tok!r} is not a finite number")
        return v

    def mechanism(self) -> list[PyslvsJoint]:
        if self.peek() != "M":
            raise self.error("a mechanism expression starts with M[")
        self.take("M")
        self.take("[")
        joints: list[PyslvsJoint] = []
        while self.peek() != "]":
            joints.append(self.joint())
            if self.peek() == ",":
                self.take(",")
            elif self.peek() != "]":
                raise self.error(f"expected ',' or ']' after a joint, found {self.peek()!r}")
        self.take("]")
        if self.peek() is not None:
            raise self.error(f"text after the end of the expression: {self.peek()!r}",
                             hint="keep one M[...] per file")
        return joints

    def joint(self) -> PyslvsJoint:
        """``J[type, A[deg], color[...], P[x, y], L[...]]`` as Pyslvs writes it (``A`` and
        ``color`` optional); ``A[deg]`` after ``P[...]`` (mechsyn's order before issue 26)
        is read too."""
        index, self.count = self.count, self.count + 1
        if self.count > self.max_joints:
            raise self.error(f"more than the limit of {self.max_joints:,} points (joints)", hint=limit_hint("joints"))
        self.take("J")
        self.take("[")
        jtype = self.take()
        if jtype not in _TYPES:
            self.i -= 1
            raise self.error(f"unknown joint type {jtype!r}", hint="use R, P or RP")
        self.take(",")
        angle = self.angle() if self.peek() == "A" else None
        color = None
        if self.peek() == "color":
            color = self.color()
            self.take(",")
        self.take("P")
        self.take("[")
        x = self.number()
        self.take(",")
        y = self.number()
        self.take("]")
        self.take(",")
        if self.peek() == "A":
            if angle is not None:
                raise self.error("a second slot angle A[...] in one joint")
            angle = self.angle()
        if angle is None and jtype != "R":
            angle = 0.0
            self.notes.append(f"point {index}: a {jtype} joint without its slot angle A[degrees]: 0 "
                              "(along x, Pyslvs' default)")
        self.take("L")
        self.take("[")
        links: dict[str, None] = {}  # in order, looked up in constant time
        while self.peek() != "]":
            name = self.take()
            if name in "[](),":
                self.i -= 1
                raise self.error(f"expected a link name, found {name!r}")
            if name in links:
                self.i -= 1
                raise self.error(f"link {name!r} listed twice in one joint")
            links[name] = None
            self._count_link(name)
            if self.peek() == ",":
                self.take(",")
        self.take("]")
        self.take("]")
        return PyslvsJoint(jtype, x, y, tuple(links), angle if jtype != "R" else None, color)

    def _count_link(self, name: str) -> None:
        """Count a link name against the limit ``links`` as it is read (an expression naming
        40,000 links is refused at the 2,001st, not after reading them all)."""
        self.link_names.add(name)
        if len(self.link_names) > self.max_links:
            self.i -= 1
            raise self.error(f"more than the limit of {self.max_links:,} links (the analyses would run for hours "
                             "or longer)", hint=limit_hint("links"))

    def angle(self) -> float:
        """``A[deg], `` (the comma after it included)."""
        self.take("A")
        self.take("[")
        value = self.number()
        self.take("]")
        self.take(",")
        return value

    def color(self) -> str:
        self.take("color")
        self.take("[")
        depth, parts = 1, []
        while depth:
            tok = self.take()
            depth += {"[": 1, "]": -1}.get(tok, 0)
            if depth:
                parts.append(tok)
        return "".join(p if p in "(),[]" else p for p in parts).replace(",", ", ")


_INPUTS = re.compile(r"^\s*#\s*inputs?\s*:(.*)$", re.IGNORECASE | re.MULTILINE)
_PAIR = re.compile(r"\(\s*(-?\d+)\s*,\s*(-?\d+)\s*\)")


def _strip_comments(text: str) -> str:
    """The text with ``#[ ... #]`` block comments and ``#`` line comments blanked out
    (offsets and lines kept)."""
    blank = lambda m: re.sub(r"[^\n]", " ", m.group())  # noqa: E731
    return re.sub(r"#[^\n]*", blank, re.sub(r"#\[[\s\S]*?#\][^\n]*", blank, text))


def parse_expression(text: str, source: str = "<expression>") -> PyslvsMechanism:
    """Parse a Pyslvs mechanism expression.

    The text may carry ``#`` comments; a ``# inputs: (0, 1), (2, 3)`` line gives the
    inputs. In a Pyslvs project file (YAML) the expression is the ``M[...]`` after
    ``mechanism:``, found as the first ``M[`` with its brackets.

    Examples
    --------
    >>> m = parse_expression("M[J[R, P[0, 0], L[ground, link_1]], J[R, P[1, 0], L[link_1]]]")
    >>> [j.links for j in m.joints]
    [('ground', 'link_1'), ('link_1',)]
    """
    inputs = []
    for m in _INPUTS.finditer(text):
        inputs += [(int(a), int(b)) for a, b in _PAIR.findall(m.group(1))]
    clean = _strip_comments(text)
    start = re.search(r"(?<![A-Za-z0-9_])M\s*\[", clean)
    if start is None:
        raise MechsynInputError("no mechanism expression M[...] in the file", source=source,
                                hint="paste Pyslvs's expression (File > Export > Mechanism expression)")
    end = _matching_bracket(clean, clean.index("[", start.start()))
    if end is None:
        line = clean.count("\n", 0, start.start()) + 1
        raise MechsynInputError("the M[ ... ] brackets are not closed", source=source, line=line,
                                hint="close every J[...] and the final ]")
    body = re.sub(r"[^\n]", " ", clean[:start.start()]) + clean[start.start():end + 1]
    parser = _Parser(body, source)
    joints = parser.mechanism()
    return PyslvsMechanism(joints, inputs, parser.notes)


def _matching_bracket(text: str, open_at: int) -> int | None:
    depth = 0
    for k in range(open_at, len(text)):
        if text[k] == "[":
            depth += 1
        elif text[k] == "]":
            depth -= 1
            if depth == 0:
                return k
    return None


def _num(v: float) -> str:
    r = round(v, 12)
    return repr(0.0 if r == 0 else r)


def format_expression(joints: list[PyslvsJoint], inputs: list[tuple[int, int]] | None = None) -> str:
    """The text of an expression, one joint a line (plus an ``# inputs:`` line).

    Examples
    --------
    >>> print(format_expression([PyslvsJoint("R", 0.0, 0.0, ("ground", "link_1"))]))
    M[
      J[R, color[Green], P[0.0, 0.0], L[ground, link_1]],
    ]
    """
    lines = []
    if inputs:
        lines.append("# inputs: " + ", ".join(f"({a}, {b})" for a, b in inputs))
    lines.append("M[")
    for j in joints:
        color = j.color or ("Green" if FRAME in j.links else ("Orange" if j.type != "R" else "Blue"))
        angle = f"A[{_num(j.angle or 0.0)}], " if j.type != "R" else ""
        lines.append(f"  J[{j.type}, {angle}color[{color}], P[{_num(j.x)}, {_num(j.y)}], "
                     f"L[{', '.join(j.links)}]],")
    lines.append("]")
    return "\n".join(lines)


# --------------------------------------------------------------------------- to a mechanism file
def _unique(name: str, taken: set[str]) -> str:
    out, k = name, 2
    while out in taken:
        out, k = f"{name}_{k}", k + 1
    return out


def expression_to_data(expr: PyslvsMechanism, name: str = "Pyslvs mechanism",
                       source: str = "<expression>",
                       inputs: list[tuple[int, int]] | None = None) -> tuple[dict[str, Any], list[str]]:
    """Mechanism-file data (the YAML/JSON layout) of a parsed expression, with notes.

    ``inputs`` (point pairs ``(base, drive)``) override the expression's own; without
    any, ground cranks are chosen (the shortest links pivoted on the frame), as many
    as the mobility ``3 n - 2 p5`` of the expression.

    Returns the data and the notes on what was dropped or chosen.

    Examples
    --------
    >>> e = parse_expression('''M[J[R, P[0, 0], L[ground, a]], J[R, P[0, 1], L[a, b]],
    ...                          J[R, P[3, 2], L[b, c]], J[R, P[3, 0], L[c, ground]]]''')
    >>> data, notes = expression_to_data(e)
    >>> [(j["id"], j["links"], j.get("actuated", False)) for j in data["joints"]][:2]
    [('P0', ['ground', 'a'], True), ('P1', ['a', 'b'], False)]
    """
    notes: list[str] = list(expr.notes)
    links = _link_names(expr, source)
    taken = set(links)
    joints: list[dict[str, Any]] = []
    points: dict[str, dict[str, Any]] = {}
    colors: dict[str, str] = {}
    # joints[...] of each point, and the link pairs each point joins (for the drivers)
    at_point: dict[int, list[dict[str, Any]]] = {}
    for i, j in enumerate(expr.joints):
        pid = f"P{i}"
        xy = [j.x, j.y]
        made: list[dict[str, Any]] = []
        if len(j.links) == 0:
            notes.append(f"point {i} ({pid}) is on no link: dropped")
        elif len(j.links) == 1:
            points[pid] = {"link": j.links[0], "at": xy}
            if j.type != "R":
                notes.append(f"point {i} ({pid}) is a {j.type} joint on one link only: kept as a point of "
                             f"{j.links[0]}")
        elif j.type == "R":
            centre = FRAME if FRAME in j.links else j.links[0]
            others = [lk for lk in j.links if lk != centre]
            for k, lk in enumerate(others, start=1):
                made.append({"id": pid if k == 1 else f"{pid}_{k}", "type": "R", "links": [centre, lk],
                             "point": xy})
        else:
            a = math.radians(j.angle or 0.0)
            axis = [math.cos(a), math.sin(a)]
            if j.type == "P":
                if len(j.links) > 2:
                    raise MechsynInputError(
                        f"point {i}: a P joint with {len(j.links)} links (the others would be welded "
                        "together, which mechsyn's pairs cannot say)", source=source,
                        hint="join one link to the slot with P and the others to it with R points")
                made.append({"id": pid, "type": "P", "links": list(j.links), "point": xy, "axis": axis})
            else:  # RP: block sliding along links[0], turning on the others
                block = _unique(f"block{i}", taken)
                taken.add(block)
                links.append(block)
                made.append({"id": pid, "type": "P", "links": [j.links[0], block], "point": xy, "axis": axis})
                turning = j.links[1:]  # one pin: the block turns on the first, the others on it
                if turning:
                    made.append({"id": f"{pid}_1", "type": "R", "links": [block, turning[0]], "point": xy})
                for k, lk in enumerate(turning[1:], start=2):
                    made.append({"id": f"{pid}_{k}", "type": "R", "links": [turning[0], lk], "point": xy})
        at_point[i] = made
        joints += made
        if j.color and (made or pid in points):
            colors[pid] = j.color
    n_moving = len(links) - 1
    mobility = 3 * n_moving - 2 * len(joints)
    chosen = list(inputs) if inputs else list(expr.inputs)
    if chosen:
        by_id = {jd["id"]: jd for jd in joints}
        for base, drive in chosen:
            by_id[_driver_joint(expr, at_point, base, drive, source, notes)]["actuated"] = True
    else:
        for jd in _ground_cranks(joints, mobility, notes):
            jd["actuated"] = True
    if len(joints) and sum(bool(jd.get("actuated")) for jd in joints) != max(mobility, 0):
        notes.append(f"{sum(bool(jd.get('actuated')) for jd in joints)} driven joint(s) for mobility "
                     f"3n - 2p5 = {mobility}")
    data: dict[str, Any] = {"name": name, "kind": "planar", "ground": FRAME, "links": links,
                            "joints": joints}
    if points:
        data["points"] = points
    if colors:
        data["colors"] = colors
    data["source"] = f"converted from the Pyslvs expression {source}"
    return data, notes


def _link_names(expr: PyslvsMechanism, source: str) -> list[str]:
    """The frame, then every link in order of appearance; refused before any other work
    when there are more than the ``links`` or ``joints`` limits (:mod:`mechsyn.limits`)."""
    if len(expr.joints) > limit("joints"):
        raise MechsynInputError(f"{len(expr.joints):,} points are more than the limit of {limit('joints'):,} "
                                "joints", source=source, hint=limit_hint("joints"))
    names = dict.fromkeys([FRAME, *(lk for j in expr.joints for lk in j.links)])
    if len(names) > limit("links"):
        raise MechsynInputError(f"{len(names):,} links are more than the limit of {limit('links'):,} (the "
                                "analyses would run for hours or longer)", source=source, hint=limit_hint("links"))
    if not any(FRAME in j.links for j in expr.joints):
        raise MechsynInputError("no joint on the frame: no L[...] names 'ground'", source=source,
                                hint="pin at least one joint to ground, e.g. L[ground, link_1]")
    return list(names)


def _driver_joint(expr: PyslvsMechanism, at_point: dict[int, list[dict[str, Any]]], base: int, drive: int,
                  source: str, notes: list[str]) -> str:
    n = len(expr.joints)
    for k in (base, drive):
        if not 0 <= k < n:
            raise MechsynInputError(f"input ({base}, {drive}): no point {k} (points are 0..{n - 1})",
                                    source=source, hint="give input pairs as BASE,DRIVE point indices")
    if base == drive:  # Pyslvs' input of a slider: its travel along the slot
        slide = [jd for jd in at_point[base] if jd["type"] == "P"]
        if not slide:
            raise MechsynInputError(f"input ({base}, {base}): point {base} is no slider",
                                    source=source, hint="an input (i, i) drives the P or RP joint at point i")
        return slide[0]["id"]
    common = [lk for lk in expr.joints[base].links if lk in expr.joints[drive].links]
    if not common:
        raise MechsynInputError(f"input ({base}, {drive}): no link joins points {base} and {drive}",
                                source=source, hint="the drive point must be on a link pivoted at the base")
    link = common[0]
    cands = [jd for jd in at_point[base] if jd["type"] == "R" and link in jd["links"]]
    if not cands:
        raise MechsynInputError(f"input ({base}, {drive}): point {base} is no revolute joint of {link}",
                                source=source, hint="drive a crank about a pin")
    frame = [jd for jd in cands if FRAME in jd["links"]]
    if not frame:
        other = next(lk for lk in cands[0]["links"] if lk != link)
        notes.append(f"input ({base}, {drive}) drives {link} relative to {other} (joint {cands[0]['id']}), "
                     "where Pyslvs turns it relative to the frame")
    return (frame or cands)[0]["id"]


def _ground_cranks(joints: list[dict[str, Any]], mobility: int, notes: list[str]) -> list[dict[str, Any]]:
    """The ``mobility`` shortest links pivoted on the frame by R joints (one joint each)."""
    if mobility <= 0:
        notes.append(f"mobility 3n - 2p5 = {mobility}: no input chosen")
        return []
    on: dict[str, list[dict[str, Any]]] = {}  # link -> its joints (one pass: linear time)
    for jd in joints:
        for lk in jd["links"]:
            on.setdefault(lk, []).append(jd)
    cand = []
    for jd in joints:
        if jd["type"] != "R" or FRAME not in jd["links"]:
            continue
        link = next(lk for lk in jd["links"] if lk != FRAME)
        if link.startswith("block") and any(o["type"] == "P" for o in on[link]):
            continue
        far = [math.hypot(o["point"][0] - jd["point"][0], o["point"][1] - jd["point"][1])
               for o in on[link] if o is not jd]
        reach = max(far) if far else math.inf
        cand.append((reach, len(cand), jd, link))
    cand.sort(key=lambda c: (c[0], c[1]))
    out: list[dict[str, Any]] = []
    used: set[str] = set()
    for _, _, jd, link in cand:
        if link not in used:
            out.append(jd)
            used.add(link)
        if len(out) == mobility:
            break
    if len(out) < mobility:
        notes.append(f"mobility {mobility} but only {len(out)} link(s) pivoted on the frame to drive")
    notes.append("inputs chosen (ground cranks): " + (", ".join(jd["id"] for jd in out) or "none")
                 + "; give --input BASE,DRIVE to choose others")
    return out


# --------------------------------------------------------------------------- from a mechanism file
def _close(p: Any, q: Any, scale: float) -> bool:
    return float(np.hypot(p[0] - q[0], p[1] - q[1])) <= 1e-9 * max(scale, 1.0)


_PID = re.compile(r"^P(\d+)(?:_\d+)?$")


def data_to_expression(data: dict[str, Any], source: str = "<mechanism>") -> PyslvsMechanism:
    """The Pyslvs expression of mechanism-file data (as :func:`mechsyn.io.mechanism_to_dict` gives).

    Planar mechanisms of R and P pairs with joint points. Blocks made by
    :func:`expression_to_data` (a link ``block<i>`` with one P joint and R joints all
    at that joint's point, carrying nothing else) become RP points again; other
    sliders stay P joints with their links; coincident R joints that share links become one point of all their links;
    named points become one-link points. The frame is renamed ``ground``.

    Examples
    --------
    >>> d = {"name": "x", "ground": "frame", "links": ["frame", "a"],
    ...      "joints": [{"id": "A", "type": "R", "links": ["frame", "a"], "point": [0, 0]}],
    ...      "points": {"T": {"link": "a", "at": [1, 0]}}}
    >>> [(j.type, j.links) for j in data_to_expression(d).joints]
    [('R', ('ground', 'a')), ('R', ('a',))]
    """
    ground, names, joints = _expressible(data, source)

    def nm(link: Any) -> str:
        return FRAME if str(link) == ground else str(link)

    pts = [jd["point"] for jd in joints] + [p["at"] for p in data.get("points", {}).values()]
    scale = float(np.max(np.abs(pts))) if pts else 1.0
    loads = {str(ld.get("link")) for ld in data.get("loads", [])}
    linked = {str(p["link"]) for p in data.get("points", {}).values()} | loads
    blocks = _blocks(names, joints, linked, scale)
    _absorb_pins(blocks, joints, scale)
    in_block = {id(jd) for p, rs in blocks.values() for jd in [p, *rs]}
    order = {id(jd): k for k, jd in enumerate(joints)}
    # groups: (order key, PyslvsJoint, member ids)
    groups = _block_groups(blocks, order, nm, source) + _pin_groups(joints, in_block, order, nm, scale)
    for k, jd in enumerate(joints):
        if jd["type"] == "P" and id(jd) not in in_block:
            ax = jd.get("axis") or [1.0, 0.0]
            groups.append(((k,), PyslvsJoint(
                "P", *map(float, jd["point"]), tuple(nm(x) for x in jd["links"]),
                math.degrees(math.atan2(ax[1], ax[0]))), [jd["id"]]))
    for k, (pname, p) in enumerate(data.get("points", {}).items()):
        groups.append(((len(joints) + k,), PyslvsJoint("R", *map(float, p["at"]), (nm(p["link"]),)), [pname]))
    _pyslvs_order(groups)
    colors = data.get("colors") or {}
    out = [replace(gj, color=next((colors[i] for i in ids if i in colors), None)) for _, gj, ids in groups]
    where = {jid: k for k, (_, _, ids) in enumerate(groups) for jid in ids}
    inputs, notes = _inputs(joints, in_block, ground, out, where, nm)
    return PyslvsMechanism(out, inputs, notes)


_Group = tuple[tuple[int, ...], PyslvsJoint, list[str]]


def _expressible(data: dict[str, Any], source: str) -> tuple[str, list[str], list[dict[str, Any]]]:
    """The frame, the link names and the joints of a planar file of R and P pairs with
    points; anything Pyslvs cannot express is refused, naming the field."""
    if data.get("kind", "planar") != "planar":
        raise MechsynInputError("a Pyslvs expression is planar; this mechanism is spatial", source=source,
                                field="kind")
    ground = str(data["ground"])
    names = [lk if isinstance(lk, str) else lk["name"] for lk in data["links"]]
    if FRAME in names and ground != FRAME:
        raise MechsynInputError(f"link named {FRAME!r} is not the frame ({ground})", source=source,
                                field="links", hint=f"rename it: Pyslvs calls the frame {FRAME!r}")
    joints = data.get("joints", [])
    for k, jd in enumerate(joints):
        if jd["type"] not in ("R", "P"):
            raise MechsynInputError(f"joint {jd['id']} is a {jd['type']} pair; Pyslvs has R, P and RP only",
                                    source=source, field=f"joints[{k}].type")
        if jd.get("point") is None:
            raise MechsynInputError(f"joint {jd['id']} has no point", source=source, field=f"joints[{k}].point",
                                    hint="give every joint its point [x, y]")
    return ground, names, joints


def _blocks(names: list[str], joints: list[dict[str, Any]], linked: set[str],
            scale: float) -> dict[str, tuple[dict[str, Any], list[dict[str, Any]]]]:
    """Links ``block<i>`` made by :func:`expression_to_data`: one P joint plus R joints at
    its point, nothing else on the link."""
    blocks: dict[str, tuple[dict[str, Any], list[dict[str, Any]]]] = {}
    on: dict[str, list[dict[str, Any]]] = {}  # link -> its joints (one pass: linear time)
    for jd in joints:
        for x in dict.fromkeys(map(str, jd["links"])):
            on.setdefault(x, []).append(jd)
    for name in names:
        if not re.fullmatch(r"block\d+(_\d+)?", name):
            continue
        own = on.get(name, [])
        ps = [jd for jd in own if jd["type"] == "P"]
        rs = [jd for jd in own if jd["type"] == "R"]
        if (name not in linked and len(ps) == 1 and rs and len(ps) + len(rs) == len(own)
                and all(_close(r["point"], ps[0]["point"], scale) for r in rs)):
            blocks[name] = (ps[0], rs)
    return blocks


def _absorb_pins(blocks: dict, joints: list[dict[str, Any]], scale: float) -> None:
    """Add to each block the R joints at its point that join the links turning on it to
    others (the third, fourth... link of a Pyslvs RP point): one RP point again."""
    on: dict[str, list[dict[str, Any]]] = {}
    for jd in joints:
        if jd["type"] == "R":
            for x in dict.fromkeys(map(str, jd["links"])):
                on.setdefault(x, []).append(jd)
    used = {id(jd) for p, rs in blocks.values() for jd in [p, *rs]}
    for bname, (p, rs) in blocks.items():
        todo = [str(x) for r in rs for x in r["links"] if str(x) != bname]
        while todo:
            link = todo.pop()
            for jd in on.get(link, []):
                if id(jd) not in used and _close(jd["point"], p["point"], scale):
                    used.add(id(jd))
                    rs.append(jd)
                    todo += [str(x) for x in jd["links"] if str(x) != link]


def _block_groups(blocks: dict, order: dict[int, int], nm: Any, source: str) -> list[_Group]:
    """Each block as one RP point: its guide link first, then the links turning on it."""
    groups: list[_Group] = []
    for bname, (p, rs) in blocks.items():
        guide = next(str(x) for x in p["links"] if str(x) != bname)
        others = list(dict.fromkeys(str(x) for r in rs for x in r["links"] if str(x) != bname))
        if guide in others:
            raise MechsynInputError(f"block {bname} slides along and turns on {guide}", source=source)
        ax = p.get("axis") or [1.0, 0.0]
        groups.append(((order[id(p)],), PyslvsJoint(
            "RP", *map(float, p["point"]), tuple(nm(x) for x in [guide, *others]),
            math.degrees(math.atan2(ax[1], ax[0]))), [p["id"], *[r["id"] for r in rs]]))
    return groups


def _pin_groups(joints: list[dict[str, Any]], in_block: set[int], order: dict[int, int], nm: Any,
                scale: float) -> list[_Group]:
    """Coincident R joints sharing links as one R point of all their links (frame first).

    Coincident joints are found through a grid of cells the size of the tolerance (each
    joint compared with those of its 3 x 3 cells only): linear time."""
    g = nx.Graph()
    rjs = [jd for jd in joints if jd["type"] == "R" and id(jd) not in in_block]
    g.add_nodes_from(range(len(rjs)))
    cell = 1e-9 * max(scale, 1.0)
    grid: dict[tuple[int, int], list[int]] = {}
    for a, jd in enumerate(rjs):
        cx, cy = (math.floor(float(v) / cell) for v in jd["point"][:2])
        near = [b for dx in (-1, 0, 1) for dy in (-1, 0, 1) for b in grid.get((cx + dx, cy + dy), ())]
        for b in near:
            if (_close(rjs[a]["point"], rjs[b]["point"], scale)
                    and set(map(str, rjs[a]["links"])) & set(map(str, rjs[b]["links"]))):
                g.add_edge(a, b)
        grid.setdefault((cx, cy), []).append(a)
    groups: list[_Group] = []
    for comp in nx.connected_components(g):
        members = [rjs[k] for k in sorted(comp)]
        names: list[str] = []
        for jd in members:
            for x in jd["links"]:
                if nm(x) not in names:
                    names.append(nm(x))
        if FRAME in names:
            names.remove(FRAME)
            names.insert(0, FRAME)
        groups.append(((order[id(members[0])],), PyslvsJoint("R", *map(float, members[0]["point"]),
                                                             tuple(names)), [m["id"] for m in members]))
    return groups


def _pyslvs_order(groups: list[_Group]) -> None:
    """Sort in place: by P<i> ids where every group has them, else by first appearance."""
    idx = [[int(m.group(1)) for m in map(_PID.match, ids) if m] for _, _, ids in groups]
    if all(len(i) == len(ids) and len(set(i)) == 1 for i, (_, _, ids) in zip(idx, groups)) and \
            len({i[0] for i in idx}) == len(idx):
        groups.sort(key=lambda gr: int(_PID.match(gr[2][0]).group(1)))  # type: ignore[union-attr]
    else:
        groups.sort(key=lambda gr: gr[0])


def _inputs(joints: list[dict[str, Any]], in_block: set[int], ground: str, out: list[PyslvsJoint],
            where: dict[str, int], nm: Any) -> tuple[list[tuple[int, int]], list[str]]:
    """Pyslvs input pairs (base point, drive point) of the driven R joints, and notes on
    the driven joints an input cannot express."""
    inputs: list[tuple[int, int]] = []
    notes: list[str] = []
    points_of: dict[str, list[int]] = {}  # link -> the first two points on it
    for k, gj in enumerate(out):
        for lk in gj.links:
            if len(points_of.setdefault(lk, [])) < 2:
                points_of[lk].append(k)
    for jd in joints:
        if not jd.get("actuated"):
            continue
        if jd["type"] == "P" and jd["id"] in where:  # a slider's travel: Pyslvs' input (i, i)
            inputs.append((where[jd["id"]], where[jd["id"]]))
            continue
        if jd["type"] != "R" or id(jd) in in_block:
            notes.append(f"driven joint {jd['id']} is not a pin Pyslvs can drive: left out of the inputs")
            continue
        moving = str(jd["links"][1]) if str(jd["links"][0]) == ground else str(jd["links"][0])
        if str(jd["links"][0]) != ground and str(jd["links"][1]) != ground:
            moving = str(jd["links"][1])
            notes.append(f"driven joint {jd['id']} turns {moving} relative to {jd['links'][0]}; a Pyslvs "
                         "input turns it relative to the frame")
        base = where[jd["id"]]
        drive = next((k for k in points_of.get(nm(moving), []) if k != base), None)
        if drive is None:
            notes.append(f"driven joint {jd['id']}: {moving} has no other point to make an input pair")
            continue
        inputs.append((base, drive))
    return inputs, notes


# --------------------------------------------------------------------------- files
def read_pyslvs(text: str, source: str, inputs: list[tuple[int, int]] | None = None,
                name: str | None = None) -> tuple[dict[str, Any], list[str]]:
    """Mechanism-file data and notes from the text of a Pyslvs expression file."""
    expr = parse_expression(text, source)
    stem = re.sub(r"\.[^./\\]*$", "", re.split(r"[/\\]", source)[-1])
    return expression_to_data(expr, name or stem, source, inputs)


def pyslvs_text(data: dict[str, Any], source: str = "<mechanism>") -> tuple[str, list[str]]:
    """The text of a Pyslvs expression file (with an ``# inputs:`` line) and notes."""
    expr = data_to_expression(data, source)
    return format_expression(expr.joints, expr.inputs) + "\n", expr.notes


#: Pyslvs' colour names that are not Matplotlib's
_COLOR_NAMES = {"brick-red": "firebrick", "dark-gray": "dimgray", "dark-yellow": "olive",
                "dark-pink": "mediumvioletred", "dark-orange": "darkorange"}
_RGB = re.compile(r"^\(?\s*(\d+)\s*,\s*(\d+)\s*,\s*(\d+)\s*\)?$")


def color_rgb(color: str) -> tuple[float, float, float] | None:
    """RGB in [0, 1] of a colour as Pyslvs writes it (``Green``, ``dark-blue``,
    ``(255, 0, 0)``) or as Matplotlib names it (``tab:blue``, ``#1f77b4``); None if unknown.

    Examples
    --------
    >>> color_rgb("Green"), color_rgb("(255, 128, 0)")
    ((0.0, 0.5019607843137255, 0.0), (1.0, 0.5019607843137255, 0.0))
    >>> color_rgb("dark-blue"), color_rgb("no such colour")
    ((0.0, 0.0, 0.5450980392156862), None)
    """
    from matplotlib.colors import to_rgb

    text = color.strip()
    m = _RGB.match(text)
    if m:
        rgb = tuple(int(g) for g in m.groups())
        return tuple(v / 255 for v in rgb) if max(rgb) <= 255 else None  # type: ignore[return-value]
    name = _COLOR_NAMES.get(text.lower(), text.lower().replace("-", ""))
    for candidate in (text, name):
        try:
            return to_rgb(candidate)
        except ValueError:
            continue
    return None
