"""Spatial mechanisms built for the tests of issue 38, each with its own truth (closed forms
derived here, none from mechsyn's equations): a line-symmetric Bricard 6R (loop closure by the
product of exponentials of its joint values), a spherical four-bar of given arcs (the rocker
from the two cones about the coupler's and the frame's axes), an RSSR (its closure equation
``A cos ψ + B sin ψ = C``)."""

from __future__ import annotations

import numpy as np

from mechsyn.io import mechanism_from_dict


def unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def rot(a, t):
    """Rotation by ``t`` (rad) about the unit vector ``a`` (Rodrigues)."""
    a = unit(a)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * K @ K


def screw_exp(point, axis, t):
    """The displacement (4 x 4) of a rotation by ``t`` about the line (point, axis)."""
    R = rot(axis, t)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, np.asarray(point, float) - R @ np.asarray(point, float)
    return T


def _r(jid, a, b, point, axis, actuated=False):
    return {"id": jid, "type": "R", "links": [a, b], "point": [float(v) for v in point],
            "axis": [float(v) for v in axis], "actuated": actuated}


# --------------------------------------------------------------------------- Bricard
def bricard(seed=0, offset=(0.0, 0.0, 0.0)):
    """A line-symmetric Bricard 6R: joints 1-3 on random lines, joints 4-6 their images under
    the half-turn about the z axis (moved by ``offset``). It moves with one freedom keeping
    ``θ_i = θ_{i+3}`` (Bricard 1927; Baker 1980)."""
    rng = np.random.default_rng(seed)
    off = np.asarray(offset, float)
    H = np.diag([-1.0, -1.0, 1.0])
    pts = [rng.uniform(-1, 1, 3) + [1.2 * np.cos(k), 1.2 * np.sin(k), 0] for k in (0.3, 1.2, 2.1)]
    axes = [unit(rng.normal(size=3)) for _ in range(3)]
    pts += [H @ p for p in pts]
    axes += [H @ a for a in axes]
    links = ["frame", "l1", "l2", "l3", "l4", "l5"]
    joints = [_r(f"J{i + 1}", links[i], links[(i + 1) % 6], pts[i] + off, axes[i], actuated=(i == 0))
              for i in range(6)]
    return mechanism_from_dict({"name": f"Bricard line-symmetric {seed}", "kind": "spatial", "ground": "frame",
                                "links": links, "joints": joints}, f"bricard{seed}")


def loop_error(mech, joints, k):
    """Closure of the reported joint values at row ``k``: the largest entry of
    ``exp(ξ1 θ1) ... exp(ξn θn) - I`` around the single loop of ``mech`` (joints in loop
    order, each turning its second link against its first)."""
    T = np.eye(4)
    for j in mech.joints:
        T = T @ screw_exp(j.point, j.axis, np.radians(joints[j.id][k]))
    return float(np.abs(T - np.eye(4)).max())


# --------------------------------------------------------------------------- spherical four-bar
def spherical_fourbar(a, b, c, d, phi0, centre=(0.0, 0.0, 0.0), radius=1.0, branch=1):
    """A spherical four-bar with arcs (deg) crank ``a`` (A-B), coupler ``b`` (B-C), rocker ``c``
    (C-D) and frame ``d`` (A-D), drawn at crank angle ``phi0`` (deg; 0: B on the arc A-D), its
    joint points on the axes at ``radius`` from ``centre``. Returns the mechanism and
    ``axes(phi)``: the closed-form unit axes (A, B, C, D) at crank angle ``phi`` of the
    assembly ``branch`` (+1 or -1; None where it does not assemble)."""
    A = np.array([0.0, 0.0, 1.0])
    D = rot([0, 1, 0], np.radians(d)) @ A
    B0 = rot([0, 1, 0], np.radians(a)) @ A

    def axes(phi, br=branch):
        B = rot(A, np.radians(phi)) @ B0
        cb, cc = np.cos(np.radians(b)), np.cos(np.radians(c))
        # C = x B + y D + z (B x D): C.B = cos b, C.D = cos c, |C| = 1
        g = B @ D
        x, y = np.linalg.solve([[1, g], [g, 1]], [cb, cc])
        n = np.cross(B, D)
        rest = 1 - (x * x + y * y + 2 * x * y * g)
        if rest < -1e-12 or n @ n < 1e-300:
            return None
        C = x * B + y * D + br * np.sqrt(max(rest, 0.0) / (n @ n)) * n
        return A, B, C, D

    A_, B_, C_, D_ = axes(phi0)
    o = np.asarray(centre, float)
    links = ["frame", "crank", "coupler", "rocker"]
    js = [_r("A", "frame", "crank", o + radius * A_, A_, True), _r("B", "crank", "coupler", o + radius * B_, B_),
          _r("C", "coupler", "rocker", o + radius * C_, C_), _r("D", "rocker", "frame", o + radius * D_, D_)]
    m = mechanism_from_dict({"name": "spherical four-bar", "kind": "spatial", "ground": "frame", "links": links,
                             "joints": js}, "spherical")
    return m, axes


