"""S-S bars solved as one distance equation between their ends (no unknowns of their own):
the Delta's six bars and the RSSR's rod. Each bar's reported pose carries both its joint
points where the links it joins carry them, is the least rotation of its drawn line onto its
line at the row nearest it and is carried from row to row with no spin (defined and
continuous where its line turns through the opposite of its drawn line: a drag-link's
coupler), and its twist moves its ends as they move; the rank and idle count are those of
the bars as links (each S-S bar: five constraints on its six freedoms, one idle spin); a bar
with a named point stays a link solved for, and moves its point with its ends."""

from dataclasses import replace

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.spatial_result import rotation_vectors
from mechsyn.model.mechanism import PointSpec


def ends(mech, bar):
    return [j for j in mech.joints if bar in j.links]


def assert_carried_without_spin(R, d0, d, ok=None):
    """The rotations ``R`` (N, 3, 3) of a bar over the rows of a sweep (``ok``: assembled), with
    drawn line ``d0`` and lines ``d`` (N, 3): each takes ``d0`` to its row's line; from one
    assembled row to the next the bar turns by the least rotation between the two lines
    (about ``d_k x d_k+1``, by the angle between them: no spin about its line); in each
    stretch of assembled rows, at the row nearest the drawn line, the least rotation from it
    (about ``d0 x d``)."""
    ok = np.ones(len(R), bool) if ok is None else ok
    edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(int), 0]))
    assert len(edges)
    L = np.linalg.norm(d0)
    for lo, hi in zip(edges[::2], edges[1::2]):
        Rs, ds = R[lo:hi], d[lo:hi]
        assert np.isfinite(Rs).all()
        assert np.abs(Rs @ d0 - ds).max() <= 1e-9 * L
        u = ds / np.linalg.norm(ds, axis=1)[:, None]
        step = rotation_vectors(Rs[1:] @ np.swapaxes(Rs[:-1], 1, 2))  # deg
        between = np.degrees(np.arctan2(np.linalg.norm(np.cross(u[:-1], u[1:]), axis=1),
                                        np.einsum("ki,ki->k", u[:-1], u[1:])))
        assert np.abs(np.linalg.norm(step, axis=1) - between).max(initial=0.0) <= 1e-7
        assert np.abs(np.einsum("ki,ki->k", step, u[:-1])).max(initial=0.0) <= 1e-7
        assert np.abs(np.einsum("ki,ki->k", step, u[1:])).max(initial=0.0) <= 1e-7
        k = int(np.argmax(u @ d0))
        rv = rotation_vectors(Rs[k:k + 1])[0]
        assert abs(rv @ d0) <= 1e-7 * L and abs(rv @ u[k]) <= 1e-7


@pytest.mark.parametrize("name,joint,rng,bars,rank,idle", [
    ("delta", "R1", (-30, 30, 2), 6, 54, 6), ("rssr", "A", (0, 360, 5), 1, 17, 1)])
def test_bars_are_distance_equations_and_move_with_their_ends(name, joint, rng, bars, rank, idle):
    mech = ms.examples.load(name)
    # every bar's ends as named points of the links it joins (their motion is those links')
    named = {f"{bar}/{j.id}": PointSpec(link=next(x for x in j.links if x != bar), at=tuple(j.point))
             for bar in mech.moving_links if [j.type for j in ends(mech, bar)] == ["S", "S"] for j in ends(mech, bar)}
    mech = replace(mech, points={**mech.points, **named})
    s = ms.simulate(mech, {joint: ms.input_grid(*rng)}, points=list(named))
    M = s.model
    assert len(M.bars) == bars and M.n == len(mech.moving_links) - bars
    assert (s.rank, s.idle) == (rank, idle)
    ok, L = s.assembled, s.length_scale
    assert ok.any()
    for bar in M.bars:
        lp = s.links[bar]
        (j1, j2) = ends(mech, bar)
        y = []
        for j in (j1, j2):
            other = next(x for x in j.links if x != bar)
            x0 = np.asarray(j.point, float)
            on_bar = lp.rotation[ok] @ x0 + lp.translation[ok]
            if other == mech.ground:
                on_other = np.broadcast_to(x0, on_bar.shape)
            else:
                lo = s.links[other]
                on_other = lo.rotation[ok] @ x0 + lo.translation[ok]
            assert np.abs(on_bar - on_other).max() <= 1e-9 * L, (bar, j.id)
            y.append(on_other)
        d = y[1] - y[0]
        dd = np.full((len(ok), 3), np.nan)
        dd[ok] = d
        assert_carried_without_spin(lp.rotation, np.subtract(j2.point, j1.point), dd, ok)
        vel = [s.points[f"{bar}/{j.id}"].velocity[ok] for j in (j1, j2)]  # its twist moves its ends as they move
        w = lp.angular_velocity[ok]
        live = np.isfinite(w).all(axis=1)
        assert live.sum() > len(live) // 2
        assert np.abs(np.cross(w, d) - (vel[1] - vel[0]))[live].max() <= 1e-8 * L
        assert np.abs(np.einsum("ki,ki->k", w, d))[live].max() <= 1e-9 * L


