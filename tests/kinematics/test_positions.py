"""Position analysis against closed forms written independently of the solvers."""

import numpy as np
import pytest

from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics import dyads
from mechsyn.kinematics.analysis import input_grid, simulate
from mechsyn.kinematics.system import build_system

from kinematics_helpers import ex, fourbar  # noqa: F401


def rocker_angle_freudenstein(theta, a, b, c, g, branch=1):
    """Rocker angle by Freudenstein's equation K1 cos(psi) - K2 cos(theta) + K3 = cos(theta - psi),
    solved as A t^2 + B t + C = 0 with t = tan(psi / 2) (Norton, eq. 4.10)."""
    K1, K2, K3 = g / a, g / c, (a ** 2 - b ** 2 + c ** 2 + g ** 2) / (2 * a * c)
    A = np.cos(theta) - K1 - K2 * np.cos(theta) + K3
    B = -2 * np.sin(theta)
    C = K1 - (K2 + 1) * np.cos(theta) + K3
    t = (-B + branch * np.sqrt(B ** 2 - 4 * A * C)) / (2 * A)
    return 2 * np.arctan(t)


@pytest.mark.parametrize("method", ["assur", "newton"])
def test_fourbar_crank_rocker_matches_freudenstein(method):
    m = fourbar()
    sim = simulate(m, {"A": input_grid(0, 360, 5)}, points=["C"], method=method)
    assert sim.method == method and sim.assembled.all()
    th = np.radians(sim.inputs["A"])
    C = sim.points["C"].position
    psi = np.arctan2(C[:, 1], C[:, 0] - 4.0)
    # the file's assembly (C above the frame line) is the open branch: pick the matching root
    ref = [rocker_angle_freudenstein(th, 1, 3.5, 3, 4, s) for s in (1, -1)]
    err = [np.abs(np.angle(np.exp(1j * (psi - r)))).max() for r in ref]
    assert min(err) < 1e-10
    # link lengths preserved
    B = simulate(m, {"A": input_grid(0, 360, 5)}, points=["B"], method=method).points["B"].position
    assert np.allclose(np.linalg.norm(C - B, axis=1), 3.5, atol=1e-12)


@pytest.mark.parametrize("method", ["assur", "newton"])
def test_slider_crank_closed_form(ex, method):
    m = ex("textbook/slider_crank.yaml")
    sim = simulate(m, {"A": input_grid(0, 360, 10)}, points=["C"], method=method)
    th = np.radians(sim.inputs["A"])
    # rod length from the file's points (the file's C is 3.0002 from B, not exactly 3)
    r, l = 1.0, float(np.linalg.norm(m.joint("C").point - m.joint("B").point))
    x = r * np.cos(th) + np.sqrt(l ** 2 - (r * np.sin(th)) ** 2)
    assert np.allclose(sim.points["C"].position[:, 0], x, atol=1e-12)
    assert np.allclose(sim.points["C"].position[:, 1], 0, atol=1e-12)
    # slider velocity: dx/dtheta = -r sin - r^2 sin cos / sqrt(l^2 - r^2 sin^2)
    v = -r * np.sin(th) - r ** 2 * np.sin(th) * np.cos(th) / np.sqrt(l ** 2 - (r * np.sin(th)) ** 2)
    assert np.allclose(sim.points["C"].velocity[:, 0], v, atol=1e-11)


def test_inverted_slider_crank_guide_angle(ex):
    m = ex("kinematics/inverted_slider_crank.yaml")
    plan = dyads.decompose(build_system(m))
    assert [s.kind for s in plan.steps] == ["drive_R", "RPR"]
    for method in ("assur", "newton"):
        sim = simulate(m, {"A": input_grid(0, 360, 15)}, points=["B", "T"], method=method)
        B = sim.points["B"].position
        T = sim.points["T"].position
        th = np.radians(sim.inputs["A"])
        assert np.allclose(B, 1.2 * np.stack([np.cos(th), np.sin(th)], 1), atol=1e-12)
        # the guide (through C = (3, 0) and T) passes through the block B
        d1, d2 = B - [3, 0], T - [3, 0]
        assert np.allclose(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0], 0, atol=1e-11)
        assert np.allclose(np.linalg.norm(d2, axis=1), 4.0, atol=1e-12)


