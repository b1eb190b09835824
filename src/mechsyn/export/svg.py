"""Vector drawings written as SVG text: plates to cut and the mechanism at a pose with paths.

SVG is written directly (not through Matplotlib's SVG backend) so that one drawing unit is
one unit of the mechanism file, every plate outline is one closed ``<path>`` with true
arcs, every hole one ``<circle>``: what a laser cutter's software imports as cut lines,
and what a report scales without loss. Matplotlib's backend would write glyphs as paths,
clip boxes and axes in points, which cutters and editors then have to clean.

Colours: links take Matplotlib's ``tab10`` colours in the order of the file's links,
as the figures of :mod:`mechsyn.plot` do, so a link has one colour everywhere.
"""

from __future__ import annotations

import math
from html import escape
from typing import Any

import numpy as np

from mechsyn.export.plates import PlateLayout, plate_outline

__all__ = ["plates_svg", "mechanism_svg", "LINK_COLOURS"]

#: Matplotlib's tab10 palette (the colours of the links in every mechsyn figure).
LINK_COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"]


def _f(v: float) -> str:
    return f"{v:.6f}".rstrip("0").rstrip(".") if abs(v) > 1e-12 else "0"


def _svg(x0: float, y0: float, w: float, h: float, body: list[str], units: str | None,
         display_width: float | None = None) -> str:
    """An SVG document: sized in ``units`` (mm, cm, in; metres written as millimetres, SVG
    having no metre; mm when the file names none) or ``display_width`` pixels."""
    if display_width is not None:
        size = f'width="{_f(display_width)}" height="{_f(display_width * h / w)}"'
    else:
        unit, k = {"m": ("mm", 1000.0), "cm": ("cm", 1.0), "in": ("in", 1.0)}.get(units or "", ("mm", 1.0))
        size = f'width="{_f(w * k)}{unit}" height="{_f(h * k)}{unit}"'
    return "\n".join([
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" {size} '
        f'viewBox="{_f(x0)} {_f(y0)} {_f(w)} {_f(h)}">',
        *body, "</svg>", ""])


def _outline_path(outline: list[tuple[float, float, float]]) -> str:
    """SVG path data of a closed bulged polyline (y flipped: SVG's y points down)."""
    pts = [(x, -y, b) for x, y, b in outline]
    d = [f"M {_f(pts[0][0])} {_f(pts[0][1])}"]
    for k, (x, y, b) in enumerate(pts):
        nx, ny, _ = pts[(k + 1) % len(pts)]
        if abs(b) < 1e-15:
            d.append(f"L {_f(nx)} {_f(ny)}")
            continue
        theta = 4 * math.atan(b)
        chord = math.hypot(nx - x, ny - y)
        r = chord / (2 * abs(math.sin(theta / 2)))
        large = 1 if abs(theta) > math.pi else 0
        # the y flip mirrors the drawing: an arc counter-clockwise in y-up (bulge > 0) runs
        # the negative-angle way in SVG's y-down frame, sweep-flag 0
        sweep = 0 if b > 0 else 1
        d.append(f"A {_f(r)} {_f(r)} 0 {large} {sweep} {_f(nx)} {_f(ny)}")
    d.append("Z")
    return " ".join(d)


