"""Target curves from files: CSV of x,y rows, JSON ``{"points": [...], "closed": true}``,
or the first ``<path d="...">`` of an SVG file (M, L, H, V, C, S, Q, T, Z commands,
absolute and relative; arcs are refused with a clear message)."""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mechsyn.errors import MechsynInputError

__all__ = ["TargetCurve", "read_target", "target_from_points", "smooth_samples", "principal_diagonal", "MAX_TARGET_BYTES",
           "MAX_TARGET_POINTS", "SPARSE_POINTS"]

MAX_TARGET_BYTES = 20_000_000    # a target file larger than this is refused (a drawing is far smaller)
MAX_TARGET_POINTS = 200_000      # points of a target (after reading an SVG's curves)
MAX_COORDINATE = 1e12            # |x|, |y| of a target point
SPARSE_POINTS = 24               # fewer points than this: samples of a smooth curve (see smooth_samples)


@dataclass(frozen=True)
class TargetCurve:
    """Points ``(n, 2)`` of a drawn curve; ``closed`` when it is a loop."""

    points: np.ndarray
    closed: bool
    source: str = "<points>"

    @property
    def diagonal(self) -> float:
        """The error unit: the diagonal of the curve's bounding box along its own principal
        axes (see :func:`principal_diagonal`), so a turned drawing keeps its unit."""
        return principal_diagonal(self.points)


def principal_diagonal(points: np.ndarray) -> float:
    """Diagonal of the bounding box of ``points (n, 2)`` taken along the principal axes of
    the polyline (second moments of the points equally spaced along it, closed by its
    chord), so it does not change when the curve is turned; where those moments do not
    fix the axes (a circle, a square: both eigenvalues within 1e-6) the drawing's own axes.

    >>> sq = np.array([[0.0, 0.0], [2, 0], [2, 1], [0, 1]])
    >>> t = np.radians(37.0)
    >>> R = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
    >>> round(principal_diagonal(sq), 3), round(principal_diagonal(sq @ R.T), 3)
    (2.236, 2.236)
    """
    return principal_frame(points)[1]


def principal_frame(points: np.ndarray) -> tuple[np.ndarray, float]:
    """The curve's own centre and size: the centroid ``(2,)`` of the polyline through
    ``points`` closed by its chord (of points equally spaced along it) and its
    :func:`principal_diagonal`; both turn and move with the drawing.

    >>> sq = np.array([[0.0, 0.0], [2, 0], [2, 1], [0, 1]])
    >>> c, d = principal_frame(sq + [5, 0])
    >>> c.round(6).tolist(), round(d, 3)
    ([6.0, 0.5], 2.236)
    """
    from mechsyn.synthesis.curves.descriptors import resample

    P = np.asarray(points, float)
    z = P[:, 0] + 1j * P[:, 1]
    w = resample(z, 256, closed=True)
    centre = w.mean()
    u = w - centre
    m2 = np.sum(u ** 2)
    if abs(m2) > 1e-6 * np.sum(np.abs(u) ** 2):
        z = z * np.exp(-0.5j * np.angle(m2))
    return np.array([centre.real, centre.imag]), float(np.hypot(np.ptp(z.real), np.ptp(z.imag)))


def target_from_points(points, closed: bool | None = None, source: str = "<points>") -> TargetCurve:
    """Check and wrap points; ``closed=None`` decides by the gap between the ends
    (closed when it is under 5 % of the bounding-box diagonal or, for fewer than
    :data:`SPARSE_POINTS` points, at most 1.5 times the median distance between
    neighbours)."""
    try:
        P = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise MechsynInputError("points must be [x, y] pairs of numbers", source=source, field="points") from None
    if P.ndim != 2 or P.shape[1] != 2:
        raise MechsynInputError("points must be [x, y] pairs", source=source, field="points")
    if not np.all(np.isfinite(P)):
        i, k = (int(v) for v in np.argwhere(~np.isfinite(P))[0])
        what = "NaN" if np.isnan(P[i, k]) else "infinite"
        raise MechsynInputError(f"{'xy'[k]} is {what}", source=source, field=f"points[{i}]",
                                hint="give finite numbers for every point")
    if len(P) > MAX_TARGET_POINTS:
        raise MechsynInputError(f"{len(P)} points: at most {MAX_TARGET_POINTS:,} are read", source=source,
                                field="points", hint="resample the curve to fewer points")
    if P.size and np.abs(P).max() > MAX_COORDINATE:
        raise MechsynInputError(f"coordinates beyond {MAX_COORDINATE:g} in magnitude", source=source,
                                field="points", hint="give the curve in a unit where it spans ordinary numbers")
    keep = np.concatenate([[True], np.any(np.abs(np.diff(P, axis=0)) > 0, axis=1)])
    P = P[keep]
    diag = float(np.hypot(*np.ptp(P, axis=0))) if len(P) else 0.0
    gap = float(np.hypot(*(P[-1] - P[0]))) if len(P) else 0.0
    if closed is None:  # a few samples of a loop: the ends are as far apart as neighbours
        steps = np.hypot(*np.diff(P, axis=0).T) if len(P) > 1 else np.zeros(1)
        closed = gap < 0.05 * diag or (len(P) < SPARSE_POINTS and gap <= 1.5 * float(np.median(steps)))
    if closed and len(P) > 1 and gap <= 1e-9 * diag:
        P = P[:-1]
    if len(P) < 3:
        raise MechsynInputError(f"a curve needs at least 3 distinct points, got {len(P)}", source=source,
                                field="points")
    if not diag > 1e-9 * np.abs(P).max():
        raise MechsynInputError("the points (nearly) coincide: the curve has no extent", source=source,
                                field="points")
    return TargetCurve(P, bool(closed), source)


