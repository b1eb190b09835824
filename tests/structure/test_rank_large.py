"""Rank analysis of large mechanisms (issue 17 §3): the contour-by-contour elimination
gives the dense SVD's answers; contours are computed once per mechanism; stages are
reported. Speed is measured in benchmarks/rank.py, not here."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.structure import contours as contours_mod
from mechsyn.structure import rank as rank_mod
from mechsyn.structure.rank import _build_system, _eliminate, _reduce_dense, analyze_rank, as_spatial

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FILES = [p for p in sorted(EXAMPLES.glob("*/*.yaml")) if p.parent.name in ("textbook", "structural")]


def ladder(loops: int, seed: int = 1) -> dict:
    """A chain of four-bar loops, each crank the previous loop's rocker (benchmarks/rank.py)."""
    rng = np.random.default_rng(seed)
    joints = [{"id": "A", "type": "R", "links": ["frame", "r0"], "point": [0.0, 0.0], "actuated": True}]
    links = ["frame", "r0"]
    tip = np.array([0.3, 1.0])
    for i in range(1, loops + 1):
        pivot = np.array([1.2 * i, 0.0])
        c = pivot + np.array([0.2, 1.0]) + 0.1 * rng.standard_normal(2)
        links += [f"c{i}", f"r{i}"]
        joints += [{"id": f"B{i}", "type": "R", "links": [f"r{i-1}", f"c{i}"], "point": tip.tolist()},
                   {"id": f"C{i}", "type": "R", "links": [f"c{i}", f"r{i}"], "point": c.tolist()},
                   {"id": f"D{i}", "type": "R", "links": [f"r{i}", "frame"], "point": pivot.tolist()}]
        tip = c
    return {"name": f"ladder of {loops}", "kind": "planar", "ground": "frame", "links": links, "joints": joints}


def _same(mech) -> None:
    sysm = _build_system(mech, mech.kind == "planar")
    F = sysm.twists.shape[0]
    M, _ = sysm.closure(np.zeros(F))
    blocks, _ = sysm.closure_blocks(np.zeros(F))
    tol = 1e-6
    a, b = _reduce_dense(M, sysm.lam, tol), _eliminate(blocks, sysm.contour_columns(), sysm.lam, tol, F)
    assert a.rank == b.rank and a.increments == b.increments
    assert np.allclose(M @ b.null, 0, atol=1e-9)
    assert np.allclose(b.null.T @ b.null, np.eye(b.null.shape[1]), atol=1e-9)
    # the same motion space: projections agree
    assert np.allclose(a.null @ a.null.T, b.null @ b.null.T, atol=1e-8)
    for k, inc in enumerate(a.increments):  # the same redundant directions (left null spaces)
        ua, ub = a.left[k][:, inc:], b.left[k][:, inc:]
        assert np.allclose(ua @ ua.T, ub @ ub.T, atol=1e-8)


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_elimination_equals_dense_svd_on_every_example(path):
    mech = load_mechanism(path)
    if rank_mod.missing_geometry(mech):
        pytest.skip("no geometry")
    _same(mech)
    if mech.kind == "planar":
        _same(as_spatial(mech))


def test_elimination_equals_dense_on_a_ladder_seen_in_3d():
    _same(as_spatial(mechanism_from_dict(ladder(12))))


def test_large_ladder_takes_the_elimination_path_with_the_same_answer(monkeypatch):
    mech = mechanism_from_dict(ladder(45))  # 136 pair freedoms: above DENSE_MAX_FREEDOMS
    assert len(mech.joints) > rank_mod.DENSE_MAX_FREEDOMS
    states = []
    big = analyze_rank(mech, progress=states.append)
    assert [(p.done, p.total, p.stage) for p in states] == [(0, 4, "contours"), (1, 4, "rank"), (2, 4, "idle"),
                                                           (3, 4, "singularity")]
    monkeypatch.setattr(rank_mod, "DENSE_MAX_FREEDOMS", 10 ** 6)
    dense = analyze_rank(mech)
    for key in ("mobility", "useful_mobility", "redundant_constraints", "redundant_by_contour", "singular",
                "finite_mobility", "actuation_determined"):
        assert getattr(big, key) == getattr(dense, key), key
    assert (big.mobility, big.redundant_constraints, big.actuation_determined) == (1, 0, True)


def test_contours_computed_once_per_mechanism(monkeypatch):
    mech = mechanism_from_dict(ladder(5))
    calls = []
    real = contours_mod.choose_contours
    monkeypatch.setattr(contours_mod, "choose_contours", lambda *a, **k: calls.append(1) or real(*a, **k))
    from mechsyn.structure.analysis import analyze_structure

    analyze_structure(mech)
    analyze_rank(mech)
    assert len(calls) == 1


def test_large_file_says_its_size(tmp_path, run_cli, monkeypatch):
    import yaml

    from mechsyn.cli import analyze as cli_analyze

    monkeypatch.setattr(cli_analyze, "LARGE_JOINTS", 20)
    f = tmp_path / "ladder.yaml"
    f.write_text(yaml.safe_dump(ladder(8)))
    code, out, err = run_cli("analyze", f, "--json")
    assert code == 0 and "large mechanism: 25 joints" in err