def plates_svg(layout: PlateLayout, labels: bool = True) -> str:
    """The plates of :func:`mechsyn.export.plates.link_plates` as SVG (cut lines in black,
    holes and a slider guide's slots in red, point marks in green, labels in blue for engraving or hiding), sized in
    the file's ``units`` (mm when it names none) so a cutter imports it at scale.

    Examples
    --------
    >>> from mechsyn.io import mechanism_from_dict
    >>> from mechsyn.export.plates import link_plates
    >>> m = mechanism_from_dict({"name": "crank", "ground": "f", "links": ["f", "a"], "joints": [
    ...     {"id": "A", "type": "R", "links": ["f", "a"], "point": [0, 0]}],
    ...     "points": {"T": {"link": "a", "at": [40, 0]}}})
    >>> plates_svg(link_plates(m, width=10, frame=False)).count("<circle")
    2
    """
    w = layout.width
    x0, y0 = -w, -w
    width, height = layout.sheet[0] + 2 * w, layout.sheet[1] + 2 * w
    stroke = _f(max(w / 40, 1e-6))
    body = [f'<g fill="none" stroke-width="{stroke}">']
    for p in layout.plates:
        body.append(f'<g id="{escape(p.link)}">')
        body.append(f'<path stroke="#000" d="{_outline_path(p.outline)}"/>')
        for c in p.holes:
            body.append(f'<circle stroke="#d00" cx="{_f(c[0])}" cy="{_f(-c[1])}" r="{_f(layout.cut_diameter / 2)}"/>')
        for a, b in p.slots:  # a slider's guide: a slot as wide as a hole, cut like one
            body.append(f'<path stroke="#d00" d="{_outline_path(plate_outline(np.array([a, b]), layout.cut_diameter / 2))}"/>')
        for c in p.markers:
            body.append(f'<circle stroke="#080" cx="{_f(c[0])}" cy="{_f(-c[1])}" r="{_f(layout.cut_diameter / 6)}"/>')
        if labels:
            body.append(f'<text x="{_f(p.label_at[0])}" y="{_f(-p.label_at[1])}" fill="#00c" stroke="none" '
                        f'font-family="sans-serif" font-size="{_f(0.4 * w)}">{escape(p.label)}</text>')
        body.append("</g>")
    body.append("</g>")
    return _svg(x0, y0, width, height, body, layout.units)