def test_cam_roller_follower_lift(ex):
    m = ex("kinematics/cam_roller.yaml")
    sim = simulate(m, {"O": input_grid(0, 360, 10)}, points=["F"])
    assert sim.method == "newton" and sim.assembled.all()
    th = np.radians(sim.inputs["O"] - 90)  # cam rotation from the file's configuration
    e, R, r = 0.3, 1.0, 0.3
    lift = e * np.cos(th) + np.sqrt((R + r) ** 2 - (e * np.sin(th)) ** 2)
    assert np.allclose(sim.points["F"].position[:, 1], lift, atol=1e-11)
    assert any("idle" in n for n in sim.notes)


def test_cam_profile_from_points_matches_disc(ex):
    """A cam given by points on the same disc gives the same lift (spline interpolation)."""
    m = ex("kinematics/cam_roller.yaml")
    from mechsyn.io import mechanism_to_dict
    d = mechanism_to_dict(m)
    t = np.linspace(0, 2 * np.pi, 180, endpoint=False)
    d["joints"][1]["profile"] = np.stack([np.cos(t), 0.3 + np.sin(t)], 1).tolist()
    m2 = mechanism_from_dict(d, "cam_points")
    a = simulate(m, {"O": input_grid(0, 360, 30)}, points=["F"]).points["F"].position
    b = simulate(m2, {"O": input_grid(0, 360, 30)}, points=["F"]).points["F"].position
    assert np.abs(a - b).max() < 1e-6


def test_gear_pair_ratio():
    data = {"name": "gears", "ground": "frame", "links": ["frame", "g1", "g2"],
            "joints": [
                {"id": "O1", "type": "R", "links": ["frame", "g1"], "point": [0, 0], "actuated": True},
                {"id": "O2", "type": "R", "links": ["frame", "g2"], "point": [3, 0]},
                {"id": "G", "type": "gear", "links": ["g1", "g2"], "point": [1, 0]},
            ], "points": {"P": {"link": "g2", "at": [5, 0]}}}
    m = mechanism_from_dict(data, "gears")
    sim = simulate(m, {"O1": input_grid(0, 90, 10)}, points=["P"])
    # external mesh, radii 1 and 2: omega2 = -omega1 / 2
    assert np.allclose(sim.links["g2"].angular_velocity, -0.5, atol=1e-12)
    ang = np.radians(-0.5 * sim.inputs["O1"])
    assert np.allclose(sim.points["P"].position, np.stack([3 + 2 * np.cos(ang), 2 * np.sin(ang)], 1), atol=1e-12)


def test_five_bar_two_inputs(ex):
    m = ex("textbook/five_bar_5r.yaml")
    n = 25
    ua = np.linspace(100, 130, n)
    ue = np.linspace(60, 80, n)
    for method in ("assur", "newton"):
        sim = simulate(m, {"A": ua, "E": ue}, points=["tool", "B", "D"], method=method)
        assert sim.assembled.all()
        B, D, C = (sim.points[k].position for k in ("B", "D", "tool"))
        L1 = np.linalg.norm(np.array([2, 3.5]) - [-0.5, 2])
        L2 = np.linalg.norm(np.array([2, 3.5]) - [4.5, 2])
        assert np.allclose(np.linalg.norm(C - B, axis=1), L1, atol=1e-12)
        assert np.allclose(np.linalg.norm(C - D, axis=1), L2, atol=1e-12)
        rB = np.hypot(-0.5, 2)
        assert np.allclose(B, rB * np.stack([np.cos(np.radians(ua)), np.sin(np.radians(ua))], 1), atol=1e-12)


