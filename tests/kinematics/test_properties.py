"""Property tests: random four-bars, closed form = Newton, rates = differences, power balance."""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics import derived
from mechsyn.kinematics.analysis import simulate
from mechsyn.kinetostatics import forces
from mechsyn.kinematics.solve import assemble, newton
from mechsyn.kinematics.system import build_system

from kinematics_helpers import fourbar_dict, point_state

lengths = st.floats(0.5, 4.0)


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(a=lengths, b=lengths, c=lengths, g=lengths, theta=st.floats(0, 360), branch=st.sampled_from([-1, 1]),
       dtheta=st.floats(-30, 30))
def test_random_fourbar(a, b, c, g, theta, branch, dtheta):
    # only four-bars that assemble at theta
    B = a * np.array([np.cos(np.radians(theta)), np.sin(np.radians(theta))])
    L = np.linalg.norm(np.array([g, 0.0]) - B)
    if not (abs(b - c) + 1e-3 < L < b + c - 1e-3):
        return
    d = fourbar_dict(a=a, b=b, c=c, g=g, theta=theta, branch=branch)
    d["links"] = ["frame", {"name": "crank", "mass": 1.0, "inertia": 0.1},
                  {"name": "coupler", "mass": 2.0, "inertia": 0.5}, {"name": "rocker", "mass": 1.5, "inertia": 0.3}]
    d["loads"] = [{"link": "rocker", "moment": 1.0}, {"link": "coupler", "force": [0.2, -0.5], "point": "M"}]
    m = mechanism_from_dict(d, "random four-bar")
    scale = max(a, b, c, g)
    # compare the methods only on a motion that stays clear of singular configurations
    # (toggles: transmission angle near 0 or 180 degrees; B passing over D)
    fine = np.linspace(theta, theta + dtheta, 50)
    s0 = simulate(m, {"A": fine}, points=["B"], method="assur")
    mu = derived.transmission_angles(s0)["B-C-D"]
    BD = np.linalg.norm(s0.points["B"].position - [g, 0.0], axis=1)
    if s0.assembled.all() and np.all((mu > 8) & (mu < 172)) and BD.min() > 0.05 * scale:
        x = np.array([theta, theta + dtheta])
        s1 = simulate(m, {"A": x}, points=["M"], method="assur")
        s2 = simulate(m, {"A": x}, points=["M"], method="newton")
        assert s1.assembled.all() and s2.assembled.all()
        assert np.abs(s1.points["M"].position - s2.points["M"].position).max() < 1e-9 * scale
    # rates against central differences at the file's configuration
    S = build_system(m)
    q = assemble(S)
    J = S.jacobian(q[None])[0]
    if np.linalg.cond(J) > 1e6:
        return
    (qd,), (qdd,) = S.rates(q[None], np.ones(1))
    h = 1e-6
    u0 = np.array([S.drivers[0].assembled])
    qp, okp = newton(S, q + h * qd, u0 + h)
    qm, okm = newton(S, q - h * qd, u0 - h)
    assert okp and okm
    assert np.abs((qp - qm) / (2 * h) - qd).max() <= 1e-6 * max(1.0, np.abs(qd).max())
    (vp,), (_,) = S.rates(qp[None], np.ones(1))
    (vm,), (_,) = S.rates(qm[None], np.ones(1))
    assert np.abs((vp - vm) / (2 * h) - qdd).max() <= 1e-5 * max(1.0, np.abs(qdd).max())
    # power balance: drive power + power of loads, gravity and inertia = 0
    fa = forces(m, {"A": np.array([theta])}, gravity=(0, -9.81))
    sim = fa.simulation
    Ss, sw = sim.system, sim.sweep
    from mechsyn.kinetostatics.reactions import loads_from_file, mass_model

    mm = mass_model(Ss)
    ld = loads_from_file(Ss, mm)
    terms = [fa.reactions.effort["A"] * 1.0]
    for i in range(len(Ss.links)):
        _, vG, aG = point_state(Ss, sw.q, sw.qd, sw.qdd, i, mm.com[i])
        terms.append(mm.mass[i] * (vG @ np.array([0, -9.81])) - mm.mass[i] * np.sum(aG * vG, axis=1)
                     - mm.inertia[i] * sw.qdd[:, 3 * i + 2] * sw.qd[:, 3 * i + 2])
    for k in range(len(ld.link)):
        i = ld.link[k]
        _, vP, _ = point_state(Ss, sw.q, sw.qd, sw.qdd, i, ld.at[k])
        terms.append(vP @ ld.force[k] + ld.moment[k] * sw.qd[:, 3 * i + 2])
    T = np.array(terms)
    assert np.abs(T.sum(axis=0)).max() <= 1e-9 * np.abs(T).sum(axis=0).max()
