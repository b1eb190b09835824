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
    # one range through 360 deg (the sweep is a whole turn), ending at the dead points, not at rows
    (rng,) = d["working_ranges"]
    assert rng == pytest.approx([360 - lim, 360 + lim], abs=1e-6)


def test_crank_rocker_has_no_dead_point_for_its_crank(ex):
    sim = simulate(ex("kinematics/crank_rocker.yaml"), {"A": input_grid(0, 720, 3)})
    assert sim.assembled.all()
    assert not [e for e in sim.events if e["kind"] == "dead point"]


def test_first_input_out_of_range_is_reported(ex):
    m = ex("kinematics/triple_rocker.yaml")
    sim = simulate(m, {"A": input_grid(150, 200, 10)}, method="newton")
    assert not sim.assembled.any()
    assert sim.events and sim.events[0]["kind"] in ("dead point", "not assembled")


def double_parallelogram():
    from mechsyn.io import mechanism_from_dict

    return mechanism_from_dict({
        "name": "double parallelogram", "ground": "frame",
        "links": ["frame", "c1", {"name": "cp", "mass": 1.0}, "c2", "c3"],
        "joints": [
            {"id": "A1", "type": "R", "links": ["frame", "c1"], "point": [0, 0], "actuated": True},
            {"id": "B1", "type": "R", "links": ["c1", "cp"], "point": [0, 1]},
            {"id": "A2", "type": "R", "links": ["frame", "c2"], "point": [2, 0]},
            {"id": "B2", "type": "R", "links": ["c2", "cp"], "point": [2, 1]},
            {"id": "A3", "type": "R", "links": ["frame", "c3"], "point": [4, 0]},
            {"id": "B3", "type": "R", "links": ["c3", "cp"], "point": [4, 1]}]}, "dp")


def test_redundant_parallelogram_passes_its_change_points():
    """An overconstrained (redundant) double parallelogram: least-squares Newton, the change
    points at 180 and 360 degrees reported as singular, the motion continued on its branch."""
    from mechsyn.kinetostatics import forces
    from mechsyn.kinematics.solve import check_mobility

    m = double_parallelogram()
    sim = simulate(m, {"A1": input_grid(90, 450, 10)}, points=["B3"])
    assert check_mobility(sim.system)["redundant"] == 1
    assert sim.method == "newton" and sim.assembled.all()
    th = np.radians(sim.inputs["A1"])
    err = np.abs(sim.points["B3"].position - np.stack([4 + np.cos(th), np.sin(th)], 1)).max(axis=1)
    singular = {round(e["input"]["A1"]) for e in sim.events if e["kind"] == "singular"}
    assert singular == {180, 360}
    regular = ~np.isin(np.round(sim.inputs["A1"]), [180, 360])
    assert err[regular].max() < 1e-10 and err.max() < 1e-4
    fa = forces(m, {"A1": input_grid(90, 170, 20)}, gravity=(0, -9.81), static=True)
    assert fa.reactions.indeterminate
    # the balancing moment is still determinate: m g times the coupler's horizontal travel rate
    assert np.allclose(fa.reactions.effort["A1"], 9.81 * np.cos(np.radians(fa.simulation.inputs["A1"])),
                       atol=1e-9)


def test_singular_file_configurations(ex):
    """Files assembled at a dead centre or folded flat: the sweep runs, the singular rows
    have positions but null rates, and a note says the file's configuration is singular."""
    sim = simulate(ex("textbook/fourbar_dead_centre.yaml"), {"A": input_grid(0, 360, 30)})
    dead = sorted(e["input"]["A"] for e in sim.events if e["kind"] == "dead point")
    lim = np.degrees(np.arctan2(2, 1))  # the file's crank angle is the dead centre
    assert abs(dead[0] - lim) < 1e-6 and abs(dead[1] - (360 - lim)) < 1e-6
    assert any("singular" in n for n in sim.notes)
    sim = simulate(ex("textbook/fourbar_folded.yaml"), {"A": input_grid(0, 360, 30)}, points=["C"])
    assert sim.assembled.all()
    assert np.allclose(sim.points["C"].position[0], [5, 0])
    assert np.isnan(sim.points["C"].velocity[0]).all() and np.isfinite(sim.points["C"].velocity[1]).all()
    assert {e["input"]["A"] for e in sim.events if e["kind"] == "singular"} == {0.0, 360.0}
    d = to_jsonable(sim)
    assert d["points"]["C"]["velocity"][0] == [None, None] or d["points"]["C"]["velocity"][0] is None