@pytest.mark.parametrize("name", ["watt_sixbar", "stephenson_sixbar"])
def test_sixbars_keep_their_links_rigid(ex, name):
    """Every link of a six-bar's closed-form sweep keeps its joint distances, and the two
    links of each joint put it at one point (the engines' agreement with each other is
    the conformance suite's, tests/kinematics/test_conformance.py)."""
    m = ex(f"textbook/{name}.yaml")
    plan = dyads.decompose(build_system(m))
    assert [s.kind for s in plan.steps] == ["drive_R", "RRR", "RRR"]
    x = input_grid(60, 110, 1)  # within the first working range (the base four-bar is non-Grashof)
    a = simulate(m, {"A": x}, method="assur")
    assert a.assembled.all()
    S = a.system
    q = a.sweep.q
    for link in S.links:
        js = m.joints_of(link)
        i = S.index(link)
        P = [S.point(q, i, S.to_local(link, j.point)) for j in js]
        for u in range(len(P)):
            for v in range(u + 1, len(P)):
                d0 = np.linalg.norm(js[u].point - js[v].point)
                assert np.allclose(np.linalg.norm(P[u] - P[v], axis=1), d0, atol=1e-12)
        # and the other link of each joint has the same point
        for j in js:
            o = j.other(link)
            Po = S.point(q, S.index(o), S.to_local(o, j.point))
            assert np.allclose(Po, S.point(q, i, S.to_local(link, j.point)), atol=1e-11)


def test_assur_equals_newton_random_fourbars():
    rng = np.random.default_rng(4)
    for _ in range(5):
        a = rng.uniform(0.5, 1.0)
        b, c, g = rng.uniform(2.5, 4, 3)
        m = fourbar(a=a, b=b, c=c, g=g, theta=rng.uniform(0, 360), branch=rng.choice([-1, 1]))
        x = input_grid(0, 360, 20)
        s1 = simulate(m, {"A": x}, points=["M"], method="assur")
        s2 = simulate(m, {"A": x}, points=["M"], method="newton")
        assert np.array_equal(s1.assembled, s2.assembled)
        ok = s1.assembled
        # the continuous part before any dead point is the same branch
        first_gap = np.argmin(ok) if not ok.all() else len(ok)
        sl = slice(0, first_gap)
        assert np.abs(s1.points["M"].position[sl] - s2.points["M"].position[sl]).max() < 1e-10


def scotch_yoke():
    """Scotch yoke: crank pin B drives a block sliding vertically in a yoke that slides
    horizontally on the frame (dyad R-P-P): yoke x = r cos(theta) + const."""
    return mechanism_from_dict({
        "name": "Scotch yoke", "ground": "frame", "links": ["frame", "crank", "block", "yoke"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
            {"id": "B", "type": "R", "links": ["crank", "block"], "point": [0.6, 0.8]},
            {"id": "S1", "type": "P", "links": ["block", "yoke"], "point": [0.6, 0.8], "axis": [0, 1]},
            {"id": "S2", "type": "P", "links": ["frame", "yoke"], "point": [0.6, -1.5], "axis": [1, 0]},
        ], "points": {"Y": {"link": "yoke", "at": [0.6, -1.5]}}}, "yoke")


def crank_guide_prp():
    """A crank carrying a guide; a block slides on it, pinned to a vertical slider at x = 2
    (dyad P-R-P): the pin is at (2, 2 tan(theta))."""
    return mechanism_from_dict({
        "name": "crank guide", "ground": "frame", "links": ["frame", "crank", "block", "slider"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
            {"id": "G", "type": "P", "links": ["crank", "block"], "point": [2, 1], "axis": [2, 1]},
            {"id": "B", "type": "R", "links": ["block", "slider"], "point": [2, 1]},
            {"id": "V", "type": "P", "links": ["frame", "slider"], "point": [2, 1], "axis": [0, 1]},
        ]}, "prp")


@pytest.mark.parametrize("method", ["assur", "newton"])
def test_scotch_yoke_rpp(method):
    m = scotch_yoke()
    assert [s.kind for s in dyads.decompose(build_system(m)).steps] == ["drive_R", "RPP"]
    sim = simulate(m, {"A": input_grid(0, 360, 15)}, points=["Y", "B"], method=method)
    th = np.radians(sim.inputs["A"])
    assert np.allclose(sim.points["Y"].position[:, 0], np.cos(th), atol=1e-12)
    assert np.allclose(sim.points["Y"].position[:, 1], -1.5, atol=1e-12)
    assert np.allclose(sim.points["Y"].velocity[:, 0], -np.sin(th), atol=1e-12)
    assert np.allclose(sim.points["Y"].acceleration[:, 0], -np.cos(th), atol=1e-12)