def test_a_bar_with_a_named_point_stays_solved_for():
    mech = ms.examples.load("delta")
    j1, j2 = ends(mech, "bar1a")
    mid = (np.asarray(j1.point, float) + np.asarray(j2.point, float)) / 2
    pointed = replace(mech, points={**mech.points, "M": PointSpec(link="bar1a", at=tuple(mid))})
    g = ms.input_grid(-20, 20, 5)
    a = ms.simulate(pointed, {"R1": g}, points=["M", "S1a1", "S1a2", "S2b2"])
    b = ms.simulate(mech, {"R1": g}, points=["S1a1", "S1a2", "S2b2"])
    assert "bar1a" not in a.model.bars and len(a.model.bars) == 5
    assert (a.rank, a.idle) == (b.rank, b.idle) == (54, 6)
    L = a.length_scale
    for k in ("S1a1", "S1a2", "S2b2"):
        for q in ("position", "velocity", "acceleration"):
            assert np.abs(getattr(a.points[k], q) - getattr(b.points[k], q)).max() <= 1e-9 * L, (k, q)
    assert np.abs(a.point("M") - (a.point("S1a1") + a.point("S1a2")) / 2).max() <= 1e-9 * L


def drag_link_rssr(theta0=60.0, a=3.0, b=3.5, c=3.0, g=1.0):
    """A drag-link RSSR (frame g the shortest: crank and rocker turn fully, and so does the
    coupler, an S-S bar, whose line passes through the opposite of its drawn line), drawn at
    crank angle ``theta0`` in a plane then placed in space by a generic rotation and offset,
    and the crank angles (deg, from the drawn one) where the coupler's line is opposite its
    drawn line (from the planar closed form, not the engine)."""
    def coupler(th):  # B, C of the planar four-bar at crank angle th (one branch)
        B = a * np.array([np.cos(th), np.sin(th), 0 * th])
        e = np.array([g, 0.0, 0.0])[:, None] - B
        L = np.linalg.norm(e, axis=0)
        f = (b ** 2 - c ** 2 + L ** 2) / (2 * L)
        h = np.sqrt(b ** 2 - f ** 2)
        return B, B + f * e / L + h * np.array([-e[1], e[0], 0 * th]) / L

    t = np.radians(theta0) + np.linspace(0, 2 * np.pi, 20001)
    B, C = coupler(t)
    psi = np.unwrap(np.arctan2(C[1] - B[1], C[0] - B[0]))
    assert np.ptp(psi) >= 2 * np.pi - 1e-3  # the coupler turns fully
    opposite = []
    for target in psi[0] + np.pi * np.array([-3, -1, 1, 3]):
        k = np.flatnonzero(np.diff(np.sign(psi - target)))
        for i in k:  # refined by bisection on the closed form
            lo, hi = t[i], t[i + 1]
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                Bm, Cm = coupler(np.array([mid]))
                val = np.unwrap(np.r_[psi[i], np.arctan2(Cm[1] - Bm[1], Cm[0] - Bm[0])])[1] - target
                lo, hi = (mid, hi) if np.sign(val) == np.sign(psi[i] - target) else (lo, mid)
            opposite.append(np.degrees(0.5 * (lo + hi)) - theta0)
    B0, C0 = (x[:, 0] for x in coupler(np.radians([theta0])))
    Q, _ = np.linalg.qr(np.array([[0.3, -1.2, 0.5], [0.8, 0.4, -0.9], [-0.2, 0.7, 1.1]]))
    Q *= np.sign(np.linalg.det(Q))
    off = np.array([2.0, -1.5, 0.7])
    place = lambda x: (Q @ x + off).tolist()  # noqa: E731
    z = (Q @ [0, 0, 1.0]).tolist()
    mech = mechanism_from_dict({
        "name": "drag-link RSSR", "kind": "spatial", "ground": "frame",
        "links": ["frame", "crank", "rod", "rocker"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "point": place([0, 0, 0]), "axis": z,
             "actuated": True},
            {"id": "B", "type": "S", "links": ["crank", "rod"], "point": place(B0)},
            {"id": "C", "type": "S", "links": ["rod", "rocker"], "point": place(C0)},
            {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": place([g, 0, 0]), "axis": z}]},
        "drag-link RSSR")
    return mech, sorted(opposite)


def test_a_bar_through_the_opposite_of_its_drawn_line_keeps_a_defined_continuous_pose():
    mech, opposite = drag_link_rssr()
    assert len(opposite) == 1 and 0 < opposite[0] < 360
    s0 = ms.simulate(mech, {"A": ms.input_grid(0, 10, 10)})
    zero = s0.zero["A"]
    # two full turns of the crank, one row exactly where the rod is opposite its drawn line
    u = zero + np.unique(np.r_[np.arange(0, 721, 3.0), opposite[0], opposite[0] + 360])
    s = ms.simulate(mech, {"A": u})
    assert s.model.bars == ("rod",) and s.assembled.all()
    assert not any(e.kind == "singular" for e in s.events)
    pB, pC = (np.asarray(mech.joint(j).point, float) for j in "BC")
    crank = s.links["crank"]
    y1 = crank.rotation @ pB + crank.translation
    rocker = s.links["rocker"]
    y2 = rocker.rotation @ pC + rocker.translation
    d0, d = pC - pB, y2 - y1
    cos = d @ d0 / np.linalg.norm(d, axis=1) / np.linalg.norm(d0)
    assert cos.min() < -1 + 1e-12  # a row on the opposite of the drawn line
    rod = s.links["rod"]
    assert np.isfinite(rod.rotation).all() and np.isfinite(rod.translation).all()
    L = s.length_scale
    for p0, y in ((pB, y1), (pC, y2)):  # the drawn ends onto the ends
        assert np.abs(rod.rotation @ p0 + rod.translation - y).max() <= 1e-9 * L
    assert_carried_without_spin(rod.rotation, d0, d)
    w = rod.angular_velocity
    assert np.isfinite(w).all() and np.abs(np.einsum("ki,ki->k", w, d)).max() <= 1e-9 * L
