"""Derived quantities: transmission angle, mechanical advantage, Grashof's criterion,
coupler-curve extent, straightness of a path segment.

* Transmission angle of an RRR dyad with joints ``J1 - J2 - J3`` (a four-bar's
  coupler and rocker): the angle ``mu`` at the middle joint between the two dyad links,
  ``cos mu = (J1 - J2) . (J3 - J2) / (|J1 - J2| |J3 - J2|)``; the force is best
  transmitted at 90 degrees (Alt 1932; Norton, *Design of Machinery*, sec. 4.10). Of an
  RRP dyad (a slider-crank): the angle between the connecting rod and the normal to the
  slide, in 0..90 degrees (90: the rod pushes along the slide).
* Mechanical advantage (ideal, no friction): ``MA = omega_in / omega_out`` for a
  rotating output, ``omega_in / v_out`` for a sliding one (power balance).
* Grashof (1883): with ``s, l`` the shortest and longest links of a four-bar and ``p, q``
  the others, ``s + l < p + q``: at least one link turns fully; the shortest link as
  crank gives a crank-rocker, as frame a double crank, as coupler a double rocker;
  ``s + l = p + q``: change point; ``s + l > p + q``: triple rocker (non-Grashof).
* Straightness of a path segment: largest distance of its points from their total
  least-squares line (the first principal axis of the points).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.groups import decompose
from mechsyn.model.mechanism import Mechanism

__all__ = ["transmission_angles", "mechanical_advantage", "slide", "grashof", "Grashof", "is_fourbar", "path_extent",
           "straightness", "default_output_link"]


def transmission_angles(sim) -> dict[str, np.ndarray]:
    """Transmission angle (degrees, 0..180) of every RRR and RRP dyad of the sweep.

    Keys name the dyad by its joints, e.g. ``"B-C-D"``. Needs the Assur decomposition.
    """
    S = sim.system
    plan = decompose(S)
    out: dict[str, np.ndarray] = {}
    if plan is None:
        return out
    q = sim.sweep.q
    for step in plan.steps:
        if step.kind not in ("RRR", "RRP", "PRR"):
            continue
        J1, J2, J3 = step.joints
        pts = {}
        for jid in (J1, J2, J3):
            j = S.mech.joint(jid)
            side = S.index(j.links[1]) if S.index(j.links[1]) >= 0 else S.index(j.links[0])
            name = S.links[side] if side >= 0 else S.mech.ground
            pts[jid] = S.point(np.nan_to_num(q), side, S.to_local(name, j.point))
        if step.kind == "RRR":
            u, v = pts[J1] - pts[J2], pts[J3] - pts[J2]
        else:
            jr, jp = (J1, J3) if step.kind == "RRP" else (J3, J1)
            u = pts[jr] - pts[J2]
            j = S.mech.joint(jp)
            a = S.index(j.links[0])
            ang = S.pose(np.nan_to_num(q), a)[1]
            ax = np.asarray(S.to_local_dir(j.links[0], j.axis))
            c, s = np.cos(ang), np.sin(ang)
            v = np.stack([-(s * ax[0] + c * ax[1]), c * ax[0] - s * ax[1]], axis=1)  # slide normal
        with np.errstate(divide="ignore", invalid="ignore"):
            cosmu = np.sum(u * v, axis=1) / (np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1))
        if step.kind != "RRR":
            cosmu = np.abs(cosmu)
        mu = np.degrees(np.arccos(np.clip(cosmu, -1, 1)))
        mu[~sim.assembled] = np.nan
        out["-".join(step.joints)] = mu
    return out


def default_output_link(mech: Mechanism, inputs: list[str]) -> str | None:
    """The last moving link joined to the frame by an undriven pair (a four-bar's rocker)."""
    out = None
    for j in mech.joints:
        if j.id in inputs or j.actuated:
            continue
        if mech.ground in j.links:
            out = j.other(mech.ground)
    return out


def mechanical_advantage(sim, output: str) -> np.ndarray:
    """Ideal mechanical advantage ``omega_in / omega_out`` (or ``/ v_out`` for a slider)."""
    main = sim.main_input
    if output not in sim.links:
        raise MechsynInputError(f"no moving link {output!r}", field="output",
                                hint=f"links: {', '.join(sim.links)}")
    mech = sim.system.mech
    p = next((j.id for j in mech.joints if j.type == "P" and set(j.links) == {mech.ground, output}), None)
    out_rate = slide(sim, p)[1] if p is not None else sim.links[output].angular_velocity
    with np.errstate(divide="ignore", invalid="ignore"):
        ma = np.abs(sim.speeds[main] / out_rate)
    ma[~sim.assembled] = np.nan
    return ma


def slide(sim, joint: str, acceleration: bool = False) -> tuple[np.ndarray, ...]:
    """P joint ``joint``'s slide along its guide over a planar simulation
    (:meth:`~mechsyn.kinematics.system.PlanarSystem.coordinate`: from the guide link's
    origin, the world origin for the frame; NaN where not assembled) and its rate at the
    drives' speeds; with ``acceleration`` also the rate's time derivative along the motion
    (a central difference)."""
    S, q, qd, qdd = sim.system, sim.sweep.q, sim.sweep.qd, sim.sweep.qdd
    value = np.where(sim.assembled, S.coordinate(np.nan_to_num(q), joint), np.nan)
    rate = S.coordinate_rate(q, qd, joint)
    if not acceleration:
        return value, rate
    h = 1e-4 / max(1.0, float(np.nanmax(np.abs(qd))) if np.isfinite(qd).any() else 1.0)
    ahead, back = (S.coordinate_rate(q + sh * qd, qd + sh * qdd, joint) for sh in (h, -h))
    return value, rate, (ahead - back) / (2 * h)


@dataclass(frozen=True)
class Grashof:
    lengths: dict[str, float]      # frame, crank (input), coupler, rocker
    s: float
    l: float
    p: float
    q: float
    grashof: bool
    classification: str
    expression: str


def grashof(mech: Mechanism) -> Grashof:
    """Grashof classification of a four-bar (four links, four R pairs, from the joint points)."""
    src = mech.source or "<mechanism>"
    if len(mech.links) != 4 or len(mech.joints) != 4 or any(j.type != "R" for j in mech.joints):
        raise MechsynInputError("Grashof's criterion applies to a four-bar of four R pairs", source=src)
    if not mech.has_geometry:
        raise MechsynInputError("the four-bar needs joint points", source=src)
    lengths = {}
    for link in mech.link_names:
        js = mech.joints_of(link)
        if len(js) != 2:
            raise MechsynInputError("not a single-loop four-bar", source=src)
        lengths[link] = float(np.linalg.norm(js[0].point - js[1].point))
    ground = mech.ground
    drive = next((j for j in mech.joints if j.actuated and ground in j.links), None)
    crank = drive.other(ground) if drive else next(j.other(ground) for j in mech.joints if ground in j.links)
    rocker = next(j.other(ground) for j in mech.joints if ground in j.links and j.other(ground) != crank)
    coupler = next(n for n in mech.link_names if n not in (ground, crank, rocker))
    vals = sorted(lengths.values())
    s, p, q, l = vals[0], vals[1], vals[2], vals[3]
    rel = "=" if abs((s + l) - (p + q)) <= 1e-9 * l else ("<" if s + l < p + q else ">")
    by_shortest = {ground: "double crank (drag link)", crank: "crank-rocker",
                   rocker: "rocker-crank (the output turns fully)"}  # (Grashof: which link is the shortest)
    cls = {"=": "change point (s + l = p + q)", ">": "triple rocker (non-Grashof)"}.get(rel) or by_shortest.get(
        min(lengths, key=lengths.get), "double rocker (Grashof)")
    expr = f"s + l = {s:.6g} + {l:.6g} = {s + l:.6g} {rel} p + q = {p:.6g} + {q:.6g} = {p + q:.6g}"
    named = {"frame": lengths[ground], "crank": lengths[crank], "coupler": lengths[coupler],
             "rocker": lengths[rocker]}
    return Grashof(named, s, l, p, q, rel != ">", cls, expr)


def is_fourbar(mech: Mechanism) -> bool:
    """A planar four-bar of R pairs (four links, four R joints, two on every link): the
    mechanisms :func:`grashof` classifies."""
    return (mech.kind == "planar" and len(mech.links) == 4 and len(mech.joints) == 4
            and all(j.type == "R" for j in mech.joints) and all(len(mech.joints_of(n)) == 2 for n in mech.link_names))


def path_extent(path: np.ndarray) -> dict[str, float]:
    """Bounding box of a path (N, 2) over its finite points: min, max, width, height."""
    ok = np.all(np.isfinite(path), axis=1)
    if not ok.any():
        return {"x_min": None, "x_max": None, "y_min": None, "y_max": None, "width": None, "height": None}
    p = path[ok]
    lo, hi = p.min(axis=0), p.max(axis=0)
    return {"x_min": float(lo[0]), "x_max": float(hi[0]), "y_min": float(lo[1]), "y_max": float(hi[1]),
            "width": float(hi[0] - lo[0]), "height": float(hi[1] - lo[1])}


def straightness(path: np.ndarray) -> dict[str, float | list[float]]:
    """Largest deviation of the points (N, 2) from their best (total least-squares) line."""
    p = path[np.all(np.isfinite(path), axis=1)]
    if len(p) < 2:
        raise MechsynInputError("a straightness check needs at least two assembled points", field="straight")
    c = p.mean(axis=0)
    _, sv, vt = np.linalg.svd(p - c, full_matrices=False)
    d = vt[0]
    n = np.array([-d[1], d[0]])
    dev = (p - c) @ n
    t = (p - c) @ d
    return {"max_deviation": float(np.abs(dev).max()), "rms_deviation": float(np.sqrt(np.mean(dev ** 2))),
            "length": float(t.max() - t.min()), "direction": d.tolist(), "centre": c.tolist()}
