"""Dead points of six-bars found by the regular pass on each group's discriminant (issue 30):
against an independent bisection of the discriminant, against the general Newton engine
on perturbed copies, at any scale, and at the cost of a four-bar per dyad."""

from dataclasses import replace
from itertools import product

import numpy as np
import pytest

from mechsyn.kinematics import kernel
from mechsyn.kinematics.analysis import input_grid, simulate
from mechsyn.kinematics.system import build_system

from kinematics_helpers import ex  # noqa: F401
from test_scale import scaled

#: Six-bars whose second dyad folds too (the drawn ones fold in their first loop only):
#: (file, joint moved, its new point, the groups that fold, a sweep (degrees) through
#: folds where the Newton engine and the closed form mean the same motion: below -9.55
#: degrees the Stephenson variant's dyad E-F-G cannot be assembled with its first loop in
#: the drawn mode, and Newton goes on with that loop in the other mode, a branch the
#: closed form does not take).
FOLDING = [("textbook/watt_sixbar.yaml", "G", (3.5, 5.0), {"B-C-D", "E-G-F"}, (-90, 270, 4)),
           ("textbook/stephenson_sixbar.yaml", "F", (5.5, 3.0), {"B-C-D", "E-F-G"}, (-5, 115, 3))]


def moved(m, jid, point):
    return m.with_joints(tuple(replace(j, point=np.array(point, float)) if j.id == jid else j for j in m.joints))


def folding(ex, case):
    f, jid, point, groups, _ = case
    return moved(ex(f), jid, point), groups


def dyads(m):
    """The chain's RRR dyads in solving order from the joints alone: (J1, J2, J3, link of
    J1-J2, link of J2-J3), each with both end joints on placed links."""
    placed = {m.ground, "crank"}
    joints = {j.id: j for j in m.joints}
    out, left = [], [j for j in m.joints if not (set(j.links) <= placed)]
    while left:
        for J2 in left:
            b1, b2 = J2.links
            ends = []
            for b in (b1, b2):
                e = [j for j in joints.values() if b in j.links and j.id != J2.id and (set(j.links) - {b}) <= placed]
                ends.append(e[0] if e else None)
            if None not in ends:
                out.append((ends[0].id, J2.id, ends[1].id, b1, b2))
                placed |= {b1, b2}
                break
        left = [j for j in m.joints if not (set(j.links) <= placed)]
    return out


def discriminants(m, theta_deg: float) -> dict[str, float]:
    """Every dyad's normalised discriminant h^2 / L1^2 at the crank angle ``theta_deg``,
    computed here from the drawn joint points alone: the crank turned about its frame
    pivot, each dyad's middle joint on the intersection of two circles (law of cosines) in
    its drawn mode, every other joint of a link carried rigidly by two of its joints."""
    P0 = {j.id: complex(*j.point) for j in m.joints}
    on = {ln.name: [j.id for j in m.joints if ln.name in j.links] for ln in m.links}
    th0 = build_system(m).drivers[0].assembled  # the drawn input (the input's zero)
    P = {j: P0[j] for j in on[m.ground]}
    rot = np.exp(1j * (np.radians(theta_deg) - th0))
    for j in on["crank"]:
        P[j] = P0["A"] + rot * (P0[j] - P0["A"])
    out = {}
    for J1, J2, J3, b1, b2 in dyads(m):
        A, C = P[J1], P[J3]
        L1, L2 = abs(P0[J2] - P0[J1]), abs(P0[J2] - P0[J3])
        d = C - A
        D = abs(d)
        a = (L1 ** 2 - L2 ** 2 + D ** 2) / (2 * D)
        h2 = L1 ** 2 - a ** 2
        out[f"{J1}-{J2}-{J3}"] = h2 / L1 ** 2
        if h2 < 0:
            break  # not assembled: the dyads after it cannot be placed
        sigma = 1.0 if ((P0[J3] - P0[J1]).conjugate() * (P0[J2] - P0[J1])).imag >= 0 else -1.0
        P[J2] = A + d / D * (a + 1j * sigma * np.sqrt(h2))
        for b, (p, q) in ((b1, (J1, J2)), (b2, (J3, J2))):
            r = (P[q] - P[p]) / (P0[q] - P0[p])
            r /= abs(r)
            for j in on[b]:
                P[j] = P[p] + r * (P0[j] - P0[p])
    return out


def bisect(f, lo: float, hi: float, tol: float = 1e-14) -> float:
    flo = f(lo)
    assert (flo > 0) != (f(hi) > 0)
    while hi - lo > tol * max(1.0, abs(lo)):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        if (f(mid) > 0) == (flo > 0):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("case", FOLDING, ids=["watt", "stephenson"])
def test_six_bar_dead_points_equal_a_bisection_of_the_discriminant(ex, case):
    m, groups = folding(ex, case)
    s = simulate(m, {"A": input_grid(0, 360, 1)})
    assert s.engine == "regular pass"
    dead = [e for e in s.events if e.kind == "dead point"]
    assert {e.group for e in dead} == groups  # both dyads fold
    x = s.inputs["A"]
    for e in dead:
        i = e.index
        root = bisect(lambda t: discriminants(m, t)[e.group], x[i - 1], x[i])
        assert abs(e.input["A"] - root) < 1e-9, (e, root)
        # the group assembled on the side where its discriminant is positive: the end of a
        # working range going forwards, the start of one going back
        before = discriminants(m, x[i - 1]).get(e.group, -1.0) > 0
        assert e.message.startswith("assembly ends" if before else "assembly starts again"), e


