"""S-S bars solved as one distance equation between their ends (no unknowns of their own):
the Delta's six bars and the RSSR's rod. Each bar's reported pose carries both its joint
points where the links it joins carry them, turns its drawn line onto its line by the least
rotation (no spin), and its twist moves its ends as they move; the rank and idle count are
those of the bars as links (each S-S bar: five constraints on its six freedoms, one idle
spin); a bar with a named point stays a link solved for, and moves its point with its ends."""

from dataclasses import replace

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.kinematics.spatial_result import rotation_vectors
from mechsyn.model.mechanism import PointSpec


def ends(mech, bar):
    return [j for j in mech.joints if bar in j.links]


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
        d0 = np.subtract(j2.point, j1.point)
        d = y[1] - y[0]
        rv = rotation_vectors(lp.rotation[ok])  # the least rotation: about d0 x d, no spin
        assert np.abs(rv @ d0).max() <= 1e-9 * np.linalg.norm(d0)
        assert np.abs(np.einsum("ki,ki->k", rv, d)).max() <= 1e-9 * np.linalg.norm(d0)
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
