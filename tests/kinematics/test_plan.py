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
