"""Kinetostatics checked by the balance of virtual power, computed independently."""

import numpy as np
import pytest

from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.analysis import input_grid
from mechsyn.kinetostatics import forces
from mechsyn.kinetostatics.reactions import loads_from_file, mass_model
from mechsyn.kinematics.plane import cross

from kinematics_helpers import ex, fourbar_dict, point_state  # noqa: F401


def power_residual(fa):
    """sum(drive effort * input rate) + power of loads, gravity and inertia; and a scale."""
    sim = fa.simulation
    S, sw = sim.system, sim.sweep
    ok = sim.assembled
    q, qd, qdd = (np.nan_to_num(a) for a in (sw.q, sw.qd, sw.qdd))
    mm = mass_model(S)
    loads = loads_from_file(S, mm)
    g = np.asarray(fa.gravity)
    terms = []
    for i, name in enumerate(S.links):
        _, vG, aG = point_state(S, q, qd, qdd, i, mm.com[i])
        w, al = qd[:, 3 * i + 2], qdd[:, 3 * i + 2]
        terms.append(mm.mass[i] * (vG @ g))
        if not fa.static:  # the static case has no inertia loads
            terms.append(-mm.mass[i] * np.sum(aG * vG, axis=1))
            terms.append(-mm.inertia[i] * al * w)
    for k in range(len(loads.link)):
        i = loads.link[k]
        _, vP, _ = point_state(S, q, qd, qdd, i, loads.at[k])
        terms.append(vP @ loads.force[k] + loads.moment[k] * qd[:, 3 * i + 2])
    for k, d in enumerate(S.drivers):
        if d.joint in fa.reactions.effort:
            terms.append(fa.reactions.effort[d.joint] * sw.speeds[k])
    T = np.array(terms)
    return T.sum(axis=0)[ok], np.abs(T).sum(axis=0)[ok]


@pytest.mark.parametrize("gravity, static", [((0, -9.81), False), ((0, 0), False), ((0, -9.81), True)])
def test_virtual_work_crank_rocker(ex, gravity, static):
    m = ex("kinematics/crank_rocker.yaml")
    fa = forces(m, {"A": input_grid(0, 360, 10)}, speeds={"A": 3.0}, gravity=gravity, static=static)
    res, scale = power_residual(fa)
    assert np.all(np.abs(res) <= 1e-9 * scale)
    assert not fa.reactions.indeterminate


@pytest.mark.parametrize("rel, inp, vll", [
    ("textbook/slider_crank.yaml", {"A": input_grid(0, 360, 20)}, None),
    ("kinematics/inverted_slider_crank.yaml", {"A": input_grid(0, 360, 20)}, None),
    ("kinematics/cam_roller.yaml", {"O": input_grid(0, 360, 20)}, None),
    ("kinematics/cam_polar.yaml", {"O": input_grid(0, 360, 20)}, None),
    ("textbook/watt_sixbar.yaml", {"A": input_grid(60, 110, 5)}, None),
    ("textbook/stephenson_sixbar.yaml", {"A": input_grid(60, 110, 5)}, None),
    ("textbook/five_bar_5r.yaml", {"A": np.linspace(100, 120, 6), "E": np.linspace(60, 75, 6)}, None),
    ("fingers/two_phalanx_vll_000.yaml", {"E": input_grid(-10, 40, 5)}, None),
    ("fingers/two_phalanx_vll_000.yaml", {"E": input_grid(-10, 40, 5), "S": np.linspace(28, 26, 11)},
     {"S": "free"}),
])
def test_virtual_work_examples(ex, rel, inp, vll):
    from mechsyn.io import mechanism_to_dict

    d = mechanism_to_dict(ex(rel))
    # give every link a mass, an inertia and a load so that every term works
    rng = np.random.default_rng(1)
    links = []
    for k, ln in enumerate(d["links"]):
        name = ln if isinstance(ln, str) else ln["name"]
        if name == d["ground"]:
            links.append(ln)
            continue
        links.append({"name": name, "mass": float(rng.uniform(0.5, 2)), "inertia": float(rng.uniform(0.1, 1))})
    d["links"] = links
    movers = [x["name"] for x in links if isinstance(x, dict)]
    d["loads"] = [{"link": movers[-1], "force": [1.0, -2.0], "moment": 0.7},
                  {"link": movers[0], "moment": -0.4}]
    m = mechanism_from_dict(d, rel)
    fa = forces(m, inp, gravity=(0, -9.81), vll=vll, speeds={j: 1.7 for j in inp})
    res, scale = power_residual(fa)
    assert fa.simulation.assembled.all()
    assert np.all(np.abs(res) <= 1e-9 * scale)


