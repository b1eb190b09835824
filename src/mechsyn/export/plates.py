"""Links as flat plates to cut: outlines round the joint holes, laid out on a sheet.

Each link of a planar mechanism becomes a plate: the convex hull of its holes grown
by half the link width (straight sides tangent to the hole bosses, arcs round them),
with a hole of diameter ``hole_diameter + clearance`` at every revolute joint and a
marker hole at every named point. The holes are placed by a rigid motion of the
assembled configuration, so the distance between two hole centres is the distance
between the joints in the file: the link length.

Pure geometry (NumPy, SciPy): :mod:`mechsyn.export.dxf` writes the result as DXF.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from mechsyn.errors import MechsynInputError
from mechsyn.model.mechanism import Mechanism

__all__ = ["Plate", "PlateLayout", "link_plates", "plate_outline"]


@dataclass
class Plate:
    """One link's plate on the sheet.

    ``outline`` is a closed polyline of ``(x, y, bulge)`` vertices (DXF LWPOLYLINE
    convention: the bulge ``tan(angle / 4)`` of the arc to the next vertex, 0 for a
    straight side); ``holes`` are the hole centres, named ``hole_names`` (joint ids,
    then named points in ``markers``). A slider's guide has ``slots`` (the end centres of
    slots as wide as a cut hole), its block a rectangular outline along ``block_axis``
    (:mod:`mechsyn.export.sliders`).
    """

    link: str
    holes: np.ndarray
    hole_names: list[str]
    markers: np.ndarray
    marker_names: list[str]
    outline: list[tuple[float, float, float]]
    label: str
    label_at: tuple[float, float]
    size: tuple[float, float]
    slots: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    block_axis: np.ndarray | None = None

    def hole_distance(self, a: str, b: str) -> float:
        """Distance between the centres of holes ``a`` and ``b``."""
        i, k = self.hole_names.index(a), self.hole_names.index(b)
        return float(np.linalg.norm(self.holes[i] - self.holes[k]))

    def to_dict(self) -> dict[str, Any]:
        return {"link": self.link, "holes": dict(zip(self.hole_names, self.holes.tolist())),
                "markers": dict(zip(self.marker_names, self.markers.tolist())),
                "slots": [[a.tolist(), b.tolist()] for a, b in self.slots],
                "size": list(self.size), "label": self.label}


@dataclass
class PlateLayout:
    """The plates of a mechanism laid out on a sheet, with the sizes used."""

    mechanism: str
    plates: list[Plate]
    width: float
    hole_diameter: float
    clearance: float
    sheet: tuple[float, float]
    units: str | None = None
    notes: list[str] = field(default_factory=list)

    @property
    def cut_diameter(self) -> float:
        """Diameter of the cut holes: the pin diameter plus the clearance."""
        return self.hole_diameter + self.clearance

    def to_dict(self) -> dict[str, Any]:
        return {"mechanism": self.mechanism, "width": self.width, "hole_diameter": self.hole_diameter,
                "clearance": self.clearance, "cut_diameter": self.cut_diameter, "sheet": list(self.sheet),
                "units": self.units, "plates": [p.to_dict() for p in self.plates], "notes": self.notes}


def _hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise hull vertices (two extreme points for collinear input, one for
    coincident points: a named point at a hole's centre adds no vertex)."""
    scale = max(1.0, float(np.abs(points).max())) if len(points) else 1.0
    points = points[_distinct(points, 1e-12 * scale)]
    if len(points) >= 3:
        try:
            return points[ConvexHull(points).vertices]
        except QhullError:
            pass
    if len(points) == 1:
        return points
    centred = points - points.mean(axis=0)
    direction = np.linalg.svd(centred)[2][0]
    s = centred @ direction
    return points[[int(np.argmin(s)), int(np.argmax(s))]]


def _distinct(points: np.ndarray, tol: float) -> list[int]:
    """Indices of the first of each group of points closer than ``tol``."""
    keep: list[int] = []
    for i, p in enumerate(points):
        if all(np.linalg.norm(p - points[k]) > tol for k in keep):
            keep.append(i)
    return keep


