"""Paper 003 (per-contour structural analysis): every number of the spec's section 2.

The figures are not in the OCR; the example files use the topologies the spec gives,
consistent with every printed count.
"""

import pytest

from conftest import EXAMPLES
from mechsyn.io import load_mechanism
from mechsyn.structure import analyze_structure
from mechsyn.structure.remedies import find_remedies

S = EXAMPLES / "structural"


@pytest.fixture
def fig3(cli_json):
    return cli_json("analyze", S / "robot_actuator_003.yaml")


def test_fig3_counts(fig3):
    assert fig3["moving_links"] == 7
    assert fig3["pairs_by_class"] == {"3": 2, "4": 1, "5": 6}
    assert fig3["independent_contours"] == 2
    assert fig3["formulas"]["gokhman_contours"]["value"] == 2
    assert fig3["formulas"]["gokhman_contours"]["expression"] == "K = 9 - 7 = 2"


def test_fig3_contours(fig3):
    c1, c2 = fig3["contours"]
    assert c1["joints"] == ["B", "C", "D5", "D4"]
    assert (c1["S"], c1["T"], c1["Z"], c1["n_j"], c1["n_k"]) == (2, 0, 0, 4, 4)
    assert c1["S_expression"] == "S1 = 3 - (5-4)·1 - (5-5)·3 = 2"
    # contour 2: only C', F3, D3 are new (C was counted in contour 1)
    assert [p["id"] for p in c2["new_pairs"]] == ["C'", "F3", "D3"]
    assert (c2["S"], c2["T"], c2["Z"], c2["n_k"]) == (-1, 0, 0, 2)
    assert c2["idle_mobilities"] == 1
    assert c2["S_expression"] == "S2 = 3 - (5-3)·2 - (5-5)·1 = -1"


def test_fig3_totals(fig3):
    assert fig3["structural_redundancy"] == 1
    assert fig3["constructive_redundancy"] == 0
    assert fig3["mobility"] == 3
    assert fig3["formulas"]["somov_malyshev"]["expression"] == "W = 6·7 - 3·2 - 4·1 - 5·6 + 1 = 3"
    assert fig3["degrees_of_mobility"] == 3  # H = 7 - 2·2: three rotary drives
    assert fig3["degrees_of_mobility_expression"] == "H = 7 - (2 + 2) = 3"


def test_fig3_remedy_a_file(cli_json):
    d = cli_json("analyze", S / "robot_actuator_003_remedy_a.yaml")
    assert [c["S"] for c in d["contours"]] == [0, 0]
    assert d["pairs_by_class"] == {"3": 2, "4": 2, "5": 5}
    assert d["formulas"]["somov_malyshev"]["expression"] == "W = 6·7 - 3·2 - 4·2 - 5·5 = 3"
    assert d["mobility"] == 3


def test_fig3_remedy_b_file(cli_json):
    d = cli_json("analyze", S / "robot_actuator_003_remedy_b.yaml")
    assert [c["S"] for c in d["contours"]] == [0, 0]
    assert d["mobility"] == 3


def test_fig3_remedies_found():
    """The program finds the paper's remedy a (B5 -> B3, D3 -> D4) among its variants."""
    mech = load_mechanism(S / "robot_actuator_003.yaml")
    variants = find_remedies(mech, max_variants=10)
    assert variants
    as_sets = [{(c.joint, c.new_class) for c in r.changes} for r in variants]
    assert {("B", 3), ("D3", 4)} in as_sets
    first = variants[0]
    assert len(first.changes) == 2
    for r in variants:
        assert all(row.S == 0 for row in r.analysis.contours)
        assert r.analysis.mobility == 3
        # mobility unchanged, S_Σ now zero
        assert r.analysis.structural_redundancy == 0


@pytest.fixture
def fig4(cli_json):
    return cli_json("analyze", S / "gripper_003.yaml")


def test_fig4_contours(fig4):
    assert fig4["independent_contours"] == 4
    rows = fig4["contours"]
    assert [r["S"] for r in rows] == [1, 1, 3, 3]
    assert [r["T"] for r in rows] == [0, 0, 1, 1]
    assert [r["Z"] for r in rows] == [0, 0, 0, 0]
    assert rows[0]["S_expression"] == "S1 = 3 - (4-2)·1 - (5-5)·2 = 1"
    assert rows[2]["S_expression"] == "S3 = 3 - (5-5)·2 = 3"
    assert (rows[2]["n_j"], rows[2]["n_k"]) == (2, 1)


def test_fig4_totals(fig4):
    assert fig4["structural_redundancy"] == 8
    assert fig4["constructive_redundancy"] == 2
    assert fig4["mobility"] == 1
    assert fig4["formulas"]["somov_malyshev"]["expression"] == "W = 6·5 - 2·2 - 5·7 + 8 + 2 = 1"


def test_fig4_degrees_of_mobility_readings(fig4):
    # The paper prints H = 5 - 4·1 = 1; neither reading of its rule gives 1 on a topology
    # consistent with every other count: the sequential rule gives 0, the exclusive-link
    # reading 3. The report gives both and says they differ (the rank method gives 1).
    assert fig4["degrees_of_mobility"] == 0
    assert fig4["degrees_of_mobility_exclusive"] == 3
    assert any("degrees of mobility" in n for n in fig4["notes"])


def test_fig4_remedy(cli_json):
    d = cli_json("analyze", S / "gripper_003_remedy.yaml")
    assert d["moving_links"] == 7
    assert [r["S"] for r in d["contours"]] == [0, 0, 0, 0]
    rows = d["contours"]
    assert rows[0]["S_expression"] == "S1 = 3 - (4-1)·1 - (5-5)·2 = 0"
    assert rows[2]["S_expression"] == "S3 = 3 - (5-4)·3 = 0"
    assert (rows[2]["T"], rows[2]["n_j"], rows[2]["n_k"]) == (0, 3, 2)
    assert d["mobility"] == 1
    assert d["formulas"]["somov_malyshev"]["expression"] == "W = 6·7 - 1·2 - 4·6 - 5·3 = 1"
    # Paper: H = 7 - 2·2 - 2·1 = 1; the sequential rule gives 7 - (2 + 1 + 2 + 2) = 0.
    assert d["degrees_of_mobility"] == 0


def test_fig4_class_remedies_keep_mobility():
    mech = load_mechanism(S / "gripper_003.yaml")
    variants = find_remedies(mech, max_variants=5)
    assert variants
    # the paper's first step, B2 -> B1 in both higher pairs, is the preferred change
    first = {(c.joint, c.new_class) for c in variants[0].changes}
    assert {("B", 1), ("B'", 1)} <= first
    for r in variants:
        assert r.analysis.mobility == 1
        assert [row.S for row in r.analysis.contours] == [0, 0, 0, 0]
        # the metric constraints of contours 3, 4 stay: class changes cannot remove them
        assert r.analysis.metric_constraints == 2


def test_contour_order_matters():
    """Paper 003's results depend on the order of the contours (sequential reading)."""
    mech = load_mechanism(S / "robot_actuator_003.yaml")
    from dataclasses import replace

    swapped = replace(mech, contours=tuple(reversed(mech.contours)))
    a, b = analyze_structure(mech), analyze_structure(swapped)
    assert [r.S for r in a.contours] == [2, -1]
    assert [r.S for r in b.contours] == [-1, 2]  # C now counts in the first contour
    assert a.structural_redundancy == b.structural_redundancy == 1
