"""Dead points of a non-Grashof four-bar are reported, never hidden."""

import numpy as np
import pytest

from mechsyn.kinematics.analysis import input_grid, simulate
from mechsyn.results import to_jsonable

from kinematics_helpers import ex  # noqa: F401


def limit_angle(a, b, c, g):
    """Input angle where coupler and rocker are stretched out: |BD| = b + c (law of cosines)."""
    return np.degrees(np.arccos((a ** 2 + g ** 2 - (b + c) ** 2) / (2 * a * g)))


@pytest.mark.parametrize("method", ["assur", "newton"])
def test_triple_rocker_dead_points(ex, method):
    m = ex("kinematics/triple_rocker.yaml")
    sim = simulate(m, {"A": input_grid(0, 360, 2)}, points=["C"], method=method)
    lim = limit_angle(2.2, 3.0, 2.6, 4.5)  # 108.46 deg; the other limit is 360 - lim
    x = sim.inputs["A"]
    expected = (x <= lim) | (x >= 360 - lim)
    assert np.array_equal(sim.assembled, expected), x[sim.assembled != expected]
    dead = sorted(e["input"]["A"] for e in sim.events if e["kind"] == "dead point")
    assert len(dead) == 2
    assert abs(dead[0] - lim) < 1e-6 and abs(dead[1] - (360 - lim)) < 1e-6
    # not assembled: NaN (null in JSON), never a wrong number
    assert np.isnan(sim.points["C"].position[~expected]).all()
    assert np.isfinite(sim.points["C"].position[expected]).all()
    d = to_jsonable(sim)
    k = int(np.flatnonzero(~expected)[0])
    assert d["points"]["C"]["position"][k] is None and d["assembled"][k] is False
    assert d["working_ranges"][0][0] == 0 and d["working_ranges"][0][1] <= lim


def test_crank_rocker_has_no_dead_point_for_its_crank(ex):
    sim = simulate(ex("kinematics/crank_rocker.yaml"), {"A": input_grid(0, 720, 3)})
    assert sim.assembled.all()
    assert not [e for e in sim.events if e["kind"] == "dead point"]


def test_first_input_out_of_range_is_reported(ex):
    m = ex("kinematics/triple_rocker.yaml")
    sim = simulate(m, {"A": input_grid(150, 200, 10)}, method="newton")
    assert not sim.assembled.any()
    assert sim.events and sim.events[0]["kind"] in ("dead point", "not assembled")