def plate_outline(points: np.ndarray, radius: float) -> list[tuple[float, float, float]]:
    """The outline of the convex hull of ``points`` grown by ``radius``, as bulged vertices.

    Examples
    --------
    >>> out = plate_outline(np.array([[0.0, 0.0], [10.0, 0.0]]), 2.0)
    >>> [(round(x, 9), round(y, 9), round(b, 9)) for x, y, b in out]
    [(0.0, -2.0, 0.0), (10.0, -2.0, 1.0), (10.0, 2.0, 0.0), (0.0, 2.0, 1.0)]
    """
    v = _hull(np.asarray(points, float))
    if len(v) == 1:
        x, y = v[0]
        return [(x - radius, y, 1.0), (x + radius, y, 1.0)]
    m = len(v)
    normals = []
    for i in range(m):
        d = v[(i + 1) % m] - v[i]
        d = d / np.linalg.norm(d)
        normals.append(np.array([d[1], -d[0]]))  # outward for a counter-clockwise hull
    out: list[tuple[float, float, float]] = []
    for i in range(m):
        n0, n1 = normals[i], normals[(i + 1) % m]
        turn = math.atan2(n0[0] * n1[1] - n0[1] * n1[0], float(n0 @ n1)) % (2 * math.pi)
        if m == 2:
            turn = math.pi
        s = v[i] + radius * n0
        e = v[(i + 1) % m] + radius * n0
        out.append((float(s[0]), float(s[1]), 0.0))
        out.append((float(e[0]), float(e[1]), math.tan(turn / 4)))
    return out


def _rotation_to_x(points: np.ndarray) -> np.ndarray:
    """The rotation turning the longest chord of ``points`` onto the x axis."""
    if len(points) < 2:
        return np.eye(2)
    d = points[:, None, :] - points[None, :, :]
    i, k = np.unravel_index(np.argmax(np.einsum("ijk,ijk->ij", d, d)), d.shape[:2])
    a = -math.atan2(*(points[k] - points[i])[::-1])
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s], [s, c]])


def link_plates(mech: Mechanism, width: float | None = None, hole_diameter: float | None = None,
                clearance: float = 0.0, frame: bool = True, sheet_width: float | None = None,
                gap: float | None = None) -> PlateLayout:
    """Plates of every link of a planar mechanism, laid out in rows on a sheet.

    Parameters
    ----------
    mech:
        A planar mechanism with joint points; revolute joints become holes.
    width:
        Plate width (twice the material round a hole centre); default: a fifth of the
        shortest distance between two holes of one link.
    hole_diameter:
        Pin diameter; default: 40 % of the width.
    clearance:
        Added to the pin diameter to give the cut hole diameter (a running fit).
    frame:
        Include the frame's plate (the base with the ground pivots).
    sheet_width:
        Width of the sheet the rows of plates fill; default: the longest plate, or
        three times the mean plate length if more.
    gap:
        Space between plates; default: the width.

    Returns
    -------
    PlateLayout

    Raises
    ------
    MechsynInputError
        a spatial mechanism or one without points; holes that overlap or leave less
        than a tenth of the width of material round them.

    Examples
    --------
    >>> from mechsyn.io import mechanism_from_dict
    >>> m = mechanism_from_dict({"name": "4R", "ground": "f", "links": ["f", "a", "b", "c"], "joints": [
    ...     {"id": "A", "type": "R", "links": ["f", "a"], "point": [0, 0]},
    ...     {"id": "B", "type": "R", "links": ["a", "b"], "point": [30, 40]},
    ...     {"id": "C", "type": "R", "links": ["b", "c"], "point": [100, 40]},
    ...     {"id": "D", "type": "R", "links": ["c", "f"], "point": [90, 0]}]})
    >>> lay = link_plates(m, width=12, hole_diameter=5, clearance=0.2)
    >>> round(lay.plates[1].hole_distance("A", "B"), 9), lay.cut_diameter
    (50.0, 5.2)
    """
    if mech.kind != "planar":
        raise MechsynInputError("plates are cut for planar mechanisms; this one is spatial", field="kind")
    if not mech.has_geometry:
        raise MechsynInputError("the joints have no points to place the holes", field="joints[].point",
                                hint="give every joint its point [x, y]")
    holes_of, markers_of, notes = _holes_and_markers(mech)
    links = [n for n in mech.link_names if frame or n != mech.ground]
    width, hole_diameter = _plate_sizes([holes_of[n] for n in links], width, hole_diameter, clearance)
    cut = hole_diameter + clearance
    slots_of, axis_of = _sliders(mech, holes_of, notes)
    plates: list[Plate] = []
    for n in links:
        if not holes_of[n] and not markers_of[n]:
            notes.append(f"link {n} has no pin or point: no plate")
            continue
        plates.append(_plate(n, holes_of[n], markers_of[n], cut, width, slots_of.get(n, []), axis_of.get(n)))
    sheet = _shelf_layout(plates, mech, width, width if gap is None else gap, sheet_width)
    return PlateLayout(mech.name, plates, float(width), float(hole_diameter), float(clearance),
                       sheet, mech.attrs.get("unit"), notes)


