"""The belt pair in the general planar solver against paper 001's closed form.

Issue 5: "the general planar solver, given the same mechanism as a file, agrees with the
closed form; a belt wrap is a pair whose relative rotation follows the free belt length".
The closed form (``kinematics/belt.py``) follows the spec's corrected equations, not the
paper's printed (4), (9), (13), (14); the general solver knows nothing of them: it only
keeps the belt length ``b + r·(wrapped angle)`` constant.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from mechsyn.cli.main import main
from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism, mechanism_from_dict, mechanism_to_dict
from mechsyn.kinematics.analysis import simulate
from mechsyn.belt import BeltDesign, analyze
from mechsyn.kinematics.system import build_system
from mechsyn.model.pairs import PAIR_KINDS, belt_tangent, canonical_pair_type
from mechsyn.structure.analysis import analyze_structure

from kinematics_helpers import EX

FILE = EX / "belt" / "paper001_mechanism.yaml"
PAPER = BeltDesign(a=500.0, c=350.0, h=100.0, r=75.0)
DPHI = np.arange(-73.0, 85.0 + 1e-9, 1.0)       # the paper's range, degrees
RTOL = 1e-8


def _close(got, want, rtol=RTOL):
    """Agreement relative to the size of the closed-form curve (no division by ~0)."""
    scale = np.abs(want).max()
    assert np.all(np.isfinite(got))
    assert np.abs(got - want).max() <= rtol * scale, np.abs(got - want).max() / scale


def belt_dict(design: BeltDesign, dphi0_deg: float = 0.0, wrap: str = "ccw") -> dict:
    """Paper 001's manipulator as a mechanism file, assembled at Δφ = dphi0 (closed form).

    ``wrap="cw"``: the mirror image about the y axis (x -> -x): the belt then turns
    clockwise round the pulley.
    """
    st = analyze(design, np.radians([dphi0_deg]))
    m = np.array([1.0, 1.0]) if wrap == "ccw" else np.array([-1.0, 1.0])
    f = lambda p: [float(x) for x in np.asarray(p).ravel() * m]  # noqa: E731
    return {
        "name": f"belt manipulator ({wrap})", "kind": "planar", "ground": "frame",
        "links": ["frame", "lever", "hand"],
        "joints": [
            {"id": "A0", "type": "R", "links": ["frame", "lever"], "point": [0.0, 0.0], "actuated": True},
            {"id": "A", "type": "R", "links": ["lever", "hand"], "point": f(st.A)},
            {"id": "W", "type": "belt", "links": ["frame", "hand"], "point": f(st.A),
             "anchor": f(design.B0), "radius": design.r, "wrap": wrap},
        ],
        "points": {"C": {"link": "hand", "at": f(st.C)}, "H": {"link": "hand", "at": f(st.H)}},
    }


# ------------------------------------------------------------------------ the file
def test_paper_file_agrees_with_closed_form_over_the_paper_range():
    mech = load_mechanism(FILE)
    sim = simulate(mech, {"A0": 90.0 + DPHI}, points=["C", "H"])   # lever on +y at Δφ = 0
    assert sim.method == "newton" and bool(np.all(sim.sweep.assembled))
    st = analyze(PAPER, np.radians(DPHI))
    # unit input speed: time derivatives = derivatives with respect to Δφ (rad)
    for P in "CH":
        pm = sim.points[P]
        _close(pm.position, getattr(st, P))
        _close(pm.velocity, getattr(st, P + "1"))
        _close(pm.acceleration, getattr(st, P + "2"))
    # link 2's absolute angle is θ = Δφ + Δψ: the relative rotation follows the belt
    hand = sim.links["hand"]
    _close(np.radians(hand.angle), st.theta)
    _close(hand.angular_velocity, 1.0 + st.psi1)
    _close(hand.angular_acceleration, st.psi2)


def test_paper_file_design_position_identities():
    # spec: ψ'(0) = -1 (link 2 translates), C''(0) = (0, 0), H''(0) = (a h / c, 0)
    sim = simulate(load_mechanism(FILE), {"A0": [90.0]}, points=["C", "H"])
    a, c, h = PAPER.a, PAPER.c, PAPER.h
    assert abs(sim.links["hand"].angular_velocity[0]) < 1e-9
    assert np.allclose(sim.points["C"].acceleration[0], [0.0, 0.0], atol=1e-8 * a)
    assert np.allclose(sim.points["H"].acceleration[0], [a * h / c, 0.0], rtol=1e-9, atol=1e-8 * a)


def test_paper_file_constants_are_the_closed_forms():
    mech = load_mechanism(FILE)
    W = mech.joint("W")
    assert np.allclose(W.attrs["anchor"], PAPER.B0, rtol=0, atol=1e-12)   # B0 = (r, a - b0)
    assert W.attrs["radius"] == PAPER.r and W.attrs["wrap"] == "ccw"
    assert np.allclose(np.linalg.norm(W.attrs["anchor"]), PAPER.l0)
    assert math.isclose(math.degrees(math.atan2(*W.attrs["anchor"][::-1])), math.degrees(PAPER.alpha0))
    # the tangent point of the design position is B = (r, a), the belt runs along +y
    T, g, b = belt_tangent(W.point, np.asarray(W.attrs["anchor"]), 75.0, "ccw")
    assert np.allclose(T, [75.0, 500.0]) and np.allclose(g, [0.0, 1.0]) and math.isclose(b, PAPER.b0)


# ----------------------------------------------------- other designs, positions, senses
@pytest.mark.parametrize("dphi0", [0.0, 35.0, -50.0])
def test_non_design_configuration_and_dimensions(dphi0):
    # another design, the file drawn away from the design position: the solver must find
    # the same motion from the belt length alone
    design = BeltDesign(a=420.0, c=260.0, h=-60.0, r=55.0)
    mech = mechanism_from_dict(belt_dict(design, dphi0))
    dphi = np.arange(-60.0, 80.0 + 1e-9, 2.0)
    sim = simulate(mech, {"A0": 90.0 + dphi})
    assert bool(np.all(sim.sweep.assembled))
    st = analyze(design, np.radians(dphi))
    for P in "CH":
        pm = sim.points[P]
        _close(pm.position, getattr(st, P))
        _close(pm.velocity, getattr(st, P + "1"))
        _close(pm.acceleration, getattr(st, P + "2"))


def test_clockwise_wrap_is_the_mirror_image():
    # mirror x -> -x: lever angle 90 + Δφ becomes 90 - Δφ; the belt turns clockwise.
    # Derivatives with respect to the mirrored input (= -Δφ): first ones change sign.
    mech = mechanism_from_dict(belt_dict(PAPER, 10.0, wrap="cw"))
    assert mech.joint("W").attrs["wrap"] == "cw"
    sim = simulate(mech, {"A0": 90.0 - DPHI})
    st = analyze(PAPER, np.radians(DPHI))
    mx = np.array([-1.0, 1.0])
    for P in "CH":
        pm = sim.points[P]
        _close(pm.position, getattr(st, P) * mx)
        _close(pm.velocity, -getattr(st, P + "1") * mx)
        _close(pm.acceleration, getattr(st, P + "2") * mx)
    # the hand's reference line is its attitude in the file (drawn at Δφ = 10°)
    theta_file = analyze(PAPER, np.radians([10.0])).theta[0]
    _close(np.radians(sim.links["hand"].angle), -(st.theta - theta_file))


def test_wrong_wrap_sense_is_a_different_mechanism():
    # the ccw file with wrap: cw would wind the belt the other way: not the closed form
    d = belt_dict(PAPER)
    d["joints"][2]["wrap"] = "cw"
    sim = simulate(mechanism_from_dict(d), {"A0": 90.0 + np.array([-30.0, 30.0])})
    st = analyze(PAPER, np.radians([-30.0, 30.0]))
    assert np.abs(sim.points["C"].position - st.C).max() > 10.0


def test_anchor_on_a_moving_link_by_kinematic_inversion():
    # hold the lever and let the frame turn: the anchor B0 is then on a moving link. In the
    # lever's frame the points are R(-Δφ) C(Δφ); derivatives by the product rule:
    # C_L' = R(-Δφ)(C' - J C), C_L'' = R(-Δφ)(C'' - 2 J C' - C), J = rotation by +90°.
    d = belt_dict(PAPER)
    d["ground"] = "lever"
    mech = mechanism_from_dict(d)
    u0 = math.degrees(build_system(mech).drivers[0].assembled)
    dphi = np.arange(-70.0, 80.0 + 1e-9, 5.0)
    sim = simulate(mech, {"A0": u0 + dphi})
    st = analyze(PAPER, np.radians(dphi))
    ang = -np.radians(dphi)

    def R(v):
        c, s = np.cos(ang), np.sin(ang)
        return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], axis=-1)

    def J(v):
        return np.stack([-v[:, 1], v[:, 0]], axis=-1)

    for P in "CH":
        X, X1, X2 = getattr(st, P), getattr(st, P + "1"), getattr(st, P + "2")
        pm = sim.points[P]
        _close(pm.position, R(X))
        _close(pm.velocity, R(X1 - J(X)))
        _close(pm.acceleration, R(X2 - 2 * J(X1) - X))


# ------------------------------------------------------------- finite differences
def _two_moving_links_system(wrap: str):
    # a belt anchored on a moving link (carrier) wrapping a pulley on another (wheel)
    d = {
        "name": "belt between moving links", "ground": "frame",
        "links": ["frame", "carrier", "wheel"],
        "joints": [
            {"id": "O", "type": "R", "links": ["frame", "carrier"], "point": [0.0, 0.0], "actuated": True},
            {"id": "Q", "type": "R", "links": ["frame", "wheel"], "point": [3.0, 1.0], "actuated": True},
            {"id": "W", "type": "belt", "links": ["carrier", "wheel"], "point": [3.0, 1.0],
             "anchor": [0.5, 0.8], "radius": 0.7, "wrap": wrap},
        ],
    }
    return build_system(mechanism_from_dict(d))


@pytest.mark.parametrize("wrap", ["ccw", "cw"])
def test_belt_jacobian_and_gamma_by_finite_differences(wrap):
    S = _two_moving_links_system(wrap)
    rng = np.random.default_rng(5)
    rows = S.rows_of("W")
    assert len(rows) == 1
    u = np.zeros((1, len(S.drivers)))
    for _ in range(5):
        q = S.q0 + 0.2 * rng.standard_normal(S.n)
        qd = rng.standard_normal(S.n)
        J = S.jacobian(q[None])[0][rows]
        h = 1e-6
        Jfd = np.array([(S.residual((q + h * e)[None], u)[0] - S.residual((q - h * e)[None], u)[0])[rows] / (2 * h)
                        for e in np.eye(S.n)]).T
        np.testing.assert_allclose(J, Jfd, rtol=1e-7, atol=1e-8)
        # gamma = -(d/dt Phi_q) q' = -(second derivative of Phi along q + t q')
        h = 1e-4
        f = lambda t: S.residual((q + t * qd)[None], u)[0][rows]  # noqa: E731
        d2 = (f(h) - 2 * f(0.0) + f(-h)) / h ** 2
        g = S.gamma(q[None], qd[None])[0][rows]
        np.testing.assert_allclose(g, -d2, rtol=1e-5, atol=1e-6)


def test_rates_by_finite_differences_of_the_sweep():
    sim = simulate(load_mechanism(FILE), {"A0": 90.0 + np.linspace(-40.0, 40.0, 801)})   # 0.1° steps
    h = math.radians(0.1)
    for P in "CH":
        pm = sim.points[P]
        v_fd = (pm.position[2:] - pm.position[:-2]) / (2 * h)
        a_fd = (pm.position[2:] - 2 * pm.position[1:-1] + pm.position[:-2]) / h ** 2
        _close(v_fd, pm.velocity[1:-1], rtol=1e-5)
        _close(a_fd, pm.acceleration[1:-1], rtol=1e-4)


def test_belt_length_is_kept():
    # b + σ r (φ_hand - τ) is the same in every solved pose (τ: tangent angle)
    mech = load_mechanism(FILE)
    sim = simulate(mech, {"A0": 90.0 + DPHI}, points=["A"])
    A = sim.points["A"].position
    B0 = np.asarray(mech.joint("W").attrs["anchor"])
    theta = np.unwrap(np.radians(sim.links["hand"].angle))
    lengths = []
    for k in range(len(DPHI)):
        T, g, b = belt_tangent(A[k], B0, 75.0, "ccw")
        tau = math.atan2(T[1] - A[k, 1], T[0] - A[k, 0])
        lengths.append(b + 75.0 * (theta[k] - tau))
    lengths = np.unwrap(np.array(lengths) / 75.0) * 75.0
    assert np.ptp(lengths) < 1e-8 * PAPER.a


# ------------------------------------------------------------------- structure
def test_structure_and_rank_give_mobility_one(capsys):
    mech = load_mechanism(FILE)
    assert mech.joint("W").pair_class == 4 and mech.joint("W").is_higher
    f = analyze_structure(mech)
    assert f.mobility == 1
    code = main(["analyze", str(FILE), "--json"])
    d = json.loads(capsys.readouterr().out)
    assert code == 0
    assert d["mobility"] == 1 and d["pairs_by_class"] in ({"4": 1, "5": 2}, {4: 1, 5: 2})
    assert d["rank"]["mobility"] == 1 and d["rank"]["redundant_constraints"] == 0
    assert d["rank"]["useful_mobility"] == 1


def test_belt_in_the_catalogue():
    assert PAIR_KINDS["belt"].higher and PAIR_KINDS["belt"].planar
    assert canonical_pair_type("chain") == "belt" and canonical_pair_type("Rope") == "belt"


# ------------------------------------------------------------------ file format
def test_round_trip_keeps_the_belt_fields():
    mech = load_mechanism(FILE)
    d = mechanism_to_dict(mech)
    w = next(j for j in d["joints"] if j["id"] == "W")
    assert w["type"] == "belt" and w["wrap"] == "ccw" and w["radius"] == 75.0
    again = mechanism_from_dict(d)
    assert again.joint("W").attrs == mech.joint("W").attrs


@pytest.mark.parametrize("change, words", [
    ({"wrap": None}, "needs `wrap`"),
    ({"anchor": None}, "needs `anchor`"),
    ({"radius": None}, "needs `radius`"),
    ({"point": None}, "needs `point`"),
    ({"anchor": [10.0, 480.0]}, "not outside the radius"),
    ({"wrap": "left"}, None),
    ({"radius": -1.0}, None),
])
def test_bad_belt_fields(change, words):
    d = belt_dict(PAPER)
    w = d["joints"][2]
    for k, v in change.items():
        if v is None:
            del w[k]
        else:
            w[k] = v
    with pytest.raises(MechsynInputError) as exc:
        mechanism_from_dict(d, source="belt.yaml")
    if words:
        assert words in exc.value.message


def test_belt_fields_on_another_pair_are_refused():
    d = belt_dict(PAPER)
    d["joints"][1]["radius"] = 75.0
    with pytest.raises(MechsynInputError, match="only a belt pair"):
        mechanism_from_dict(d)


def test_cli_simulate_runs_the_file_and_bad_file_exits_2(capsys, tmp_path):
    code = main(["simulate", str(FILE), "--input", "A0=17:175:2", "--points", "C,H", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert code == 0 and all(d["assembled"])
    st = analyze(PAPER, np.radians(np.arange(-73.0, 85.0 + 1e-9, 2.0)))
    assert np.allclose(d["points"]["H"]["position"], st.H, rtol=0, atol=1e-8 * PAPER.a)
    bad = tmp_path / "bad.yaml"
    bad.write_text(FILE.read_text().replace("wrap: ccw", "wrap: sideways"))
    assert main(["simulate", str(bad), "--input", "A0=90"]) == 2
    assert "wrap" in capsys.readouterr().err


def test_sweep_stops_where_the_anchor_reaches_the_pulley():
    # a winch: the anchor E (on a crank, |E| = rho) comes within r of the pulley centre Q:
    # the run cannot stay straight and taut (d <= r). The limits satisfy |Q - E(φ)| = r.
    d = {
        "name": "winch", "ground": "frame", "links": ["frame", "carrier", "wheel"],
        "joints": [
            {"id": "O", "type": "R", "links": ["frame", "carrier"], "point": [0, 0], "actuated": True},
            {"id": "Q", "type": "R", "links": ["frame", "wheel"], "point": [3, 1]},
            {"id": "W", "type": "belt", "links": ["carrier", "wheel"], "point": [3, 1],
             "anchor": [-0.5, 0.8], "radius": 2.5, "wrap": "ccw"},
        ],
    }
    sim = simulate(mechanism_from_dict(d), {"O": np.arange(0.0, 360.0, 10.0)})
    ok = sim.sweep.assembled
    assert not ok[0] and ok[10] and not ok[-1]
    rho, Q, r = math.hypot(-0.5, 0.8), np.array([3.0, 1.0]), 2.5
    c = (Q @ Q + rho ** 2 - r ** 2) / (2 * rho * math.hypot(*Q))
    phase = math.degrees(math.atan2(Q[1], Q[0]))
    limits = sorted(((phase + s * math.degrees(math.acos(c))) % 360.0) for s in (1, -1))
    found = sorted(e["input"]["O"] for e in sim.events if e["kind"] == "dead point")
    assert np.allclose([found[0], found[-1]], limits, atol=1e-4)


def test_static_forces_belt_tension_and_virtual_power():
    # a downward load on H (left of A) turns the hand counter-clockwise about A; the belt
    # holds it by a tension along its straight run, pulling the pulley towards B0
    from mechsyn.kinetostatics import forces

    d = mechanism_to_dict(load_mechanism(FILE))
    d["loads"] = [{"link": "hand", "force": [0.0, -100.0], "point": "H"}]
    mech = mechanism_from_dict(d)
    u = 90.0 + np.arange(-70.0, 80.0 + 1e-9, 10.0)
    fa = forces(mech, {"A0": u}, static=True)
    sim = simulate(mech, {"A0": u}, points=["H", "A"])
    F = np.array([0.0, -100.0])
    # virtual power at unit input speed: M_A0 + F . v_H = 0
    M = fa.reactions.effort["A0"]
    vH = sim.points["H"].velocity
    assert np.abs(M + vH @ F).max() <= 1e-9 * np.abs(vH @ F).max()
    # the belt's force on the hand lies along the run: F = -tension * g
    FW, MW = fa.reactions.force["W"], fa.reactions.moment["W"]
    tension = fa.reactions.tension["W"]
    B0 = np.asarray(mech.joint("W").attrs["anchor"])
    for k in range(len(u)):
        A = sim.points["A"].position[k]
        T, g, _ = belt_tangent(A, B0, 75.0, "ccw")
        assert np.allclose(FW[k], -tension[k] * g, atol=1e-9 * abs(tension[k]))
        # about the pulley centre its moment is that of the tension at the tangent point
        assert math.isclose(MW[k], (T - A)[0] * FW[k, 1] - (T - A)[1] * FW[k, 0], rel_tol=1e-9)
    # design position: moments about A, load 100 * c = tension * r
    k0 = int(np.flatnonzero(u == 90.0)[0])
    assert math.isclose(tension[k0], 100.0 * PAPER.c / PAPER.r, rel_tol=1e-12)
    # at Δφ = -70° H is right of A: the load turns the hand clockwise and the belt would
    # have to push; it goes slack there, and the result says so
    assert tension[0] < 0 and np.all(tension[1:] > 0)
    notes = fa.notes()
    assert len(notes) == 1 and "belt W is in compression" in notes[0] and "from 20 to 20" in notes[0]
    assert fa.to_dict()["belts"]["W"]["tension"][k0] == pytest.approx(466.6666666666667)


def test_rank_of_a_belt_in_a_spatial_file_is_a_clear_note(capsys, tmp_path):
    f = tmp_path / "spatial_belt.yaml"
    f.write_text("""name: spatial belt