def mechanism_svg(sim: Any, k: int = 0, paths: list[str] | None = None, dimensions: bool = False,
                  title: str | None = None) -> str:
    """The mechanism of a simulation at step ``k`` as an SVG drawing.

    Moving links are bars (two joints) or plates (three or more) in their colours, pins
    white circles, the frame's pivots triangles on hatched ground, named points dots with
    their names; ``paths`` (point names or joint ids reported by the simulation) are drawn
    over the whole sweep; ``dimensions`` writes each bar's length along it.
    """
    from mechsyn.plot.kinematics import link_outlines

    mech = sim.system.mech
    outl = link_outlines(sim, k)
    tracks = {p: sim.points[p].position[sim.assembled] for p in (paths or [])}
    pts = np.vstack([*outl.values(), *tracks.values()]) if tracks else np.vstack(list(outl.values()))
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    span = float(max(hi - lo)) or 1.0
    m = 0.12 * span
    lw = 0.012 * span
    x0, y1 = lo[0] - m, hi[1] + m
    w, h = hi[0] - lo[0] + 2 * m, hi[1] - lo[1] + 2 * m

    def P(p: np.ndarray) -> tuple[str, str]:
        return _f(p[0]), _f(-p[1])

    body = ['<g stroke-linecap="round" stroke-linejoin="round">']
    if title:
        body.append(f'<text x="{_f(x0 + m / 3)}" y="{_f(-y1 + m / 2)}" font-family="sans-serif" '
                    f'font-size="{_f(0.35 * m)}">{escape(title)}</text>')
    colour = {name: LINK_COLOURS[i % 10] for i, name in enumerate(mech.link_names)}
    for name, track in tracks.items():
        link = sim.points[name].link or ""
        d = " ".join(f"{_f(x)},{_f(-y)}" for x, y in track)
        body.append(f'<polyline fill="none" stroke="{colour.get(link, "#444")}" stroke-width="{_f(lw / 3)}" '
                    f'stroke-dasharray="{_f(lw)} {_f(lw / 1.5)}" points="{d}"/>')
    # ground pivots: triangle and hatched base
    for j in mech.joints:
        if mech.ground not in j.links or j.type != "R":
            continue
        c = sim_point_of(sim, j, k)
        s = 2.2 * lw
        tri = [c, c + [-s, -1.6 * s], c + [s, -1.6 * s]]
        body.append(f'<polygon fill="#ddd" stroke="#333" stroke-width="{_f(lw / 4)}" points="'
                    + " ".join(",".join(P(q)) for q in tri) + '"/>')
        base = c[1] - 1.6 * s
        body.append(f'<line stroke="#333" stroke-width="{_f(lw / 3)}" x1="{_f(c[0] - 1.6 * s)}" y1="{_f(-base)}" '
                    f'x2="{_f(c[0] + 1.6 * s)}" y2="{_f(-base)}"/>')
        for t in np.linspace(-1.4, 1.4, 6):
            body.append(f'<line stroke="#333" stroke-width="{_f(lw / 5)}" x1="{_f(c[0] + t * s)}" '
                        f'y1="{_f(-base)}" x2="{_f(c[0] + t * s - 0.5 * s)}" y2="{_f(-(base - 0.6 * s))}"/>')
    for name, pts_l in outl.items():
        if name == mech.ground or len(pts_l) == 0:
            continue
        col = colour[name]
        if len(pts_l) >= 3:
            centre = pts_l.mean(axis=0)
            order = np.argsort(np.arctan2(pts_l[:, 1] - centre[1], pts_l[:, 0] - centre[0]))
            body.append(f'<polygon fill="{col}" fill-opacity="0.25" stroke="{col}" stroke-width="{_f(lw)}" '
                        'points="' + " ".join(",".join(P(q)) for q in pts_l[order]) + '"/>')
        elif len(pts_l) == 2:
            a, b = pts_l
            body.append(f'<line stroke="{col}" stroke-width="{_f(lw)}" x1="{P(a)[0]}" y1="{P(a)[1]}" '
                        f'x2="{P(b)[0]}" y2="{P(b)[1]}"/>')
            if dimensions:
                mid, d = (a + b) / 2, b - a
                ang = -math.degrees(math.atan2(d[1], d[0]))
                if ang > 90 or ang < -90:
                    ang += 180
                body.append(f'<text x="{_f(mid[0])}" y="{_f(-mid[1] - 1.5 * lw)}" text-anchor="middle" '
                            f'font-family="sans-serif" font-size="{_f(3 * lw)}" '
                            f'transform="rotate({_f(ang)} {_f(mid[0])} {_f(-mid[1])})">'
                            f'{np.linalg.norm(d):.4g}</text>')
    for j in mech.joints:
        if j.type in ("R", "P"):
            c = sim_point_of(sim, j, k)
            if j.type == "R":
                body.append(f'<circle fill="#fff" stroke="#222" stroke-width="{_f(lw / 3)}" cx="{P(c)[0]}" '
                            f'cy="{P(c)[1]}" r="{_f(0.9 * lw)}"/>')
            else:
                s = 1.4 * lw
                body.append(f'<rect fill="#fff" stroke="#222" stroke-width="{_f(lw / 3)}" x="{_f(c[0] - s)}" '
                            f'y="{_f(-c[1] - s)}" width="{_f(2 * s)}" height="{_f(2 * s)}"/>')
    for name, p in mech.points.items():
        c = sim_point_of_named(sim, name, k)
        body.append(f'<circle fill="{colour[p.link]}" cx="{P(c)[0]}" cy="{P(c)[1]}" r="{_f(0.6 * lw)}"/>')
        body.append(f'<text x="{_f(c[0] + 1.2 * lw)}" y="{_f(-c[1] - 1.2 * lw)}" font-family="sans-serif" '
                    f'font-size="{_f(3 * lw)}">{escape(name)}</text>')
    body.append("</g>")
    return _svg(x0, -y1, w, h, body, mech.attrs.get("unit"), display_width=800)


def _global(sim: Any, link: str, at: np.ndarray, k: int) -> np.ndarray:
    S = sim.system
    q = sim.sweep.q[k:k + 1]
    return S.point(q, S.index(link), S.to_local(link, np.asarray(at, float)))[0]


def sim_point_of(sim: Any, joint: Any, k: int) -> np.ndarray:
    """A joint's point at step ``k`` (carried by its second link)."""
    return _global(sim, joint.links[1], joint.point, k)


def sim_point_of_named(sim: Any, name: str, k: int) -> np.ndarray:
    """A named point's position at step ``k``."""
    p = sim.system.mech.points[name]
    return _global(sim, p.link, p.at, k)