_Marks = list[tuple[str, np.ndarray]]


def _holes_and_markers(mech: Mechanism) -> tuple[dict[str, _Marks], dict[str, _Marks], list[str]]:
    """Per link: its pins (R joints) and its named points, and notes on joints that are no pin."""
    notes: list[str] = []
    holes_of: dict[str, _Marks] = {name: [] for name in mech.link_names}
    for j in mech.joints:
        if j.type == "R":
            for link in j.links:
                holes_of[link].append((j.id, np.asarray(j.point, float)))
        else:
            notes.append(f"joint {j.id} ({j.type}) is not a pin: no hole cut for it")
    markers_of: dict[str, _Marks] = {name: [] for name in mech.link_names}
    for name, p in mech.points.items():
        markers_of[p.link].append((name, np.asarray(p.at, float)))
    return holes_of, markers_of, notes


def _sliders(mech: Mechanism, holes_of: dict[str, _Marks], notes: list[str]
             ) -> tuple[dict[str, list[tuple[np.ndarray, np.ndarray]]], dict[str, np.ndarray]]:
    """Each P joint's parts (:func:`~mechsyn.export.sliders.slider_parts`): a pin hole on
    the block at the slide point, a slot in the guide over the stroke; per link its slots
    and, for a block, its slide axis (the notes of "not a pin" replaced by what is cut)."""
    from mechsyn.export.sliders import slider_parts

    slots: dict[str, list[tuple[np.ndarray, np.ndarray]]] = {}
    axes: dict[str, np.ndarray] = {}
    for part in slider_parts(mech) if any(j.type == "P" for j in mech.joints) else []:
        notes[:] = [n for n in notes if not n.startswith(f"joint {part.joint} (P)")]
        if part.slot is None:
            notes.append(part.note)
            continue
        holes_of[part.block].append((part.joint, part.point))
        slots.setdefault(part.guide, []).append(part.slot)
        axes.setdefault(part.block, part.axis)
        notes.append(f"joint {part.joint} (P): {part.block} rides on a pin at {part.joint} in a slot of "
                     f"{part.guide}, stroke {part.stroke[1] - part.stroke[0]:.6g}")
    return slots, axes


def _plate_sizes(holes: list[_Marks], width: float | None, hole_diameter: float | None,
                 clearance: float) -> tuple[float, float]:
    """Width (default: a fifth of the shortest distance between two holes of one link) and
    pin diameter (default: 40 % of the width); refused when the holes leave too little material."""
    spans = []
    for hp in holes:
        pts = np.array([p for _, p in hp]) if hp else np.zeros((0, 2))
        if len(pts) >= 2:
            d = np.linalg.norm(pts[:, None] - pts[None], axis=2)
            spans.append(d[np.triu_indices(len(pts), 1)].min())
    if width is None:
        positive = [s for s in spans if s > 0]
        if not positive:
            raise MechsynInputError("no link has two holes to size the plates from", field="width",
                                    hint="give the plate width")
        width = min(positive) / 5
    if hole_diameter is None:
        hole_diameter = 0.4 * width
    if width <= 0 or hole_diameter <= 0 or clearance < 0:
        raise MechsynInputError("width and hole diameter must be positive, clearance not negative",
                                field="width/hole_diameter/clearance")
    cut = hole_diameter + clearance
    if cut >= 0.9 * width:
        raise MechsynInputError(
            f"holes of {cut:g} leave less than a tenth of the width {width:g} of material", field="hole_diameter",
            hint=f"make the width more than {cut / 0.9:.4g} or the hole smaller")
    return width, hole_diameter