# --------------------------------------------------------------------------- RSSR
def rssr_at_dead_point(r=2.0, rod=None):
    """An RSSR (crank radius ``r`` about z at the origin; rocker radius 1 about x through
    ``(3, 2, 1)``) drawn at a dead point of its crank: the rod ``B C`` is perpendicular to the
    rocker's circle there (``∂f/∂ψ = 0``), so the crank angle is at a limit of its range.
    Returns the mechanism, the drawn crank angle ``phi_star`` (deg) and ``psi(phi)``: the two
    rocker angles (rad, from the rocker's drawn position) by the closed form, NaN where the
    crank does not reach."""
    Dp = np.array([3.0, 2.0, 1.0])
    e1, e2 = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])  # the rocker's circle about x

    def Cpt(psi):
        return Dp + np.cos(psi) * e1 + np.sin(psi) * e2

    def far(phi):  # the largest distance from the crank pin to the rocker's circle
        B = r * np.array([np.cos(phi), np.sin(phi), 0.0])
        q = Dp - B
        return np.sqrt((q @ [1, 0, 0]) ** 2 + (np.hypot(q @ e1, q @ e2) + 1) ** 2)

    grid = np.radians(np.arange(0, 360, 0.5))
    f = np.array([far(t) for t in grid])
    rising = np.gradient(f) > 0
    goal = f.min() + 0.25 * (f.max() - f.min())  # a rod this long: a dead point on the rising side
    phi_star = float(grid[rising][np.argmin(np.abs(f[rising] - goal))])
    Bs = r * np.array([np.cos(phi_star), np.sin(phi_star), 0.0])
    # ψ* with C'(ψ*)·(C(ψ*) - B*) = 0: (-sin ψ e1 + cos ψ e2)·(D - B*) = 0
    q = Dp - Bs
    psi_star = np.arctan2(q @ e2, q @ e1) + np.pi  # the far side: the rod at its longest over ψ
    ell = float(np.linalg.norm(Cpt(psi_star) - Bs)) if rod is None else rod
    Cs = Cpt(psi_star)

    def psi(phi_deg):
        B = r * np.array([np.cos(np.radians(phi_deg)), np.sin(np.radians(phi_deg)), 0.0])
        q = Dp - B  # |q + cos ψ e1 + sin ψ e2|² = ℓ²
        Acoef, Bcoef = 2 * q @ e1, 2 * q @ e2
        Ccoef = ell ** 2 - q @ q - 1.0
        h = np.hypot(Acoef, Bcoef)
        if abs(Ccoef) > h * (1 + 1e-12):
            return np.array([np.nan, np.nan])
        base, w = np.arctan2(Bcoef, Acoef), np.arccos(np.clip(Ccoef / h, -1, 1))
        return np.array([base + w, base - w]) - psi_star

    m = mechanism_from_dict({"name": "RSSR at a dead point", "kind": "spatial", "ground": "frame",
                             "links": ["frame", "crank", "rod", "rocker"], "joints": [
        _r("A", "frame", "crank", [0, 0, 0], [0, 0, 1], True),
        {"id": "B", "type": "S", "links": ["crank", "rod"], "point": Bs.tolist()},
        {"id": "C", "type": "S", "links": ["rod", "rocker"], "point": Cs.tolist()},
        _r("D", "frame", "rocker", Dp, [1, 0, 0])]}, "rssr_dead")
    return m, float(np.degrees(phi_star)), psi