kind: spatial
ground: frame
links: [frame, lever, hand]
joints:
- {id: A0, type: R, links: [frame, lever], point: [0, 0, 0], axis: [0, 0, 1], actuated: true}
- {id: A, type: R, links: [lever, hand], point: [0, 500, 0], axis: [0, 0, 1]}
- {id: W, type: belt, links: [frame, hand], point: [0, 500, 0], anchor: [75, 88.2, 0], radius: 75, wrap: ccw}
""")
    assert main(["analyze", str(f), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["rank"] is None and "not supported for belt pairs" in d["rank_unavailable"]


def test_belt_mechanism_dict_is_the_example_file_and_the_cli_writes_it(capsys, tmp_path):
    from mechsyn.belt import belt_mechanism_dict

    ex = load_mechanism(FILE)
    gen = mechanism_from_dict(belt_mechanism_dict(PAPER))
    for j in ex.joints:
        g = gen.joint(j.id)
        assert g.type == j.type and g.links == j.links and np.allclose(g.point, j.point, atol=1e-12)
        assert g.attrs.keys() == j.attrs.keys()
    assert np.allclose(gen.joint("W").attrs["anchor"], ex.joint("W").attrs["anchor"], atol=1e-12)
    for name, p in ex.points.items():
        assert gen.points[name].link == p.link and np.allclose(gen.points[name].at, p.at, atol=1e-12)
    out = tmp_path / "design.yaml"
    args = ["belt", "analyze", "--a", "420", "--c", "260", "--h", "80", "--r", "55", "--phi", "-10:10:10"]
    assert main([*args, "--mechanism-file", str(out)]) == 0
    capsys.readouterr()
    design = BeltDesign(a=420.0, c=260.0, h=80.0, r=55.0)
    sim = simulate(load_mechanism(out), {"A0": 90.0 + np.array([-40.0, 0.0, 60.0])})
    st = analyze(design, np.radians([-40.0, 0.0, 60.0]))
    _close(sim.points["H"].position, st.H)
    _close(sim.points["H"].acceleration, st.H2)