def _plate(n: str, hp: _Marks, mk: _Marks, cut: float, width: float,
           slots: list[tuple[np.ndarray, np.ndarray]] = (), axis: np.ndarray | None = None) -> Plate:
    """Link ``n``'s plate in its own frame (centred, longest direction along x): one hole
    per pin point, refused when two holes are too close for holes of diameter ``cut``;
    its ``slots`` (end centres) and a block's slide ``axis`` carried into the same frame."""
    scale = max(1.0, float(np.abs(np.array([q for _, q in hp + mk])).max()))
    groups: list[tuple[list[str], np.ndarray]] = []
    for jid, q in hp:  # several joints at one point of this link (a shared pin): one hole
        for g in groups:
            if np.linalg.norm(g[1] - q) <= 1e-9 * scale:
                g[0].append(jid)
                break
        else:
            groups.append(([jid], q))
    names = ["+".join(g[0]) for g in groups]
    holes = np.array([g[1] for g in groups]).reshape(-1, 2)
    if len(holes) >= 2:
        d = np.linalg.norm(holes[:, None] - holes[None], axis=2) + np.diag(np.full(len(holes), np.inf))
        i, k = np.unravel_index(np.argmin(d), d.shape)
        if d[i, k] < cut + 0.1 * width:
            raise MechsynInputError(
                f"link {n}: holes {names[i]} and {names[k]} are {d[i, k]:.6g} apart, too close for "
                f"holes of {cut:g} in a plate {width:g} wide", field="hole_diameter",
                hint="use smaller holes or a narrower plate")
    pts = np.vstack([holes, np.array([q for _, q in mk]).reshape(-1, 2)])
    R = _rotation_to_x(pts) if axis is None else _rotation_to_x(np.array([[0.0, 0.0], axis]))  # a block: along x
    mean = pts.mean(axis=0)
    local = (pts - mean) @ R.T
    return Plate(n, local[:len(holes)], names, local[len(holes):], [m for m, _ in mk], [], "", (0, 0), (0.0, 0.0),
                 [((a - mean) @ R.T, (b - mean) @ R.T) for a, b in slots], None if axis is None else R @ axis)


def _shelf_layout(plates: list[Plate], mech: Mechanism, width: float, gap: float,
                  sheet_width: float | None) -> tuple[float, float]:
    """Place the plates in rows, left to right (moves them, sets outline, size and label);
    returns the sheet's size."""
    r = width / 2
    sizes = []
    for p in plates:
        p.outline = _outline(p, r)
        corners = np.array([(x, y) for x, y, _ in p.outline])
        lo = np.minimum(corners.min(axis=0), np.vstack([p.holes, p.markers]).min(axis=0) - r)
        hi = np.maximum(corners.max(axis=0), np.vstack([p.holes, p.markers]).max(axis=0) + r)
        sizes.append((lo, hi))
    lengths = [hi[0] - lo[0] for lo, hi in sizes]
    if sheet_width is None:
        sheet_width = max(max(lengths, default=0.0), 3 * float(np.mean(lengths)) if lengths else 0.0)
    label_h = 0.5 * width
    x = y = 0.0
    row_h = 0.0
    sheet_w = 0.0
    for p, (lo, hi) in zip(plates, sizes):
        w, h = hi - lo
        if x > 0 and x + w > sheet_width + 1e-9:
            x, y = 0.0, y - row_h - gap - 1.5 * label_h
            row_h = 0.0
        shift = np.array([x, y]) - np.array([lo[0], hi[1]])
        p.holes = p.holes + shift
        p.markers = p.markers + shift
        p.slots = [(a + shift, b + shift) for a, b in p.slots]
        p.outline = [(float(x + shift[0]), float(y + shift[1]), bulge) for x, y, bulge in p.outline]
        p.size = (float(w), float(h))
        p.label = _label(p, mech)
        p.label_at = (x, y - h - 0.3 * width - label_h)
        x += w + gap
        row_h = max(row_h, h)
        sheet_w = max(sheet_w, x - gap)
    sheet_h = -(y - row_h - 1.5 * label_h) if plates else 0.0
    return float(sheet_w), float(sheet_h)


def _outline(p: Plate, r: float) -> list[tuple[float, float, float]]:
    """A plate's outline: the grown hull of its holes, marks and slot ends; for a slider's
    block a rectangle along its slide axis round its pins, at least two widths long."""
    pts = np.vstack([p.holes, p.markers, *[np.array(s) for s in p.slots]])
    if p.block_axis is None:
        return plate_outline(pts, r)
    u = p.block_axis / np.linalg.norm(p.block_axis)
    nrm = np.array([-u[1], u[0]])
    along, across = pts @ u, pts @ nrm
    mid = (along.min() + along.max()) / 2
    half = max((along.max() - along.min()) / 2 + r, 2 * r)
    n0, n1 = across.min() - r, across.max() + r
    corners = [(mid - half, n0), (mid + half, n0), (mid + half, n1), (mid - half, n1)]  # counter-clockwise
    return [(float(a * u[0] + c * nrm[0]), float(a * u[1] + c * nrm[1]), 0.0) for a, c in corners]


def _label(p: Plate, mech: Mechanism) -> str:
    parts = [p.link]
    if len(p.hole_names) == 2:
        parts.append(f"{p.hole_distance(*p.hole_names):.6g}")
    return " ".join(parts)