def smooth_samples(target: TargetCurve, m: int = 256) -> TargetCurve:
    """A few points read as samples of a smooth curve, never as a polygon.

    A target of fewer than :data:`SPARSE_POINTS` points is interpolated by a cubic
    spline through them in the centripetal parametrisation (periodic for a closed
    curve, not-a-knot for an open one), which neither overshoots between unevenly spaced
    points nor loops at close ones (E. T. Y. Lee, "Choosing nodes in parametric curve
    interpolation", *Computer-Aided Design* 21(6), 363-370, 1989), and resampled at
    ``m`` points; a denser target is returned as it is.

    >>> t = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    >>> sparse = target_from_points(np.c_[np.cos(t), np.sin(t)], closed=True)
    >>> dense = smooth_samples(sparse)
    >>> len(dense.points), bool(np.allclose(np.hypot(*dense.points.T), 1, atol=2e-3))
    (256, True)
    """
    P = target.points
    if len(P) >= SPARSE_POINTS:
        return target
    from scipy.interpolate import CubicSpline

    Q = np.vstack([P, P[:1]]) if target.closed else P
    u = np.concatenate([[0.0], np.cumsum(np.sqrt(np.linalg.norm(np.diff(Q, axis=0), axis=1)))])
    spline = CubicSpline(u, Q, axis=0, bc_type="periodic" if target.closed else "not-a-knot")
    s = np.linspace(0.0, u[-1], m, endpoint=not target.closed)
    return TargetCurve(spline(s), target.closed, target.source)


def read_target(path: str | os.PathLike[str]) -> TargetCurve:
    """Read a target curve file (CSV, JSON or SVG, by suffix).

    The file is read by :func:`mechsyn.io.files.read_text` (a regular file only, at most
    :data:`MAX_TARGET_BYTES` bytes read); JSON by :func:`mechsyn.io.files.loads_json`
    (a key written twice, deep nesting and non-finite numbers refused).
    """
    from mechsyn.io.checks import flag
    from mechsyn.io.files import check_data_size, loads_json, read_text

    p = Path(path)
    src = str(p)
    suffix = p.suffix.lower()
    if suffix not in (".json", ".svg", ".csv", ".txt"):
        raise MechsynInputError(f"unknown target format {suffix or '(no suffix)'}", source=src,
                                hint="give a .csv (x,y rows), .json ({\"points\": ...}) or .svg (a path)")
    text = read_text(p, "target file", cap=MAX_TARGET_BYTES)
    if suffix == ".json":
        data = check_data_size(loads_json(text, src, finite=True), src)
        if not isinstance(data, dict) or "points" not in data:
            raise MechsynInputError('expected {"points": [[x, y], ...], "closed": true}', source=src,
                                    field="points")
        unknown = sorted(set(data) - {"points", "closed", "name"})
        if unknown:
            raise MechsynInputError(f"unknown key {unknown[0]!r}", source=src, field=unknown[0][:80],
                                    hint='a target holds "points" and, optionally, "closed" and "name"')
        closed = None if data.get("closed") is None else flag(data["closed"], src, "closed")
        return target_from_points(_pairs(data["points"], src), closed, src)
    if suffix == ".svg":
        d = _first_path_data(text)
        if d is None:
            raise MechsynInputError("no <path d=...> in the SVG", source=src, field="path")
        pts, closed = _svg_path(d, src)
        pts[:, 1] *= -1.0  # SVG's y axis points down
        return target_from_points(pts, closed, src)
    if suffix in (".csv", ".txt"):
        rows = []
        for k, line in enumerate(text.splitlines(), 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = [s for s in re.split(r"[,;\s]+", line) if s]
            try:
                rows.append([float(parts[0]), float(parts[1])])
            except (ValueError, IndexError):
                if not rows:  # a header line
                    continue
                raise MechsynInputError(f"expected two numbers x,y, got {line!r}", source=src, line=k) from None
        return target_from_points(rows, None, src)


def _pairs(points: object, src: str) -> list:
    """``points`` of a JSON target checked as a list of ``[x, y]`` number pairs (a boolean
    or a string is not a number), naming the first wrong item."""
    if not isinstance(points, list):
        raise MechsynInputError(f"points must be a list of [x, y] pairs, not {type(points).__name__}",
                                source=src, field="points")
    for k, item in enumerate(points):
        if not (isinstance(item, list) and len(item) == 2
                and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in item)):
            raise MechsynInputError(f"expected [x, y] (two numbers), got {_json_repr(item)}", source=src,
                                    field=f"points[{k}]")
    return points


