"""The finite-mobility check's shortcut at provably regular poses: where the rank equals the
dimension of the subgroup the pairs' twists generate times the number of contours (a planar
or spherical mechanism seen in 3-D, redundant constraints and all), the loop-closure map is
a submersion into that subgroup, and the finite mobility is the instantaneous one without
following the motion. Checked against following it, and the subgroup's dimension against
twists whose span is or is not closed under the bracket."""

import numpy as np
import pytest

import mechsyn as ms
import mechsyn.structure.rank as rank_mod
from mechsyn.io import mechanism_from_dict
from mechsyn.structure.finite import subgroup_dimension
from mechsyn.structure.rank import analyze_rank, as_spatial
from mechsyn.structure.screws import _unit


def rotation(axis, point):
    w = _unit(np.asarray(axis, float))
    return np.concatenate([w, np.cross(np.asarray(point, float), w)])  # v = -ω × q


def ladder(loops):
    """Four-bar loops chained (each crank the previous rocker), points at random."""
    rng = np.random.default_rng(3)
    joints = [{"id": "A", "type": "R", "links": ["frame", "r0"], "point": [0.0, 0.0], "actuated": True}]
    links, tip = ["frame", "r0"], [0.3, 1.0]
    for i in range(1, loops + 1):
        pivot = [1.2 * i, 0.0]
        c = (np.array(pivot) + [0.2, 1.0] + 0.1 * rng.standard_normal(2)).tolist()
        links += [f"c{i}", f"r{i}"]
        joints += [{"id": f"B{i}", "type": "R", "links": [f"r{i - 1}", f"c{i}"], "point": tip},
                   {"id": f"C{i}", "type": "R", "links": [f"c{i}", f"r{i}"], "point": c},
                   {"id": f"D{i}", "type": "R", "links": [f"r{i}", "frame"], "point": pivot}]
        tip = c
    return mechanism_from_dict({"name": "ladder", "kind": "planar", "ground": "frame", "links": links,
                                "joints": joints})


def test_subgroup_dimension_of_closed_and_open_spans():
    rng = np.random.default_rng(0)
    tilt = _unit(rng.standard_normal(3))
    planar = [rotation(tilt, rng.standard_normal(3)) for _ in range(5)]
    assert subgroup_dimension(np.array(planar)) == 3                   # se(2), turned anywhere
    centre = rng.standard_normal(3)
    spherical = [rotation(rng.standard_normal(3), centre) for _ in range(4)]
    assert subgroup_dimension(np.array(spherical)) == 3                # so(3) about the centre
    assert subgroup_dimension(np.array(planar[:1])) == 1               # one R pair
    cylinder = [planar[0], np.concatenate([np.zeros(3), tilt])]
    assert subgroup_dimension(np.array(cylinder)) == 2                 # R and P along one axis
    skew = [rotation(rng.standard_normal(3), rng.standard_normal(3)) for _ in range(4)]
    assert subgroup_dimension(np.array(skew)) == 6                     # a Bennett-like span is no subalgebra
    assert subgroup_dimension(np.array(planar[:2])) == 6               # two parallel axes: span not closed


@pytest.mark.parametrize("mech", [as_spatial(ladder(4)), ms.examples.load("spherical_fourbar"),
                                  as_spatial(ms.examples.load("crank_rocker"))],
                         ids=["ladder in 3-D", "spherical four-bar", "four-bar in 3-D"])
def test_shortcut_reads_what_following_the_motion_reads(mech, monkeypatch):
    with monkeypatch.context() as m:
        m.setattr(rank_mod, "local_mobility", lambda *a, **k: pytest.fail("followed a provably regular pose"))
        short = analyze_rank(mech)
    assert short.redundant_constraints > 0  # (not the plain rank == equations case)
    with monkeypatch.context() as m:
        m.setattr(rank_mod, "subgroup_dimension", lambda twists: 6)  # no shortcut: follow the motion
        followed = analyze_rank(mech)
    assert (short.mobility, short.finite_mobility, short.configuration) == \
        (followed.mobility, followed.finite_mobility, followed.configuration)
    assert short.configuration == "regular" and short.finite_mobility == short.mobility
