"""The kinematics summary: what a designer reads off a sweep of the main input.

* every slider (P pair): its slide along the guide (the block's joint point measured along
  the guide's direction from the guide link's origin, the world origin for the frame), its
  stroke (largest minus smallest slide) and its extreme positions: the input values where the
  slide stops and turns back (its rate crosses zero between two rows: located on the cubic
  through the two rows' slides and rates, to O(h^4) in the step h), or the ends of a working
  range;
* every link pivoted on the frame and not driven: its angle range (a rocker's swing, with its
  extreme positions found as a slider's) or a full turn;
* the time ratio of an oscillating output (a crank-rocker's rocker, a slider-crank's slider)
  when the driving crank turns fully at a constant speed: the crank angle of the working
  stroke (from the smallest to the largest output) and of the return, ``Q = larger / smaller``
  (Uicker, Pennock, Shigley, *Theory of Machines and Mechanisms*, 5th ed., sec. 1.10; a
  centred slider-crank has ``Q = 1``).

:func:`motion_summary` is part of :func:`mechsyn.kinematics.report.derived_quantities`
(``mechsyn simulate``) and of the studio's simulation answer (its Analysis tab).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mechsyn.kinematics.derived import slide
from mechsyn.kinematics.simulation import is_full_turn
from mechsyn.model.mechanism import Mechanism

__all__ = ["motion_summary", "is_full_turn"]


def _hermite_stop(fa: float, fb: float, da: float, db: float, h: float) -> tuple[float, float]:
    """Where the cubic through (0, fa), (h, fb) with slopes da, db stops (its slope is zero),
    as (t in 0..1, value): the extreme between two rows, to O(h^4)."""
    # the cubic Hermite interpolant's slope, a quadratic in t: A t^2 + B t + C = 0
    A = 6 * fa + 3 * h * da - 6 * fb + 3 * h * db
    B = -6 * fa - 4 * h * da + 6 * fb - 2 * h * db
    C = h * da
    roots = [-C / B] if abs(A) < 1e-14 * (abs(B) + abs(C)) and B else []
    if not roots and A:
        disc = B * B - 4 * A * C
        if disc >= 0:
            roots = [(-B + sgn * np.sqrt(disc)) / (2 * A) for sgn in (1.0, -1.0)]
    inside = [r for r in roots if 0.0 <= r <= 1.0]
    t = min(inside, key=lambda r: abs(r - da / (da - db))) if inside else da / (da - db)  # else: linear
    h00, h10, h01, h11 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t, -2 * t**3 + 3 * t**2, t**3 - t**2
    return float(t), float(h00 * fa + h10 * h * da + h01 * fb + h11 * h * db)


def _extremes(x: np.ndarray, f: np.ndarray, dfdx: np.ndarray, ok: np.ndarray, cyclic: bool) -> list[dict[str, Any]]:
    """Stationary points of ``f(x)`` between assembled rows (``dfdx`` changes sign) and the ends
    of the assembled runs (when not cyclic): ``{"input", "value", "row", "turns"}``."""
    n = len(x)
    out = []
    closed = cyclic and abs(x[-1] - x[0]) >= 360.0 * (1 - 1e-9)  # the last row repeats the first
    pairs = [(k, k + 1) for k in range(n - 1)] + ([(n - 1, 0)] if cyclic and not closed else [])
    period = 360.0 if cyclic else 0.0
    for a, b in pairs:
        if not (ok[a] and ok[b]) or not (np.isfinite(dfdx[a]) and np.isfinite(dfdx[b])):
            continue
        da, db = dfdx[a], dfdx[b]
        if da == 0 or da * db < 0:
            xb = x[b] + (period if b < a else 0.0)
            t, value = (0.0, f[a]) if da == 0 else _hermite_stop(f[a], f[b], da, db, xb - x[a])
            xs = x[a] + t * (xb - x[a])
            if cyclic:  # within the sweep's turn
                xs = x[0] + (xs - x[0]) % period
            out.append({"input": float(xs), "value": float(value), "row": int(a if t <= 0.5 else b), "turns": True})
    if not cyclic:
        for k in range(n):
            end = ok[k] and (k == 0 or k == n - 1 or not ok[k - 1] or not ok[k + 1])
            if end and np.isfinite(f[k]):
                out.append({"input": float(x[k]), "value": float(f[k]), "row": k, "turns": False})
    return out


def _range_of(x, f, dfdx, ok, cyclic) -> dict[str, Any] | None:
    """Smallest and largest of ``f`` over the sweep, each with the input where it is reached."""
    cands = _extremes(x, f, dfdx, ok, cyclic)
    if not cands:
        good = np.flatnonzero(ok & np.isfinite(f))
        if not len(good):
            return None
        cands = [{"input": float(x[k]), "value": float(f[k]), "row": int(k), "turns": False} for k in good]
    lo = min(cands, key=lambda c: c["value"])
    hi = max(cands, key=lambda c: c["value"])
    turns = [c for c in cands if c["turns"]]
    return {"min": lo, "max": hi, "span": hi["value"] - lo["value"], "stationary": len(turns)}


def _time_ratio(lo: dict[str, Any], hi: dict[str, Any], stationary: int) -> dict[str, float] | None:
    """The crank angles of the working stroke (smallest to largest output) and of the return."""
    if stationary != 2 or not (lo["turns"] and hi["turns"]):
        return None
    forward = (hi["input"] - lo["input"]) % 360.0
    back = 360.0 - forward
    if min(forward, back) <= 0:
        return None
    return {"forward": forward, "return": back, "ratio": max(forward, back) / min(forward, back)}


def motion_summary(mech: Mechanism, sim: Any) -> dict[str, Any]:
    """Strokes of the sliders, ranges of the links pivoted on the frame and time ratios of
    ``sim`` (a planar :class:`~mechsyn.kinematics.analysis.Simulation`; see the module doc).

    Returns ``{"full_turn", "sliders", "rockers"}``: ``sliders`` joint id -> ``{"guide",
    "block", "stroke", "min", "max", "time_ratio"}`` (``min``/``max``: ``{"input", "slide",
    "point"}``; ``point`` the joint's place there for a guide on the frame, else None);
    ``rockers`` link -> ``{"pivot", "full_turn", "range", "min", "max", "time_ratio"}`` (angles
    in degrees, ``min``/``max``: ``{"input", "angle"}``). ``time_ratio`` is ``{"forward",
    "return", "ratio"}`` or None. Empty for a spatial simulation.

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = ms.examples.load("slider_crank")
    >>> s = motion_summary(m, m.simulate(A=(0, 358, 2)))  # a whole turn, 2 deg steps
    >>> round(s["sliders"]["D"]["stroke"], 6)  # a centred slider-crank: twice the crank
    2.0
    >>> round(s["sliders"]["D"]["time_ratio"]["ratio"], 6)
    1.0
    """
    out: dict[str, Any] = {"full_turn": False, "sliders": {}, "rockers": {}}
    if mech.kind != "planar" or getattr(sim, "sweep", None) is None or len(sim.inputs) != 1:
        return out
    main = sim.main_input
    x = np.asarray(sim.inputs[main], float)
    ok = np.asarray(sim.assembled, bool)
    kind = sim.input_types[main]
    cyclic = is_full_turn(x, kind) and bool(ok.all())
    out["full_turn"] = cyclic
    # the rates are per unit time at the input's speed; d/dx in the input's own unit (deg or length)
    rate_x = float(sim.speeds.get(main, 1.0)) * (180.0 / np.pi if kind == "R" else 1.0)
    for j in mech.joints:
        if j.type != "P" or j.id == main or j.actuated:
            continue
        s, sd = slide(sim, j.id)
        r = _range_of(x, s, sd / rate_x, ok, cyclic)
        if r is None:
            continue
        on_frame = mech.ground == j.links[0]
        u = np.asarray(j.axis, float)[:2] / np.linalg.norm(np.asarray(j.axis, float)[:2]) if on_frame else None
        pos = sim.points[j.id].position if j.id in sim.points else None

        def at(c, u=u, pos=pos, s=s):  # the block's place there for a guide on the frame
            p = None if u is None or pos is None else (pos[c["row"]][:2] + (c["value"] - s[c["row"]]) * u).tolist()
            return {"input": c["input"], "slide": c["value"], "point": p}

        out["sliders"][j.id] = {"guide": j.links[0], "block": j.links[1], "stroke": r["span"],
                                "min": at(r["min"]), "max": at(r["max"]),
                                "time_ratio": _time_ratio(r["min"], r["max"], r["stationary"]) if cyclic else None}
    for j in mech.joints:
        if j.type != "R" or mech.ground not in j.links or j.actuated or j.id == main:
            continue
        link = j.other(mech.ground)
        if link not in sim.links:
            continue
        lm = sim.links[link]
        ang = np.asarray(lm.angle, float).copy()
        ang[~ok] = np.nan
        good = np.isfinite(ang)
        if good.any():  # continuous over each run (the engine's angles may jump by 360)
            ang[good] = np.degrees(np.unwrap(np.radians(ang[good])))
        full = cyclic and abs(ang[-1] - ang[0]) > 180.0  # one turn of the crank turns it once: a crank too
        r = None if full else _range_of(x, ang, np.asarray(lm.angular_velocity, float) * 180.0 / np.pi / rate_x, ok,
                                        cyclic)
        if r is None and not full:
            continue
        full = full or r["span"] >= 360.0 * (1 - 1e-9)
        out["rockers"][link] = {
            "pivot": j.id, "full_turn": bool(full), "range": 360.0 if full else r["span"],
            "min": None if full else {"input": r["min"]["input"], "angle": r["min"]["value"]},
            "max": None if full else {"input": r["max"]["input"], "angle": r["max"]["value"]},
            "time_ratio": _time_ratio(r["min"], r["max"], r["stationary"]) if cyclic and not full else None}
    return out