def _json_repr(value: object) -> str:
    """A short JSON rendering of ``value`` for a message."""
    import json

    text = json.dumps(value, ensure_ascii=True)
    return text if len(text) <= 40 else text[:37] + "..."


_D_ATTR = re.compile(r"\sd\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")


def _first_path_data(text: str) -> str | None:
    """The ``d`` attribute of the first ``<path>`` element that has one, in one linear
    pass (each tag is scanned once from ``<path`` to its ``>``)."""
    pos = 0
    while True:
        i = text.find("<path", pos)
        if i < 0:
            return None
        j = text.find(">", i)
        if j < 0:
            return None
        m = _D_ATTR.search(text, i + 5, j)
        if m:
            return m.group(1) if m.group(1) is not None else m.group(2)
        pos = j


_TOKEN = re.compile(r"([MmLlHhVvCcSsQqTtZzAa])|([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def _svg_path(d: str, src: str, per_segment: int = 24) -> tuple[np.ndarray, bool]:
    toks = [(a, b) for a, b in _TOKEN.findall(d)]
    pts: list[complex] = []
    cur = start = 0j
    cmd = None
    last_ctrl = None
    closed = False
    i = 0
    t = np.linspace(0, 1, per_segment + 1)[1:]

    def nums(k: int) -> list[float]:
        nonlocal i
        out = []
        for _ in range(k):
            if i >= len(toks) or toks[i][1] == "":
                raise MechsynInputError("malformed SVG path data", source=src, field="d")
            out.append(float(toks[i][1]))
            i += 1
        return out

    while i < len(toks):
        if len(pts) > MAX_TARGET_POINTS:
            raise MechsynInputError(f"the SVG path gives more than {MAX_TARGET_POINTS:,} points", source=src,
                                    field="d", hint="simplify the path")
        if toks[i][0]:
            cmd = toks[i][0]
            i += 1
            if cmd in "Zz":
                closed = True
                cur = start
                continue
        if cmd is None:
            raise MechsynInputError("SVG path data must start with M", source=src, field="d")
        rel = cmd.islower()
        c = cmd.upper()
        base = cur if rel else 0j
        if c == "A":
            raise MechsynInputError("SVG arcs (A) are not supported", source=src, field="d",
                                    hint="convert arcs to curves (e.g. Inkscape: Path > Object to Path)")
        if c in "ML":
            x, y = nums(2)
            cur = base + complex(x, y)
            if c == "M":
                if pts:
                    raise MechsynInputError("the SVG path has several sub-paths", source=src, field="d",
                                            hint="draw the target as one stroke")
                start = cur
                cmd = "l" if rel else "L"
            pts.append(cur)
            last_ctrl = None
        elif c == "H":
            (x,) = nums(1)
            cur = complex((cur.real if rel else 0) + x, cur.imag)
            pts.append(cur)
            last_ctrl = None
        elif c == "V":
            (y,) = nums(1)
            cur = complex(cur.real, (cur.imag if rel else 0) + y)
            pts.append(cur)
            last_ctrl = None
        elif c in "CS":
            if c == "C":
                x1, y1, x2, y2, x, y = nums(6)
                p1 = base + complex(x1, y1)
            else:
                x2, y2, x, y = nums(4)
                p1 = 2 * cur - last_ctrl if last_ctrl is not None else cur
            p2, p3 = base + complex(x2, y2), base + complex(x, y)
            seg = ((1 - t) ** 3 * cur + 3 * (1 - t) ** 2 * t * p1 + 3 * (1 - t) * t ** 2 * p2 + t ** 3 * p3)
            pts.extend(seg.tolist())
            cur, last_ctrl = p3, p2
        elif c in "QT":
            if c == "Q":
                x1, y1, x, y = nums(4)
                p1 = base + complex(x1, y1)
            else:
                x, y = nums(2)
                p1 = 2 * cur - last_ctrl if last_ctrl is not None else cur
            p2 = base + complex(x, y)
            seg = (1 - t) ** 2 * cur + 2 * (1 - t) * t * p1 + t ** 2 * p2
            pts.extend(seg.tolist())
            cur, last_ctrl = p2, p1
    if len(pts) < 2:
        raise MechsynInputError("the SVG path has fewer than two points", source=src, field="d")
    z = np.array(pts)
    return np.stack([z.real, z.imag], axis=1), closed
