"""The compiled plan and incremental re-simulation (issue 14 §4)."""

from dataclasses import replace

import numpy as np

from mechsyn.kinematics.analysis import compile_plan, input_grid, simulate

from kinematics_helpers import ex  # noqa: F401


def test_with_joint_points_equals_a_fresh_simulation(ex):
    m = ex("textbook/watt_sixbar.yaml")
    plan = compile_plan(m, inputs=("A",))
    moved = {"G": (5.2, 6.1), "C": (4.05, 3.02)}
    x = {"A": input_grid(-60, 300, 3)}
    again = plan.with_joint_points(moved)
    assert again.groups is plan.groups  # the solution plan is reused
    fresh_mech = m.with_joints(tuple(replace(j, point=np.asarray(moved[j.id], float)) if j.id in moved else j
                                     for j in m.joints))
    a, b = again.simulate(x), simulate(fresh_mech, x)
    assert np.array_equal(a.assembled, b.assembled) and (~a.assembled).any()
    for p in b.points:
        assert np.allclose(a.points[p].position, b.points[p].position, equal_nan=True, atol=1e-12)
    assert [(e["index"], e["kind"]) for e in a.events] == [(e["index"], e["kind"]) for e in b.events]
    # and the moved design really differs from the drawn one
    c = plan.simulate(x)
    assert not np.allclose(c.points["P"].position, a.points["P"].position, equal_nan=True)


def jansen(writing):
    """The Jansen leg of examples/kinematics/jansen_leg.yaml with its double joint at the
    knee (P4) written three ways: both pairs on the foot link (the file), a chain
    k-c, c-foot, or a star k-c, k-foot."""
    import yaml

    from mechsyn.io import mechanism_from_dict
    from kinematics_helpers import EX

    d = yaml.safe_load((EX / "kinematics/jansen_leg.yaml").read_text())
    J = {j["id"]: j for j in d["joints"]}
    if writing == "chain":
        J["P4"]["links"], J["P4_2"]["links"] = ["k", "c"], ["c", "ghi"]
    elif writing == "star":
        J["P4"]["links"], J["P4_2"]["links"] = ["k", "c"], ["k", "ghi"]
    return mechanism_from_dict(d, f"jansen-{writing}")


def test_double_joints_decompose_however_written():
    x = {"P0": input_grid(0, 360, 5)}
    ref = simulate(jansen("third"), x, method="newton")
    for writing in ("third", "chain", "star"):
        plan = compile_plan(jansen(writing), inputs=("P0",))
        assert plan.groups is not None and [s.kind for s in plan.groups.steps] == ["drive_R"] + ["RRR"] * 3
        sim = plan.simulate(x)
        assert sim.method == "assur" and sim.assembled.all() and not sim.events
        assert np.abs(sim.points["foot"].position - ref.points["foot"].position).max() < 1e-9
        assert np.abs(sim.points["foot"].velocity - ref.points["foot"].velocity).max() < 1e-8
