"""Issue 25 items 1-2: an idle rule that does not depend on where a point of an axis is
written, and the loading of ordinary spatial mechanisms.

Expected values are the textbook mobilities written in each example's header (Hunt,
*Kinematic geometry of mechanisms*, 1978; Gosselin and Angeles 1989): a spherical four-bar
and a Hooke coupling move with one freedom and three redundant constraints (the forces
through the centre repeat), a spherical 3-RRR with three and six; none of their motions
is idle, since the links joined to the frame turn. On the code before issue 25 the
spherical four-bar written at its centre gave idle 1, the 3-RRR idle 3 and the Hooke
coupling with bearings on its shafts idle 1; the R + U coupling and the slider block were
refused at load.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.structure.analysis import analyze_structure
from mechsyn.structure.rank import analyze_rank

EX = Path(__file__).resolve().parents[2] / "examples"


def load(rel: str):
    return load_mechanism(EX / rel)


def counts(r) -> tuple[int, int, int]:
    return r.mobility, r.redundant_constraints, len(r.idle_mobilities)


@pytest.mark.parametrize("rel, m, q", [
    ("spatial/spherical_fourbar_centre.yaml", 1, 3),
    ("spatial/spherical_fourbar_axes.yaml", 1, 3),
    ("spatial/spherical_3rrr.yaml", 3, 6),
    ("spatial/hooke_coupling_bearings.yaml", 1, 3),
    ("spatial/hooke_coupling_ru.yaml", 1, 3),
    ("textbook/bennett.yaml", 1, 3),
])
def test_spherical_hooke_and_bennett_linkages_have_no_idle_motion(rel, m, q):
    mech = load(rel)
    # without drives the idle rule meets the whole motion; with them, the same answer
    free = mechanism_from_dict({**yaml.safe_load((EX / rel).read_text()),
                                "joints": [{**j, "actuated": False} for j in yaml.safe_load(
                                    (EX / rel).read_text())["joints"]]})
    for mm in (mech, free):
        r = analyze_rank(mm)
        assert counts(r) == (m, q, 0)
        assert r.useful_mobility == m == mech.mobility
    # Malyshev's count is the loop's m - q
    assert analyze_structure(mech).formulas["malyshev"].value == m - q


def test_spherical_3rrr_with_base_drives_is_determined():
    d = yaml.safe_load((EX / "spatial/spherical_3rrr.yaml").read_text())
    for j in d["joints"]:
        j["actuated"] = j["id"].startswith("A")
    r = analyze_rank(mechanism_from_dict(d))
    assert counts(r) == (3, 6, 0) and r.actuation_determined is True


@pytest.mark.parametrize("rel, idle", [("structural/gough_stewart_6sps.yaml", 6), ("textbook/delta.yaml", 6),
                                       ("textbook/rssr.yaml", 1), ("structural/wrist_3sps_s.yaml", 3)])
def test_rod_and_leg_spins_stay_idle(rel, idle):
    r = analyze_rank(load(rel))
    assert len(r.idle_mobilities) == idle
    assert all(i.family == "group" for i in r.idle_mobilities)


def _spatial_examples() -> list[Path]:
    out = []
    for p in sorted(EX.glob("*/*.yaml")):
        d = yaml.safe_load(p.read_text())
        if isinstance(d, dict) and d.get("kind") == "spatial" and "joints" in d:
            out.append(p)
    return out


def _slid(mech, rng: np.random.Generator, reach: float):
    """``mech`` with the point of every R, C, H and P pair moved along its own axis."""
    joints = []
    for j in mech.joints:
        if j.type in ("R", "C", "H", "P") and j.point is not None and j.axis is not None:
            a = np.asarray(j.axis, float) / np.linalg.norm(j.axis)
            j = replace(j, point=np.asarray(j.point, float) + rng.uniform(-reach, reach) * a)
        joints.append(j)
    return replace(mech, joints=tuple(joints))


@pytest.mark.parametrize("path", _spatial_examples(), ids=lambda p: p.stem)
def test_sliding_a_point_along_its_axis_changes_nothing(path):
    mech = load_mechanism(path)
    base = analyze_rank(mech, check_singular=False)
    rng = np.random.default_rng(25)
    for _ in range(3):
        r = analyze_rank(_slid(mech, rng, base.length_scale), tol=base.tolerance, check_singular=False)
        assert counts(r) == counts(base)


def test_the_spherical_fourbar_written_two_ways_reads_alike():
    a, b = (analyze_rank(load(f"spatial/spherical_fourbar_{k}.yaml")) for k in ("centre", "axes"))
    assert counts(a) == counts(b) == (1, 3, 0)
    assert a.finite_mobility == b.finite_mobility == 1


# --------------------------------------------------------------------------- loading
def test_hooke_coupling_written_r_plus_u_at_one_point_loads():
    mech = load("spatial/hooke_coupling_ru.yaml")
    assert len({tuple(j.point) for j in mech.joints}) == 1  # every joint at the centre
    assert counts(analyze_rank(mech)) == (1, 3, 0)


def test_slider_block_with_two_pins_at_one_point_loads():
    mech = load("textbook/slider_block_two_pins.yaml")
    r = analyze_rank(mech)
    assert r.mobility == r.useful_mobility == 1 and r.redundant_constraints == 0
    assert analyze_structure(mech).formulas["chebyshev"].value == 1


def _hooke(**changes) -> dict:
    d = yaml.safe_load((EX / "spatial/hooke_coupling_ru.yaml").read_text())
    for j in d["joints"]:
        j.update(changes.get(j["id"], {}))
    return d


@pytest.mark.parametrize("changes, what", [
    ({"U": {"axis": [1, 0, 0]}}, "link 'shaft1' has zero length"),  # the U's arm along shaft 1's bearing axis
    ({"U": {"type": "S", "axis": None, "axis2": None}}, "all joints are at one point"),  # ball + hinge at a point
])
def test_degenerate_pins_at_one_point_are_still_refused(changes, what):
    with pytest.raises(MechsynInputError) as exc:
        mechanism_from_dict(_hooke(**changes), "h.yaml")
    msg = str(exc.value)
    assert what in msg and "fix:" in msg and "h.yaml" in msg


def test_a_crank_with_both_pivots_at_one_point_is_still_refused():
    d = yaml.safe_load((EX / "textbook/slider_block_two_pins.yaml").read_text())
    d["joints"][1]["point"] = [0, 0]  # B1 onto A1: crank1 has zero length
    with pytest.raises(MechsynInputError, match="link 'crank1' has zero length"):
        mechanism_from_dict(d, "s.yaml")


def test_a_block_without_its_slide_is_refused_for_its_two_pins():
    d = yaml.safe_load((EX / "textbook/slider_block_two_pins.yaml").read_text())
    d["joints"] = [j for j in d["joints"] if j["id"] != "S"]
    with pytest.raises(MechsynInputError, match="link 'block' has zero length"):
        mechanism_from_dict(d, "s.yaml")


@pytest.mark.parametrize("seed", range(4))
def test_random_spherical_fourbars_move_without_idle_motion(seed):
    """Any four axes through one point make a spherical four-bar at a configuration: one
    freedom, three redundant constraints, no idle motion, wherever on its axis each
    joint's point is written."""
    rng = np.random.default_rng(seed)
    axes = rng.standard_normal((4, 3))
    links = ["frame", "crank", "coupler", "rocker", "frame"]

    def mech(points):
        return mechanism_from_dict({"name": "sph", "kind": "spatial", "ground": "frame", "links": links[:4],
                                    "joints": [{"id": f"J{k}", "type": "R", "links": links[k:k + 2],
                                                "point": points[k].tolist(), "axis": axes[k].tolist()}
                                               for k in range(4)]})

    at_centre = analyze_rank(mech(np.zeros((4, 3))))
    slid = analyze_rank(mech(axes * rng.uniform(-2, 2, (4, 1))), tol=at_centre.tolerance)
    for r in (at_centre, slid):
        assert counts(r) == (1, 3, 0)
        assert (r.finite_mobility, r.configuration) == (1, "regular")