@pytest.mark.parametrize("method", ["assur", "newton"])
def test_crank_guide_prp(method):
    m = crank_guide_prp()
    assert [s.kind for s in dyads.decompose(build_system(m)).steps] == ["drive_R", "PRP"]
    sim = simulate(m, {"A": input_grid(0, 60, 5)}, points=["B"], method=method)
    th = np.radians(sim.inputs["A"])
    assert np.allclose(sim.points["B"].position, np.stack([np.full_like(th, 2), 2 * np.tan(th)], 1), atol=1e-12)
    assert np.allclose(sim.points["B"].velocity[:, 1], 2 / np.cos(th) ** 2, atol=1e-11)


@pytest.mark.parametrize("method", ["assur", "newton"])
def test_slider_driven_slider_crank(ex, method):
    """Driven by the slider (a P input, in length units): the crank angle follows from
    the law of cosines, cos(theta) = (x^2 + r^2 - l^2) / (2 r x)."""
    from mechsyn.io import mechanism_to_dict

    d = mechanism_to_dict(ex("textbook/slider_crank.yaml"))
    d["joints"][0].pop("actuated")
    d["joints"][3]["actuated"] = True
    m = mechanism_from_dict(d, "slider driven")
    S = build_system(m)
    assert [s.kind for s in dyads.decompose(S).steps] == ["drive_P", "RRR"]
    assert np.isclose(S.drivers[0].assembled, m.joint("D").point[0])  # the slide coordinate is x
    x = np.linspace(3.0, 3.9, 10)
    sim = simulate(m, {"D": x}, points=["B", "C"], method=method)
    assert np.allclose(sim.points["C"].position[:, 0], x, atol=1e-12)
    r, l = 1.0, float(np.linalg.norm(m.joint("C").point - m.joint("B").point))
    th = np.arccos((x ** 2 + r ** 2 - l ** 2) / (2 * r * x))
    assert np.allclose(np.radians(sim.links["crank"].angle), th, atol=1e-10)
    assert np.allclose(sim.points["C"].velocity[:, 0], 1.0, atol=1e-12)  # unit input speed


def test_cam_polar_profile(ex):
    """A cam profile given as a function r(t): r = 1 about the disc's centre is the disc;
    a harmonic cam r = 1 + 0.1 cos(2 t) keeps the roller on its offset curve."""
    from mechsyn.errors import MechsynInputError
    from mechsyn.io import mechanism_to_dict

    d = mechanism_to_dict(ex("kinematics/cam_roller.yaml"))
    d["joints"][1]["profile"] = {"center": [0, 0.3], "polar": "1 + 0*sin(t)"}
    m = mechanism_from_dict(d, "polar")
    assert mechanism_to_dict(m)["joints"][1]["profile"] == {"center": [0.0, 0.3], "polar": "1 + 0*sin(t)"}
    a = simulate(ex("kinematics/cam_roller.yaml"), {"O": input_grid(0, 360, 30)}, points=["F"]).points["F"]
    b = simulate(m, {"O": input_grid(0, 360, 30)}, points=["F"]).points["F"]
    assert np.abs(a.position - b.position).max() < 1e-6
    for bad, msg in (("import os", "cannot parse"), ("__import__('os')", "not allowed"), ("1 - 2", "positive"),
                     ("x + 1", "unknown name")):
        d["joints"][1]["profile"] = {"center": [0, 0.3], "polar": bad}
        with pytest.raises(MechsynInputError, match=msg):
            mechanism_from_dict(d, "bad")
    d["joints"][1]["profile"] = {"center": [0, 0.3]}
    with pytest.raises(MechsynInputError, match="radius or polar"):
        mechanism_from_dict(d, "bad")