@pytest.mark.parametrize("case", FOLDING, ids=["watt", "stephenson"])
@pytest.mark.parametrize("copy", [0, pytest.param(1, marks=pytest.mark.slow)])
def test_the_same_events_as_the_newton_engine_on_perturbed_copies(ex, case, copy):
    m, _ = folding(ex, case)
    rng = np.random.default_rng(copy)
    size = np.ptp([j.point for j in m.joints], axis=0).max()
    m = m.with_joints(tuple(replace(j, point=np.asarray(j.point, float) + rng.uniform(-0.01, 0.01, 2) * size)
                            for j in m.joints))
    x = input_grid(*case[4])
    a = simulate(m, {"A": x})
    n = simulate(m, {"A": x}, method="newton")
    assert a.engine == "regular pass" and n.engine == "newton"
    assert (~a.assembled).any() and np.array_equal(a.assembled, n.assembled)
    # where the mechanism stops or starts being assembled, the first (last) of the groups'
    # folds between the two rows is Newton's dead point (a group's fold hidden between
    # the same rows by an upstream group's: found too)
    for i in np.flatnonzero(a.assembled[1:] != a.assembled[:-1]) + 1:
        ours = [e.input["A"] for e in a.events if e.kind == "dead point" and e.index == i]
        theirs = [e.input["A"] for e in n.events if e.kind == "dead point" and e.index == i]
        assert ours and theirs, (i, a.events, n.events)
        first = min if a.assembled[i - 1] == (x[1] > x[0]) else max
        assert abs(first(ours) - theirs[0]) < 1e-6, (i, ours, theirs)
    ok = a.assembled
    for p in a.points:
        assert np.abs(a.points[p].position[ok] - n.points[p].position[ok]).max() < 1e-9, p


@pytest.mark.parametrize("k", [1e-3, 1e4])
def test_dead_points_do_not_depend_on_the_scale(ex, k):
    m, _ = folding(ex, FOLDING[0])
    x = {"A": input_grid(0, 360, 1)}
    a, b = simulate(m, x), simulate(scaled(m, k), x)
    assert b.engine == "regular pass" and np.array_equal(a.assembled, b.assembled)
    assert [(e.index, e.kind, e.group) for e in a.events] == [(e.index, e.kind, e.group) for e in b.events]
    for e, f in zip(a.events, b.events):
        assert abs(e.input["A"] - f.input["A"]) < 1e-9
    for p in a.points:
        pa, pb = a.points[p].position, b.points[p].position
        assert np.allclose(pb, k * pa, rtol=0, atol=1e-12 * k * 10, equal_nan=True), p


def test_a_fold_costs_a_few_evaluations_of_its_dyad(ex, monkeypatch):
    """A dead point of a four-bar loop (the first of each six-bar) is found in closed
    form; any other is refined from the discriminant's values at the two rows around it
    (the array pass's) by secant steps: at most 6 evaluations of the one-input
    discriminant per fold in all (Brent's method from scratch took 7.2 per fold on these
    six-bars); the rows themselves are never evaluated one by one. The tracked chain's
    Python scan is counted (the regular pass's is the kernel's, the same decisions)."""
    calls = []
    real = kernel.scalar_disc
    monkeypatch.setattr(kernel, "scalar_disc", lambda *a: calls.append(a[1]) or real(*a))
    for case in FOLDING:
        m, _ = folding(ex, case)
        calls.clear()
        s = simulate(m, {"A": input_grid(0, 360, 1)}, method="tracked chain")
        dead = [e for e in s.events if e.kind == "dead point"]
        assert len(dead) >= 4 and calls
        assert len(calls) <= 6 * len(dead), (len(calls), len(dead))


def test_four_bar_dead_points_in_closed_form(ex, monkeypatch):
    """The textbook four-bar (crank sqrt(5), coupler = rocker = sqrt(10), frame 5) stands
    stretched where |BD| = 2 sqrt(10): cos(theta) = -1/sqrt(5), theta = 180 deg - atan(2)
    and its mirror, by the law of cosines on the crank's circle, without evaluating the
    discriminant, on sweeps either way and from any turn."""
    calls = []
    real = kernel.scalar_disc
    monkeypatch.setattr(kernel, "scalar_disc", lambda *a: calls.append(1) or real(*a))
    m = ex("textbook/fourbar.yaml")
    exact = 180.0 - np.degrees(np.arctan(2.0))
    for grid, method in product(((0, 360, 1), (360, 0, -7), (-300, 60, 3)), ("regular pass", "tracked chain")):
        s = simulate(m, {"A": input_grid(*grid)}, method=method)
        dead = sorted(e.input["A"] % 360.0 for e in s.events if e.kind == "dead point")
        assert len(dead) == 2 and s.engine == method
        assert abs(dead[0] - exact) < 1e-12 and abs(dead[1] - (360.0 - exact)) < 1e-12, (grid, dead)
    assert not calls