def test_pendulum_reaction_and_torque():
    """A crank of mass m held by its motor: reaction m g up, torque m g x_G (statics by hand)."""
    d = {"name": "pendulum", "ground": "frame",
         "links": ["frame", {"name": "arm", "mass": 2.0, "com": [0.5, 0.0], "inertia": 0.1}],
         "joints": [{"id": "A", "type": "R", "links": ["frame", "arm"], "point": [0, 0], "actuated": True},
                    {"id": "T", "type": "R", "links": ["arm", "frame"], "point": [1, 0]}]}
    # the second joint would close a loop: use a single-joint arm instead
    d["joints"] = d["joints"][:1]
    d["links"][1]["com"] = [0.5, 0.0]
    d["points"] = {"tip": {"link": "arm", "at": [1, 0]}}
    m = mechanism_from_dict(d, "pendulum")
    x = input_grid(0, 90, 30)
    fa = forces(m, {"A": x}, gravity=(0, -9.81), static=True)
    F = fa.reactions.force["A"]
    assert np.allclose(F, [[0, 2 * 9.81]] * len(x), atol=1e-12)
    tau = fa.reactions.effort["A"]
    assert np.allclose(tau, 2 * 9.81 * 0.5 * np.cos(np.radians(x)), atol=1e-12)


def test_static_fourbar_moment_balance():
    """Static four-bar with a moment M on the rocker: tau = -M omega_rocker / omega_crank."""
    data = fourbar_dict(extra={"loads": [{"link": "rocker", "moment": 5.0}]})
    m = mechanism_from_dict(data, "fb")
    fa = forces(m, {"A": input_grid(0, 360, 15)}, static=True)
    w = fa.simulation.links["rocker"].angular_velocity
    assert np.allclose(fa.reactions.effort["A"], -5.0 * w, atol=1e-12)
    # the rocker is a two-force member: the reaction at D is along the rocker
    sim = fa.simulation
    F = fa.reactions.force["D"]
    S = sim.system
    q = sim.sweep.q
    C = S.point(q, S.index("rocker"), S.to_local("rocker", m.joint("C").point))
    D = m.joint("D").point
    # with a moment on the rocker it is not a two-force member; the coupler is: force at C along BC
    B = S.point(q, S.index("coupler"), S.to_local("coupler", m.joint("B").point))
    Fc = fa.reactions.force["C"]
    assert np.allclose(cross(Fc, C - B), 0, atol=1e-10)
    assert np.isfinite(F).all() and np.isfinite(D).all()


def test_loads_schema_errors():
    from mechsyn.errors import MechsynInputError

    d = fourbar_dict(extra={"loads": [{"link": "rocker"}]})
    with pytest.raises(MechsynInputError, match="force or a moment"):
        mechanism_from_dict(d, "x")
    d = fourbar_dict(extra={"loads": [{"link": "rocker", "force": [1, 0], "point": "M"}]})
    with pytest.raises(MechsynInputError, match="on link coupler"):
        mechanism_from_dict(d, "x")
    d = fourbar_dict(extra={"loads": [{"link": "nope", "moment": 1}]})
    with pytest.raises(MechsynInputError, match="unknown link"):
        mechanism_from_dict(d, "x")


def geared_five_bar():
    """A geared five-bar: two meshing gears on the frame each carry a crank pin."""
    return {"name": "geared five-bar", "ground": "frame",
            "links": ["frame", {"name": "g1", "mass": 1.0, "inertia": 0.3},
                      {"name": "g2", "mass": 2.0, "inertia": 0.8},
                      {"name": "l1", "mass": 0.7, "inertia": 0.4}, {"name": "l2", "mass": 0.6, "inertia": 0.3}],
            "joints": [
                {"id": "O1", "type": "R", "links": ["frame", "g1"], "point": [0, 0], "actuated": True},
                {"id": "O2", "type": "R", "links": ["frame", "g2"], "point": [3, 0]},
                {"id": "G", "type": "gear", "links": ["g1", "g2"], "point": [1, 0]},
                {"id": "P1", "type": "R", "links": ["g1", "l1"], "point": [0, 0.8]},
                {"id": "P2", "type": "R", "links": ["g2", "l2"], "point": [3, 1.5]},
                {"id": "Q", "type": "R", "links": ["l1", "l2"], "point": [1.6, 3.2]},
            ],
            "loads": [{"link": "l2", "force": [0.3, -1.0], "at": [1.6, 3.2]}]}


