"""Paper 000's attachment of groups to adaptive fingers (issue 7, spec section 4)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mechsyn.cli.main import main
from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism
from mechsyn.synthesis.chains import rigid_subchain
from mechsyn.synthesis.finger.candidates import synthesize_fingers

EX = Path(__file__).resolve().parents[2] / "examples" / "fingers"


@pytest.fixture(scope="module")
def two_phalanx():
    return synthesize_fingers(load_mechanism(EX / "two_phalanx_base_000.yaml"), 1, 3)


def test_two_phalanx_counts_and_leashes(two_phalanx):
    s = two_phalanx
    assert (s.W0, s.W_f, s.m_0) == (2, -1, 2)
    assert [(r.n_f, r.P_f, r.m_f) for r in s.groups] == [(1, 2, 2), (3, 5, 3)]
    assert set(s.leash_sites) == {"proximal", "rod"}


def test_two_phalanx_one_link_group(two_phalanx):
    """Paper 000 fig. 4a-c: a single link (n_f = 1, P_f = 2) between the proximal phalanx
    and the rod (both made ternary); it is the VLL candidate; freeing it gives W = 2."""
    ones = [r for r in two_phalanx.results if r.n_f == 1]
    assert len(ones) == 1
    r = ones[0]
    assert r.attachments == {"proximal": ["g1"], "rod": ["g1"]}
    assert r.mobility_locked == 1
    assert r.vll_candidates == ("g1",)
    assert [(c.links, c.underactuated_mobility) for c in r.vll_combinations] == [(("g1",), 2)]


def test_two_phalanx_three_link_group_in_two_orders(two_phalanx):
    """Paper 000 fig. 4d, 4e: the group n_f = 3, P_f = 5 (three leashes: proximal, rod,
    palm) attached in different orders gives different mechanisms."""
    threes = [r for r in two_phalanx.results if r.n_f == 3]
    assert len(threes) >= 2
    # the group is a path g-g-g; with its three leashes on three different links, the
    # base link holding the middle of the path differs between attachment orders
    middles = set()
    for r in threes:
        holders = {g[0]: t for t, g in r.attachments.items() if len(g) == 1}
        if len(holders) == 3 and len(r.attachments) == 3:
            tree = [p for p in r.group_pairs if p[0].startswith("g") and p[1].startswith("g")]
            middle = next(g for g in r.group_links if sum(g in p for p in tree) == 2)
            middles.add(holders[middle])
    assert len(middles) >= 2
    assert len({r.certificate for r in threes}) == len(threes)
    for r in threes:
        assert set(r.attachments) >= {"proximal", "rod"}
        assert 1 <= len(r.vll_candidates) <= 3
        assert all(c.underactuated_mobility == 1 + len(c.links) for c in r.vll_combinations)


def test_every_result_is_movable_and_fully_actuated(two_phalanx):
    for r in two_phalanx.results:
        names = [x if isinstance(x, str) else x["name"] for x in r.mechanism["links"]]
        idx = {n: i for i, n in enumerate(names)}
        edges = [(idx[a], idx[b]) for a, b in (j["links"] for j in r.mechanism["joints"])]
        assert rigid_subchain(edges, len(names)) is None
        assert r.mobility_locked == 1
        assert r.structural_formula.startswith("I(palm,crank)")


@pytest.mark.slow
def test_three_phalanx_four_link_group():
    """Paper 000 fig. 6: W0 = 3, W_f = -2, the group n_f = 4, P_f = 7 (m_f = 4)."""
    s = synthesize_fingers(load_mechanism(EX / "three_phalanx_base_000.yaml"), 1, 4)
    assert (s.W0, s.W_f, s.m_0) == (3, -2, 4)
    assert [(r.n_f, r.P_f, r.m_f) for r in s.groups] == [(4, 7, 4)]
    assert s.results and all(r.n_f == 4 and r.mobility_locked == 1 for r in s.results)
    assert all(r.vll_candidates for r in s.results)


def test_finger_cli_files_pass_analyze(tmp_path, capsys):
    assert main(["synth", "finger", str(EX / "two_phalanx_base_000.yaml"), "--max-links", "3",
                 "--out", str(tmp_path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["W0"] == 2 and len(data["results"]) >= 3
    assert (tmp_path / "fingers.png").stat().st_size > 10_000
    for r in data["results"]:
        assert main(["analyze", r["file"], "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["mobility"] == 1


def test_finger_bad_input(capsys):
    assert main(["synth", "finger", str(EX.parent / "textbook" / "fourbar.yaml")]) == 2
    assert "nothing to attach" in capsys.readouterr().err
    with pytest.raises(MechsynInputError):
        synthesize_fingers(load_mechanism(EX.parent / "structural" / "gripper_003.yaml"))


def test_three_phalanx_two_separate_groups():
    """Paper 000 step 6: W0 - 1 = 2 groups of W_f = -1 each instead of one group."""
    s = synthesize_fingers(load_mechanism(EX / "three_phalanx_base_000.yaml"), 1, 4,
                           separate=True)
    kinds = {r.groups for r in s.results}
    assert ((1, 2), (1, 2)) in kinds
    for r in s.results:
        assert len(r.groups) == 2 and r.mobility_locked == 1
        assert sum(3 * n - 2 * p for n, p in r.groups) == -2


def test_finger_cli_json_is_the_result_to_dict(cli_json):
    """``synth finger --json`` prints the library result's ``to_dict()``, nothing added."""
    from mechsyn.results import to_jsonable

    base = EX / "two_phalanx_base_000.yaml"
    js = cli_json("synth", "finger", base, "--max-links", "3")
    expected = synthesize_fingers(load_mechanism(base), 1, 3).to_dict()
    assert js == json.loads(json.dumps(to_jsonable(expected)))
    assert js["results"] and {"W0", "W_f", "m_0", "groups", "results", "notes"} <= set(js)


def test_finger_cli_plain_output_at_80_columns(run_cli, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    code, out, err = run_cli("synth", "finger", EX / "two_phalanx_base_000.yaml", "--max-links", "3")
    assert code == 0, err
    assert "W0 = 2" in out and "distinct fingers" in out
    assert "admissible groups: (n_f=1, P_f=2, m_f=2); (n_f=3, P_f=5, m_f=3)" in out