def rssr_taut():
    """An RSSR drawn with its rod at the largest distance between the crank pin's circle and
    the rocker pin's circle (over both angles): stretched taut, it cannot move at all (finite
    mobility 0 besides the rod's idle spin) though it has two instantaneous motions."""
    Dp = np.array([3.0, 2.0, 1.0])

    def pins(phi, psi):
        return np.array([np.cos(phi), np.sin(phi), 0.0]), Dp + [0.0, np.cos(psi), np.sin(psi)]

    def dist(x):
        B, C = pins(*x)
        return np.linalg.norm(C - B)

    g = np.radians(np.arange(0, 360, 2.0))
    best = max(((a, b) for a in g for b in g), key=dist)
    x = np.array(best)
    for _ in range(60):  # Newton on the gradient of the squared distance (a smooth maximum)
        h = 1e-5
        f = lambda y: dist(y) ** 2  # noqa: E731
        gr = np.array([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(2)])
        H = np.array([[(f(x + h * (ei + ej)) - f(x + h * (ei - ej)) - f(x - h * (ei - ej)) + f(x - h * (ei + ej)))
                       / (4 * h * h) for ej in np.eye(2)] for ei in np.eye(2)])
        x = x - np.linalg.solve(H, gr)
    B, C = pins(*x)
    return mechanism_from_dict({"name": "taut RSSR", "kind": "spatial", "ground": "frame",
                                "links": ["frame", "crank", "rod", "rocker"], "joints": [
        _r("A", "frame", "crank", [0, 0, 0], [0, 0, 1], True),
        {"id": "B", "type": "S", "links": ["crank", "rod"], "point": B.tolist()},
        {"id": "C", "type": "S", "links": ["rod", "rocker"], "point": C.tolist()},
        _r("D", "frame", "rocker", Dp, [1, 0, 0])]}, "rssr_taut")


# --------------------------------------------------------------------------- Sarrus
def sarrus(alpha=40.0, leg_a=1.0, leg_b=(1.3, 1.6)):
    """A Sarrus linkage: leg A (axes along x, both links ``leg_a`` long, its crank A1 at
    ``alpha`` degrees above the horizontal, driven) and leg B (axes along y, links ``leg_b``)
    hold the top, which translates along z at height ``2 leg_a sin(alpha + A1)``. Leg A is
    stretched (A1, A2, A3 on one line, a change point) at ``A1 = 90 - alpha``; where B's reach
    ``sum(leg_b)`` is less than ``2 leg_a`` the input stops (leg B stretched, a dead point) at
    ``A1 = asin(sum(leg_b) / (2 leg_a)) - alpha``. Returns the mechanism."""
    al = np.radians(alpha)
    h = 2 * leg_a * np.sin(al)
    b1, b2 = leg_b
    beta = np.arcsin((b1 * b1 + h * h - b2 * b2) / (2 * h * b1))
    ex, ey = [1, 0, 0], [0, 1, 0]
    joints = [_r("A1", "frame", "a1", [1, 0, 0], ex, actuated=True),
              _r("A2", "a1", "a2", [1, leg_a * np.cos(al), leg_a * np.sin(al)], ex),
              _r("A3", "a2", "top", [1, 0, h], ex),
              _r("B3", "top", "b2", [0, 1, h], ey),
              _r("B2", "b2", "b1", [b1 * np.cos(beta), 1, b1 * np.sin(beta)], ey),
              _r("B1", "b1", "frame", [0, 1, 0], ey)]
    return mechanism_from_dict({"name": "Sarrus", "kind": "spatial", "ground": "frame",
                                "links": ["frame", "a1", "a2", "top", "b2", "b1"], "joints": joints}, "sarrus")