def test_virtual_work_geared_five_bar():
    m = mechanism_from_dict(geared_five_bar(), "geared")
    # g1's reference line runs from O1 to the pitch point G: the file is at input 0
    fa = forces(m, {"O1": input_grid(-20, 20, 5)}, gravity=(0, -9.81), speeds={"O1": 2.0})
    assert fa.simulation.method == "newton" and fa.simulation.assembled.all()
    assert np.allclose(fa.simulation.links["g2"].angular_velocity, -1.0)  # ratio -r1/r2 = -1/2
    res, scale = power_residual(fa)
    assert np.all(np.abs(res) <= 1e-9 * scale)
    # the teeth only push: the reaction moment about the pitch point vanishes
    assert np.allclose(fa.reactions.moment["G"], 0, atol=1e-9 * scale.max())


FREE_BODY_CASES = [
    ("kinematics/crank_rocker.yaml", {"A": input_grid(0, 360, 30)}, None),
    ("textbook/slider_crank.yaml", {"A": input_grid(0, 360, 30)}, None),
    ("kinematics/inverted_slider_crank.yaml", {"A": input_grid(0, 360, 30)}, None),
    ("kinematics/cam_roller.yaml", {"O": input_grid(0, 360, 30)}, None),
    ("fingers/two_phalanx_vll_000.yaml", {"E": input_grid(-10, 40, 10)}, None),
    ("geared", {"O1": input_grid(-20, 20, 10)}, None),
]


@pytest.mark.parametrize("rel, inp, vll", FREE_BODY_CASES)
def test_every_link_is_in_equilibrium(ex, rel, inp, vll):
    """Free body of every moving link: joint forces + loads + gravity + inertia = 0 (forces
    and moments about the origin), with the reported reactions (first link on second)."""
    from mechsyn.io import mechanism_to_dict

    if rel == "geared":
        m = mechanism_from_dict(geared_five_bar(), "geared")
    else:
        d = mechanism_to_dict(ex(rel))
        d["links"] = [ln if (ln if isinstance(ln, str) else ln["name"]) == d["ground"] else
                      {"name": ln if isinstance(ln, str) else ln["name"], "mass": 1.0 + k, "inertia": 0.2 * k}
                      for k, ln in enumerate(d["links"])]
        m = mechanism_from_dict(d, rel)
    g = (0.0, -9.81)
    fa = forces(m, inp, gravity=g, speeds={j: 1.5 for j in inp})
    sim = fa.simulation
    S, sw = sim.system, sim.sweep
    q, qd, qdd = sw.q, sw.qd, sw.qdd
    mm = mass_model(S)
    loads = loads_from_file(S, mm)
    R = fa.reactions
    for i, name in enumerate(S.links):
        Fsum = np.zeros((len(q), 2))
        Msum = np.zeros(len(q))
        PG, _, aG = point_state(S, q, qd, qdd, i, mm.com[i])
        Fi = mm.mass[i] * (np.asarray(g) - aG)
        Fsum += Fi
        Msum += cross(PG, Fi) - mm.inertia[i] * qdd[:, 3 * i + 2]
        for k in range(len(loads.link)):
            if loads.link[k] == i:
                P = S.point(q, i, loads.at[k])
                Fsum += loads.force[k]
                Msum += cross(P, np.broadcast_to(loads.force[k], P.shape)) + loads.moment[k]
        for j in m.joints_of(name):
            sign = 1.0 if j.links[1] == name else -1.0  # reported: on the second link by the first
            side = S.index(j.links[1]) if S.index(j.links[1]) >= 0 else S.index(j.links[0])
            side_name = S.links[side]
            P = S.point(q, side, S.to_local(side_name, j.point))
            if j.type == "gear":  # the tooth force acts at the pitch point (the carrier is the frame)
                P = np.broadcast_to(j.point, P.shape)
            F = sign * R.force[j.id]
            Fsum += F
            Msum += cross(P, F) + sign * R.moment[j.id]
            if j.id in R.effort and j.type == "R":
                Msum += sign * R.effort[j.id]
        scale = np.abs(Fi).max() + 1.0
        assert np.abs(Fsum).max() < 1e-9 * scale * 10, (name, np.abs(Fsum).max())
        assert np.abs(Msum).max() < 1e-8 * scale * 10 * S.scale, (name, np.abs(Msum).max())
