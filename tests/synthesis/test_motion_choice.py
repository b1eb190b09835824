"""Issue 40: Burmester four-bars labelled, filtered and ranked; 3-pose pivots picked."""

from __future__ import annotations

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.synthesis.exact import motion_synthesis
from mechsyn.synthesis.motion_choice import MAX_SIZE_RATIO, linkage_from_pivots, motion_choices, rank_motion

P3 = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, np.radians(20)], [2.0, 0.6, np.radians(45)]])
P4 = np.vstack([P3, [3.0, 0.4, np.radians(70)]])


def test_three_poses_offer_a_choice_every_one_buildable():
    cs = motion_choices(P3)
    assert len(cs) >= 2
    for c in cs:
        assert c.buildable and c.one_branch_in_order and c.size_ratio <= MAX_SIZE_RATIO
        assert c.result.position_error < 1e-9
    assert [c.score for c in cs] == sorted((c.score for c in cs), reverse=True)


def test_four_poses_filtered_and_labelled():
    results = motion_synthesis(P4, max_pairs=600)
    everything = rank_motion(results, P4, keep_unbuildable=True)
    kept = rank_motion(results, P4)
    assert 0 < len(kept) < len(everything)
    assert all(c.buildable for c in kept)
    assert any(not c.buildable for c in everything)
    label = kept[0].label()
    for words in ("Grashof", "× the poses", "reaches the poses on one branch, in order", "min μ"):
        assert words in label


def test_min_transmission_is_along_the_motion_not_only_at_the_poses():
    c = motion_choices(P4, max_pairs=600)[0]
    assert c.min_transmission_deg <= c.result.min_transmission_deg + 1e-9


def test_picked_pivots_give_their_linkage():
    r = linkage_from_pivots(P3, [-0.5, 0.2], [1.0, 1.5])
    assert r.position_error < 1e-9
    # each moving pivot runs on a circle about its fixed pivot
    R = lambda a: np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])  # noqa: E731
    A = [R(P3[j, 2]) @ r.pA + P3[j, :2] for j in range(3)]
    d = [np.linalg.norm(a - r.O2) for a in A]
    assert np.ptp(d) < 1e-9 * max(d)
    assert np.allclose(A[0], [-0.5, 0.2])
    with pytest.raises(MechsynInputError, match="coincide"):
        linkage_from_pivots(P3, [0.0, 0.0], [0.0, 0.0])
