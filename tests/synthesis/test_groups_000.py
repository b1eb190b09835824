"""Paper 000, structural part: tables 1 and 2 of the spec (section 4)."""

import pytest

from conftest import EXAMPLES
from mechsyn.synthesis.finger.groups import group_table


def test_two_phalanx_table(cli_json):
    d = cli_json("synth", "groups", "--base-mobility", "2", "--actuators", "1", "--max-links", "5")
    assert (d["W0"], d["W_f"], d["m_0"]) == (2, -1, 2)
    assert [(r["n_f"], r["P_f"], r["m_f"]) for r in d["rows"]] == [(1, 2, 2), (3, 5, 3), (5, 8, 4)]
    assert all(r["meets_conditions"] for r in d["rows"])


def test_three_phalanx_table(cli_json):
    d = cli_json("synth", "groups", "--base-mobility", "3", "--actuators", "1", "--max-links", "4")
    assert (d["W0"], d["W_f"], d["m_0"]) == (3, -2, 4)
    assert [(r["n_f"], r["P_f"], r["m_f"]) for r in d["rows"]] == [(2, 4, 3), (4, 7, 4)]
    # n_f = 2 gives too few free leashes (3 < m_0 = 4); the paper illustrates n_f = 4, P_f = 7
    assert [r["meets_conditions"] for r in d["rows"]] == [False, True]


def test_base_file_gives_w0(cli_json):
    d = cli_json("synth", "groups", "--base", EXAMPLES / "fingers" / "two_phalanx_base_000.yaml")
    assert d["W0"] == 2  # W0 = 3·4 - 2·5
    d3 = cli_json("synth", "groups", "--base", EXAMPLES / "fingers" / "three_phalanx_base_000.yaml")
    assert d3["W0"] == 3


@pytest.mark.parametrize("w0", [2, 3, 4, 5])
def test_rows_satisfy_group_mobility(w0):
    t = group_table(w0, 1, 9)
    for r in t.rows:
        assert 3 * r.n_f - 2 * r.P_f == t.W_f
        assert r.m_f == r.P_f - (r.n_f - 1)


def test_fully_actuated_base_rejected(run_cli):
    code, _, err = run_cli("synth", "groups", "--base-mobility", "1")
    assert code == 2 and "nothing to attach" in err
