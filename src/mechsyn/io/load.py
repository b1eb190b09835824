"""Reading and writing mechanism files (YAML or JSON), with clear errors.

Every problem raises :class:`mechsyn.errors.MechsynInputError` naming the file, the
line, the field and how to fix it.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import ValidationError

from mechsyn.errors import MechsynInputError, input_boundary
from mechsyn.io import files
from mechsyn.io.checks import check_counts, check_geometry, link_components
from mechsyn.io.plain import plain_spec
from mechsyn.io.schema import JointEntry, LinkEntry, MechanismFile, StateEntry
from mechsyn.model.contour import contour_links
from mechsyn.model.mechanism import (
    ExternalSpec,
    Joint,
    Link,
    Mechanism,
    PointSpec,
    StateSpec,
)
from mechsyn.model.pairs import PAIR_KINDS, canonical_pair_type
from mechsyn.results import to_jsonable, write_atomic

__all__ = [
    "load", "loads", "save", "load_mechanism", "mechanism_from_dict", "mechanism_from_text",
    "mechanism_to_dict", "mechanism_text", "write_mechanism", "read_data",
]

_YAML_LOADER = files._YAML_LOADER


def safe_load_yaml(text: str) -> Any:
    """``yaml.safe_load`` through LibYAML when available."""
    return yaml.load(text, Loader=_YAML_LOADER)  # noqa: S506 (a safe loader)


# --------------------------------------------------------------------------- reading
def read_data(path: str | os.PathLike[str]) -> tuple[Any, str]:
    """Parse a YAML or JSON file (or a bundled example, by name) into Python data; return it
    with its text (:func:`mechsyn.io.files.read_data`, the one reader of every input file)."""
    from mechsyn.examples import resolve

    try:
        path = resolve(path)
    except OSError:  # e.g. a name too long for the file system: the reader says so
        pass
    return files.read_data(path)


def parse_text(text: str, source: str) -> Any:
    """Parse YAML (or JSON, when the source ends in .json) text."""
    return files.parse_data(text, source)


def _line_finder(text: str | None, source: str) -> Any:
    """A function mapping a data path (keys and indices) to its 1-based line (the text is
    parsed again, into YAML nodes with their marks, only when a line is asked for: a valid
    file is parsed once)."""
    composed: list[Any] = []

    def document() -> Any:
        if not composed:
            try:
                composed.append(None if text is None else yaml.compose(text, Loader=files._YAML_LOADER))
            except yaml.YAMLError:
                composed.append(None)
        return composed[0]

    def find(path: Sequence[Any]) -> int | None:
        node = document()
        line = None
        for key in path:
            if node is None:
                break
            if isinstance(node, yaml.MappingNode):
                nxt = None
                for k, v in node.value:
                    if str(getattr(k, "value", None)) == str(key):
                        nxt = v
                        line = k.start_mark.line + 1
                        break
                node = nxt
            elif isinstance(node, yaml.SequenceNode) and isinstance(key, int):
                if 0 <= key < len(node.value):
                    node = node.value[key]
                    line = node.start_mark.line + 1
                else:
                    node = None
            else:
                break
        return line

    return find


def _field_name(path: Sequence[Any]) -> str:
    out = ""
    for key in path:
        if isinstance(key, int):
            out += f"[{key}]"
        else:
            out += ("." if out else "") + str(key)
    return out


def _data_path(data: Any, loc: Sequence[Any]) -> list[Any]:
    """Keep the parts of a pydantic error location that exist in the data."""
    path: list[Any] = []
    node = data
    for key in loc:
        if isinstance(node, dict) and key in node:
            node = node[key]
            path.append(key)
        elif isinstance(node, list) and isinstance(key, int) and 0 <= key < len(node):
            node = node[key]
            path.append(key)
        elif isinstance(node, dict) and isinstance(key, str) and key not in node and not path[-1:] == [key]:
            # a missing field (pydantic names it) or a union member name: keep missing fields
            if key in _KNOWN_FIELDS:
                path.append(key)
                node = None
        # otherwise a union tag such as 'str' or 'LinkEntry': skip
    return path


_KNOWN_FIELDS = set(MechanismFile.model_fields) | set(JointEntry.model_fields) | {"class"} \
    | set(StateEntry.model_fields) | {"link", "at"}


_HINTS = {
    "missing": "add the field",
    "extra_forbidden": "remove it or check its spelling",
    "literal_error": None,
    "int_parsing": "give a whole number",
    "float_parsing": "give a number",
    "list_type": "give a list, e.g. [a, b]",
    "dict_type": "give a mapping of names to values",
    "string_type": "give a text value",
    "greater_than_equal": "give a value that is not negative",
    "greater_than": "give a positive value",
    "finite_number": "give a finite number",
    "bool_not_number": "write a number such as 0 or 1, not true/false",
    "too_short": None,
}


def _validation_error(exc: ValidationError, data: Any, source: str, text: str | None) -> MechsynInputError:
    errors = exc.errors()
    # Prefer the most specific error: for unions pydantic reports one per member (a link
    # given as a mapping fails as text too); the one reaching deepest into the data is
    # the member the user meant.
    paths = [tuple(_data_path(data, e["loc"])) for e in errors]
    best = max(range(len(errors)), key=lambda i: (len(paths[i]), -i))
    err, loc = errors[best], list(paths[best])
    find = _line_finder(text, source)
    msg = err["msg"]
    if err["type"] == "extra_forbidden":
        msg = "unknown field"
    elif err["type"] == "missing":
        msg = "required field is missing"
    # other problems: other places (not the union members failing at an enclosing one)
    more = len({p for p in paths if p != tuple(loc) and tuple(loc)[:len(p)] != p})
    if more > 0:
        msg += f" (and {more} more problem{'s' if more > 1 else ''})"
    return MechsynInputError(
        msg, source=source, field=_field_name(loc) or None, line=find(loc),
        hint=_HINTS.get(err["type"]),
    )


@input_boundary("mechanism file")
def mechanism_from_dict(data: Any, source: str = "<data>", text: str | None = None) -> Mechanism:
    """Validate mechanism-file data and build a :class:`Mechanism`.

    ``text`` (the file's text) lets errors name their line.
    """
    if not isinstance(data, dict):
        raise MechsynInputError(
            "a mechanism file must be a mapping with name, kind, ground, links, joints",
            source=source, line=1, hint="see `mechsyn schema` and the files in examples/",
        )
    check_counts(data, source)
    files.check_data_size(data, source)  # nesting, size, hidden characters in ids (issue 27)
    try:  # a plain file without building pydantic's validators (the same models)
        spec = plain_spec(data)
        if spec is None:
            spec = MechanismFile.model_validate(data)
    except ValidationError as exc:
        raise _validation_error(exc, data, source, text) from None
    return check_geometry(_Builder(spec, source, _line_finder(text, source)).build(), source)


def mechanism_from_text(text: str, source: str = "<text>") -> Mechanism:
    """Parse and build a mechanism from YAML/JSON text."""
    return mechanism_from_dict(parse_text(text, source), source, text)


def load_mechanism(path: str | os.PathLike[str]) -> Mechanism:
    """Read a mechanism file (YAML or JSON), validated.

    Raises
    ------
    MechsynInputError
        naming the file, line and field of the first problem, with a fix.

    Examples
    --------
    >>> import mechsyn as ms
    >>> ms.load_mechanism(ms.examples.path("slider_crank")).pairs_by_class()
    {5: 4}
    """
    from mechsyn.examples import resolve

    data, text = read_data(path)
    return mechanism_from_dict(data, str(resolve(path)), text)


def load(source: str | os.PathLike[str] | dict[str, Any] | Mechanism) -> Mechanism:
    """A mechanism from a file (YAML or JSON), file-format data (a dict), or the name of
    one of the bundled examples (:mod:`mechsyn.examples`).

    Parameters
    ----------
    source : path, dict or str
        A mechanism file, its data, or an example's name such as ``"fourbar"``.

    Returns
    -------
    Mechanism

    Raises
    ------
    MechsynInputError
        naming the file, line and field of the first problem, with a fix.

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = ms.load({"name": "four-bar", "kind": "planar", "ground": "frame",
    ...              "links": ["frame", "crank", "coupler", "rocker"],
    ...              "joints": [{"id": "A", "type": "R", "links": ["frame", "crank"]},
    ...                         {"id": "B", "type": "R", "links": ["crank", "coupler"]},
    ...                         {"id": "C", "type": "R", "links": ["coupler", "rocker"]},
    ...                         {"id": "D", "type": "R", "links": ["rocker", "frame"]}]})
    >>> m.n_moving, len(m.joints)
    (3, 4)
    """
    if isinstance(source, Mechanism):
        return source
    if isinstance(source, dict):
        return mechanism_from_dict(source)
    return load_mechanism(source)


def loads(text: str, format: str = "yaml") -> Mechanism:
    """A mechanism from the text of a file, ``format`` ``"yaml"`` (JSON is YAML too) or
    ``"json"``.

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = ms.loads('''
    ... name: slider-crank
    ... kind: planar
    ... ground: frame
    ... links: [frame, crank, rod, slider]
    ... joints:
    ...   - {id: A, type: R, links: [frame, crank]}
    ...   - {id: B, type: R, links: [crank, rod]}
    ...   - {id: C, type: R, links: [rod, slider]}
    ...   - {id: D, type: P, links: [slider, frame]}
    ... ''')
    >>> m.pairs_by_class()
    {5: 4}
    """
    if format not in ("yaml", "json"):
        raise MechsynInputError(f"unknown format {format!r}", field="format", hint="use yaml or json")
    return mechanism_from_text(text, "<text>.json" if format == "json" else "<text>")


def save(mech: Mechanism | dict[str, Any], path: str | os.PathLike[str]) -> None:
    """Write ``mech`` as a mechanism file: YAML, or JSON for a ``.json`` path; whole or not
    at all (the same as :func:`write_mechanism`).

    Examples
    --------
    >>> import mechsyn as ms, tempfile, pathlib
    >>> m = ms.examples.load("fourbar")
    >>> with tempfile.TemporaryDirectory() as d:
    ...     ms.save(m, pathlib.Path(d) / "copy.yaml")
    ...     ms.load(pathlib.Path(d) / "copy.yaml").name == m.name
    True
    """
    write_mechanism(mech, path)


#: The length units a file may name (``unit``).
UNITS = ("mm", "cm", "m", "in")


class _Builder:
    """Resolves names, checks the semantics, converts to the model."""

    def __init__(self, spec: MechanismFile, source: str, find: Any) -> None:
        self.spec = spec
        self.source = source
        self.find = find
        self.kind = spec.kind
        self.dim = 2 if spec.kind == "planar" else 3

    def error(self, path: Sequence[Any], message: str, hint: str | None = None) -> MechsynInputError:
        return MechsynInputError(
            message, source=self.source, field=_field_name(path), line=self.find(path), hint=hint,
        )

    # links ---------------------------------------------------------------------------
    def _links(self, entries: Sequence[str | LinkEntry], path0: str, names: dict[str, str] | None = None,
               ids: dict[int, str] | None = None) -> tuple[list[Link], dict[str, str], dict[int, str]]:
        links: list[Link] = []
        names = dict(names or {})
        ids = dict(ids or {})
        for i, entry in enumerate(entries):
            path = [path0, i]
            if isinstance(entry, str):
                name, attrs, lid = entry, {}, None
            else:
                attrs = entry.model_dump(exclude_none=True, exclude={"name", "id"})
                lid = entry.id
                name = entry.name if entry.name is not None else (str(lid) if lid is not None else None)
                if name is None:
                    raise self.error(path, "a link needs a name or an id", "add `name: ...`")
            name = name.strip()
            if not name:
                raise self.error(path, "empty link name")
            if name in names:
                raise self.error(path, f"duplicate link name {name!r}", "give each link a unique name")
            if lid is not None:
                if lid in ids:
                    raise self.error(path, f"duplicate link id {lid}", "give each link a unique id")
                ids[lid] = name
            names[name] = name
            links.append(Link(name=name, attrs=attrs))
        return links, names, ids

    def resolve_link(self, ref: Any, path: Sequence[Any], names: dict[str, str], ids: dict[int, str]) -> str:
        if isinstance(ref, bool):
            raise self.error(path, f"{ref!r} is not a link")
        if isinstance(ref, int):
            if ref in ids:
                return ids[ref]
            if str(ref) in names:
                return str(ref)
            raise self.error(path, f"unknown link id {ref}", f"links are: {', '.join(names)}")
        if ref in names:
            return ref
        raise self.error(path, f"unknown link {ref!r}", f"links are: {', '.join(names)}")

    # geometry --------------------------------------------------------------------------
    def vector(self, values: list[float] | None, path: Sequence[Any], what: str, dim: int | None = None,
               unit: bool = False) -> np.ndarray | None:
        if values is None:
            return None
        dim = dim or self.dim
        if len(values) != dim:
            raise self.error(
                path, f"{what} has {len(values)} coordinates; a {self.kind} mechanism needs {dim}",
                f"write [{', '.join('x y z'.split()[:dim])}]",
            )
        v = np.asarray(values, dtype=float)
        if not np.all(np.isfinite(v)):
            raise self.error(path, f"{what} must be finite numbers")
        if unit:
            norm = float(np.linalg.norm(v))
            if norm < 1e-12:
                raise self.error(path, f"{what} is a zero vector", "give a direction, e.g. [1, 0]")
            v = v / norm
        return v

    # joints ----------------------------------------------------------------------------
    def joint(self, entry: JointEntry, path: list[Any], names: dict[str, str], ids: dict[int, str]) -> Joint:
        jtype, kind = self.pair_type(entry, path)
        if len(entry.links) != 2:
            raise self.error(path + ["links"], f"a pair joins exactly two links, {len(entry.links)} given",
                             "write links: [a, b]")
        a = self.resolve_link(entry.links[0], path + ["links", 0], names, ids)
        b = self.resolve_link(entry.links[1], path + ["links", 1], names, ids)
        if a == b:
            raise self.error(path + ["links"], f"a pair must join two different links, both are {a!r}")
        given = entry.pair_class
        if given is not None and not 1 <= given <= 5:
            raise self.error(path + ["class"], f"class {given} is out of 1..5",
                             "the class is the number of constraints: 1 (point contact) .. 5 (R, P, H)")
        if self.kind == "planar":
            pair_class, higher_override = self.planar_class(path, jtype, kind, given)
        else:
            pair_class, higher_override = self.spatial_class(path, jtype, kind, given)
        point, axis, axis2, normal = self.joint_geometry(entry, path, jtype)
        self.check_type_fields(entry, path, jtype)
        limits = None
        if entry.limits is not None:
            if len(entry.limits) != 2 or entry.limits[0] > entry.limits[1]:
                raise self.error(path + ["limits"], "limits must be [min, max] with min <= max")
            limits = (float(entry.limits[0]), float(entry.limits[1]))
        attrs = {"description": entry.description} if entry.description else {}
        if entry.zero is not None:
            attrs["zero"] = self.zero(entry, path, jtype, axis)
        if entry.profile is not None:
            if jtype != "cam":
                raise self.error(path + ["profile"], "only a cam pair has a profile", "remove `profile`")
            attrs["profile"] = self.profile(entry.profile, path + ["profile"])
        belt_fields = {"anchor": entry.anchor, "radius": entry.radius, "wrap": entry.wrap}
        if jtype != "belt":
            for key, v in belt_fields.items():
                if v is not None:
                    raise self.error(path + [key], f"only a belt pair has `{key}`", f"remove `{key}` or set type: belt")
        else:
            attrs.update(self.belt(entry, path, point))
        return Joint(
            id=entry.id, type=jtype, links=(a, b), pair_class=pair_class, point=point, axis=axis,
            axis2=axis2, normal=normal, pitch=entry.pitch, ratio=entry.ratio, actuated=entry.actuated,
            vll=entry.vll, limits=limits, attrs=attrs, higher_override=higher_override,
        )

    def pair_type(self, entry: JointEntry, path: list[Any]) -> tuple[str, Any]:
        """The catalogue type of a joint and its kind; a spatial pair in a planar file is refused."""
        jtype = canonical_pair_type(entry.type)
        if jtype is None:
            raise self.error(
                path + ["type"], f"unknown pair type {entry.type!r}",
                f"use one of {', '.join(PAIR_KINDS)}",
            )
        kind = PAIR_KINDS[jtype]
        if self.kind == "planar" and not kind.planar:
            raise self.error(
                path + ["type"],
                f"pair {jtype} ({kind.title}) is spatial and cannot appear in a planar mechanism",
                "use R, P, cam, gear, belt or generic, or set `kind: spatial`",
            )
        return jtype, kind

    def planar_class(self, path: list[Any], jtype: str, kind: Any, given: int | None) -> tuple[int, bool | None]:
        """Class of a planar pair (5 lower, 4 higher) and the generic pair's higher flag."""
        if jtype == "generic":
            if given is None:
                raise self.error(path, "a generic pair needs `class`", "add class: 5 (lower) or 4 (higher)")
            if given not in (4, 5):
                raise self.error(path + ["class"], f"class {given} is not a planar pair class",
                                 "in a planar mechanism use 5 (lower pair) or 4 (higher pair)")
            return given, given == 4
        pair_class = 4 if kind.higher else 5
        if given is not None and given != pair_class:
            raise self.error(path + ["class"],
                             f"a planar {jtype} pair counts as class {pair_class}, not {given}",
                             "remove `class`")
        return pair_class, None

    def spatial_class(self, path: list[Any], jtype: str, kind: Any, given: int | None) -> tuple[int, bool | None]:
        """Class of a spatial pair (the catalogue's, or the file's for generic, cam and gear)."""
        if kind.pair_class is None:
            if jtype == "generic" and given is None:
                raise self.error(path, "a generic pair needs `class`", "add class: 1..5")
            pair_class = given if given is not None else 2  # cam/gear: line contact
        else:
            pair_class = kind.pair_class
            if given is not None and given != pair_class:
                raise self.error(
                    path + ["class"], f"a {jtype} pair ({kind.title}) is class {pair_class}, not {given}",
                    "remove `class`, or use type: generic to give any class",
                )
        return pair_class, (pair_class <= 2 if jtype == "generic" else None)

    def joint_geometry(self, entry: JointEntry, path: list[Any], jtype: str) -> tuple[np.ndarray | None, ...]:
        """Point, axis, axis2 and normal of a joint (directions as unit vectors)."""
        point = self.vector(entry.point, path + ["point"], "point")
        axis = None
        if entry.axis is not None:
            if self.kind == "planar" and jtype == "R":
                raise self.error(path + ["axis"],
                                 "an R pair in a planar mechanism turns about the plane's normal",
                                 "remove `axis`")
            axis = self.vector(entry.axis, path + ["axis"], "axis", unit=True)
        if self.kind == "planar" and jtype == "P" and axis is None and point is not None:
            raise self.error(path + ["axis"], f"planar P pair {entry.id} has no axis: its sliding direction "
                             "is not assumed", "add axis: [dx, dy], e.g. axis: [1, 0] to slide along x")
        axis2 = self.vector(entry.axis2, path + ["axis2"], "axis2", unit=True)
        normal = self.vector(entry.normal, path + ["normal"], "normal", unit=True)
        return point, axis, axis2, normal

    def zero(self, entry: JointEntry, path: list[Any], jtype: str, axis: Any) -> list[float]:
        """A spatial R, H or C pair's input zero: a direction perpendicular to its axis."""
        if self.kind != "spatial" or jtype not in ("R", "H", "C"):
            raise self.error(path + ["zero"], "only an R, H or C pair of a spatial mechanism has a zero",
                             "remove `zero` (a planar input is the driven link's angle)")
        z = np.asarray(self.vector(entry.zero, path + ["zero"], "zero direction"), float)
        a = np.asarray(axis, float)
        if z.shape != (3,) or not np.linalg.norm(z) > 0 or abs(z @ a) > 1e-6 * np.linalg.norm(z) * np.linalg.norm(a):
            raise self.error(path + ["zero"], "zero must be a nonzero direction [dx, dy, dz] perpendicular to the axis",
                             "give a direction at right angles to `axis`")
        return [float(v) for v in z]

    def check_type_fields(self, entry: JointEntry, path: list[Any], jtype: str) -> None:
        """Pitch, ratio and vll belong to H, gear and prismatic pairs only."""
        if entry.pitch is not None and jtype != "H":
            raise self.error(path + ["pitch"], "only a helical (H) pair has a pitch", "remove `pitch`")
        if entry.ratio is not None and jtype != "gear":
            raise self.error(path + ["ratio"], "only a gear pair has a ratio", "remove `ratio`")
        if entry.vll is not None and jtype not in ("P", "C", "generic"):
            raise self.error(path + ["vll"], "a variable-length link is a prismatic (P) pair",
                             "set type: P or remove `vll`")

    def profile(self, prof: Any, path: list[Any]) -> Any:
        """A cam profile: a list of at least 4 points, or a circle, or a polar curve r(t)."""
        if isinstance(prof, list):
            pts = [self.vector(p, path + [k], "profile point") for k, p in enumerate(prof)]
            if len(pts) < 4:
                raise self.error(path, "a cam profile needs at least 4 points", "list points round the whole cam")
            return [[float(x) for x in p] for p in pts]
        c = self.vector(prof.center, path + ["center"], "profile centre")
        if (prof.radius is None) == (prof.polar is None):
            raise self.error(path, "a cam profile needs either radius or polar",
                             "write {center: [x, y], radius: r} or {center: [x, y], polar: '1 + 0.2*cos(t)'}")
        if prof.radius is not None:
            return {"center": [float(x) for x in c], "radius": float(prof.radius)}
        from mechsyn.kinematics.expr import ExpressionError, polar_points

        try:
            pts = polar_points(prof.polar, c)
        except ExpressionError as exc:
            raise self.error(path + ["polar"], str(exc),
                             "use t, pi, numbers, + - * / **, sin, cos, tan, exp, sqrt, abs") from None
        return {"center": [float(x) for x in c], "polar": prof.polar, "points": pts.tolist()}

    def belt(self, entry: JointEntry, path: list[Any], point: np.ndarray | None) -> dict[str, Any]:
        """Check a belt pair's fields: anchor (on the first link), radius, wrap, point (the
        pulley centre on the second link); the anchor must lie outside the pulley."""
        example = "e.g. {id: W, type: belt, links: [frame, hand], point: [0, 500], anchor: [75, 88.2], radius: 75, wrap: ccw}"
        for key in ("anchor", "radius", "wrap"):
            if getattr(entry, key) is None:
                raise self.error(path, f"belt pair {entry.id} needs `{key}`", example)
        if point is None:
            raise self.error(path, f"belt pair {entry.id} needs `point` (the pulley centre)", example)
        anchor = self.vector(entry.anchor, path + ["anchor"], "anchor")
        d = float(np.linalg.norm(anchor[:2] - point[:2]))
        if d <= entry.radius:
            raise self.error(path + ["anchor"],
                             f"the anchor is {d:g} from the pulley centre, not outside the radius {entry.radius:g}",
                             "a taut straight belt needs the anchor farther from the centre than the radius")
        return {"anchor": [float(x) for x in anchor], "radius": float(entry.radius), "wrap": entry.wrap}

    def no_look_alikes(self, path0: str, texts: list[str], what: str) -> None:
        """Refuse two ids that look the same and differ (Latin ``A`` and Cyrillic ``А``, a
        fullwidth letter...): their skeletons (:func:`mechsyn.io.files.id_skeleton`) match."""
        from mechsyn.io.files import confusable_id

        if all(t.isascii() for t in texts):
            return
        seen: dict[str, str] = {}
        for i, text in enumerate(texts):
            other = confusable_id(text, seen)
            if other is not None:
                codes = " ".join(f"U+{ord(c):04X}" for c in text if not c.isascii())[:80]
                raise self.error([path0, i], f"the {what} {text!r} ({codes}) looks like {other!r}",
                                 f"give each {what} a name that differs on screen")

    def joints(self, entries: Sequence[JointEntry], path0: list[Any], names: dict[str, str],
               ids: dict[int, str], taken: set[str]) -> list[Joint]:
        out = []
        for i, entry in enumerate(entries):
            path = path0 + [i]
            if entry.id in taken:
                raise self.error(path + ["id"], f"duplicate joint id {entry.id!r}", "give each joint a unique id")
            taken.add(entry.id)
            out.append(self.joint(entry, path, names, ids))
        return out

    def contours(self, contours: list[list[str]] | None, path0: list[Any], joints: dict[str, Joint]) -> tuple[tuple[str, ...], ...] | None:
        if contours is None:
            return None
        out = []
        for c, ids in enumerate(contours):
            path = path0 + [c]
            for k, jid in enumerate(ids):
                if jid not in joints:
                    raise self.error(path + [k], f"unknown joint {jid!r} in contour",
                                     f"joints are: {', '.join(joints)}")
            if len(set(ids)) != len(ids):
                raise self.error(path, "a joint appears twice in the contour")
            if contour_links([joints[j] for j in ids]) is None:
                raise self.error(
                    path, f"contour {' '.join(ids)} is not a closed loop",
                    "list the joints in the order met walking round the loop, each sharing a link "
                    "with the next and the last with the first",
                )
            out.append(tuple(ids))
        return tuple(out)

    def unit(self, spec: Any) -> str | None:
        """The file's length unit: ``unit``, else the older ``units`` when it names one of the
        same (mm, cm, m, in); both given and different is refused."""
        old = (spec.units or "").strip().lower() or None
        if spec.unit and old and old in UNITS and old != spec.unit:
            raise self.error(["unit"], f"unit {spec.unit} and units {spec.units} disagree", "keep unit only")
        return spec.unit or (old if old in UNITS else None)

    def check_connected(self, links: Sequence[Link], joints: Sequence[Joint], path: list[Any]) -> None:
        parts = link_components([link.name for link in links], [j.links for j in joints])
        if len(parts) > 1:
            raise self.error(
                path, f"the mechanism is disconnected: {', '.join(parts[0])} "
                f"{'is' if len(parts[0]) == 1 else 'are'} joined to no other part",
                "add the missing joints or remove the stray links",
            )

    def loads(self, entries: Sequence[Any], names: dict[str, str], ids: dict[int, str],
              points: dict[str, PointSpec]) -> list[dict[str, Any]]:
        out = []
        for k, e in enumerate(entries):
            path: list[Any] = ["loads", k]
            link = self.resolve_link(e.link, path + ["link"], names, ids)
            if e.force is None and e.moment is None:
                raise self.error(path, "a load needs a force or a moment", "add force: [Fx, Fy] or moment: M")
            if e.at is not None and e.point is not None:
                raise self.error(path, "give either `at` or `point`, not both")
            at = self.vector(e.at, path + ["at"], "load point")
            if e.point is not None:
                if e.point not in points:
                    raise self.error(path + ["point"], f"unknown point {e.point!r}",
                                     f"points are: {', '.join(points) or '(none)'}")
                if points[e.point].link != link:
                    raise self.error(path + ["point"], f"point {e.point} is on link {points[e.point].link}, "
                                     f"not {link}")
                at = points[e.point].at
            d: dict[str, Any] = {"link": link}
            if e.force is not None:
                d["force"] = [float(x) for x in self.vector(e.force, path + ["force"], "force")]
            if at is not None:
                d["at"] = [float(x) for x in at]
            if e.point is not None:
                d["point"] = e.point
            if e.moment is not None:
                d["moment"] = float(e.moment)
            if e.description:
                d["description"] = e.description
            out.append(d)
        return out

    # whole file --------------------------------------------------------------------------
    def build(self) -> Mechanism:
        spec = self.spec
        links, names, ids = self._links(spec.links, "links")
        self.no_look_alikes("links", [lk.name for lk in links], "link name")
        ground = self.resolve_link(spec.ground, ["ground"], names, ids)
        taken: set[str] = set()
        joints = self.joints(spec.joints, ["joints"], names, ids, taken)
        self.no_look_alikes("joints", [j.id for j in joints], "joint id")
        self.no_look_alikes("points", list(spec.points), "point name")
        self.check_connected(links, joints, ["joints"])
        by_id = {j.id: j for j in joints}
        contours = self.contours(spec.contours, ["contours"], by_id)
        points = {}
        for pname, p in spec.points.items():
            link = self.resolve_link(p.link, ["points", pname, "link"], names, ids)
            points[pname] = PointSpec(link=link, at=self.vector(p.at, ["points", pname, "at"], "point"))
        states = {}
        for sname, s in spec.states.items():
            spath: list[Any] = ["states", sname]
            slinks, snames, sids = self._links(s.add_links, "add_links", names, ids) if s.add_links else ([], names, ids)
            sjoints = self.joints(s.add_joints, spath + ["add_joints"], snames, sids, set(taken))
            all_joints = {**by_id, **{j.id: j for j in sjoints}}
            scontours = self.contours(s.contours, spath + ["contours"], all_joints)
            self.check_connected(links + slinks, joints + sjoints, spath)
            ext = None
            if s.external is not None:
                ext = ExternalSpec(**s.external.model_dump())
            states[sname] = StateSpec(
                name=sname, description=s.description or "", add_links=tuple(slinks),
                add_joints=tuple(sjoints), contours=scontours, external=ext, mobility=s.mobility,
            )
        attrs = {k: v for k, v in (("description", spec.description), ("source", spec.source),
                                   ("units", spec.units), ("unit", self.unit(spec))) if v}
        # display only: the colour of a joint or point the file no longer has (deleted in the
        # studio, dropped by a synthesis) is let go rather than refusing the whole mechanism
        colors = {k: v for k, v in spec.colors.items() if k in by_id or k in points}
        if colors:
            attrs["colors"] = colors
        if spec.loads:
            attrs["loads"] = self.loads(spec.loads, names, ids, points)
        return Mechanism(
            name=spec.name, kind=spec.kind, ground=ground, links=tuple(links), joints=tuple(joints),
            points=points, contours=contours, states=states, mobility=spec.mobility,
            source=self.source, attrs=attrs,
        )


# --------------------------------------------------------------------------- writing
def _joint_dict(j: Joint, kind: str) -> dict[str, Any]:
    d: dict[str, Any] = {"id": j.id, "type": j.type, "links": list(j.links)}
    if j.type == "generic" or (kind == "spatial" and j.type in ("cam", "gear", "belt")):
        d["class"] = j.pair_class
    for key in ("point", "axis", "axis2", "normal"):
        v = getattr(j, key)
        if v is not None:
            d[key] = [float(x) for x in v]
    for key in ("pitch", "ratio", "vll"):
        v = getattr(j, key)
        if v is not None:
            d[key] = v
    if j.limits is not None:
        d["limits"] = list(j.limits)
    if j.actuated:
        d["actuated"] = True
    if j.attrs.get("profile") is not None:
        prof = j.attrs["profile"]
        d["profile"] = {k: v for k, v in prof.items() if k != "points"} if isinstance(prof, dict) else prof
    if j.type == "belt":
        for key in ("anchor", "radius", "wrap"):
            if j.attrs.get(key) is not None:
                d[key] = j.attrs[key]
    if j.attrs.get("zero") is not None:
        d["zero"] = list(j.attrs["zero"])
    if j.attrs.get("description"):
        d["description"] = j.attrs["description"]
    return d


def mechanism_to_dict(mech: Mechanism) -> dict[str, Any]:
    """The file-format data of ``mech`` (inverse of :func:`mechanism_from_dict`)."""
    links: list[Any] = [
        {"name": link.name, **to_jsonable(link.attrs)} if link.attrs else link.name for link in mech.links
    ]
    d: dict[str, Any] = {"name": mech.name, "kind": mech.kind, "ground": mech.ground, "links": links,
                         "joints": [_joint_dict(j, mech.kind) for j in mech.joints]}
    if mech.points:
        d["points"] = {k: {"link": p.link, "at": [float(x) for x in p.at]} for k, p in mech.points.items()}
    if mech.contours is not None:
        d["contours"] = [list(c) for c in mech.contours]
    if mech.mobility is not None:
        d["mobility"] = mech.mobility
    for key in ("description", "source", "unit", "units", "colors"):
        if mech.attrs.get(key):
            d[key] = mech.attrs[key]
    if mech.attrs.get("loads"):
        d["loads"] = [{k: v for k, v in ld.items() if not (k == "at" and "point" in ld)}
                      for ld in mech.attrs["loads"]]
    if mech.states:
        states = {}
        for name, s in mech.states.items():
            sd: dict[str, Any] = {}
            if s.description:
                sd["description"] = s.description
            if s.add_links:
                sd["add_links"] = [{"name": lk.name, **lk.attrs} if lk.attrs else lk.name for lk in s.add_links]
            if s.add_joints:
                sd["add_joints"] = [_joint_dict(j, mech.kind) for j in s.add_joints]
            if s.contours is not None:
                sd["contours"] = [list(c) for c in s.contours]
            if s.external is not None:
                sd["external"] = {k: v for k, v in to_jsonable(s.external).items() if v is not None}
            if s.mobility is not None:
                sd["mobility"] = s.mobility
            states[name] = sd
        d["states"] = states
    return d


def mechanism_text(mech: Mechanism | dict[str, Any], as_json: bool = False) -> str:
    """The text of a mechanism file (YAML, or JSON when ``as_json``) of ``mech`` or its data."""
    data = mechanism_to_dict(mech) if isinstance(mech, Mechanism) else to_jsonable(mech)
    if as_json:
        return json.dumps(data, indent=2, ensure_ascii=False) + "\n"
    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True, default_flow_style=None, width=100)


def write_mechanism(mech: Mechanism | dict[str, Any], path: str | os.PathLike[str]) -> None:
    """Write a mechanism (or file-format data) as YAML, or JSON for a ``.json`` path; atomic."""
    write_atomic(path, mechanism_text(mech, str(path).lower().endswith(".json")))
