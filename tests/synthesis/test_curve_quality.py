"""Curve synthesis a designer can build: size, link-ratio and transmission
bounds, fewest links first, invariance to similarity transforms, sparse targets, sharp
features, no empty answer with exit status 0, and target files that fail in one line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.io.load import mechanism_from_dict
from mechsyn.kinematics import simulate
from mechsyn.synthesis.curves.database import build_database, load_database
from mechsyn.synthesis.curves.fitting import sharp_features
from mechsyn.synthesis.curves.synthesis import synthesize_curve
from mechsyn.synthesis.curves.target import read_target, smooth_samples, target_from_points
from mechsyn.synthesis.curves.topologies import curve_topologies


def _fourbar_curve(seed: int, n: int = 200) -> np.ndarray:
    """A crank-rocker's coupler curve from its link lengths (independent of the database
    sampler), ``n`` points over a turn."""
    rng = np.random.default_rng(seed)
    while True:
        g, a, b, c = 1.0, rng.uniform(0.2, 0.4), rng.uniform(0.7, 1.3), rng.uniform(0.7, 1.3)
        if a + max(g, b, c) <= sum(sorted([g, b, c])[:2]) - 0.05:
            break
    th = np.linspace(0, 2 * np.pi, n, endpoint=False)
    A = a * np.exp(1j * th)
    d = g - A
    t = np.abs(d) ** 2
    al = (b * b - c * c + t) / (2 * t)
    B = A + d * (al + 1j * np.sqrt(b * b / t - al * al))
    p = complex(rng.uniform(0.2, 0.8), rng.uniform(0.2, 0.6))
    M = A + (B - A) * p
    return np.c_[M.real, M.imag] * 20 + [3, -2]


@pytest.fixture(scope="module")
def db_path(tmp_path_factory):
    d = tmp_path_factory.mktemp("curvedb")
    build_database(d, max_links=6, per_topology=400)
    return d


@pytest.fixture(scope="module")
def db(db_path):
    return load_database(db_path, build_if_missing=False)


def _joint_paths(cd: dict) -> np.ndarray:
    """Every joint and the tracer over the reported input range, through ``simulate``."""
    mech = mechanism_from_dict(cd["mechanism"])
    inp = cd["input"]
    ids = [j["id"] for j in cd["mechanism"]["joints"]] + [cd["tracer"]]
    vals = np.linspace(inp["start"], inp["stop"], 181)
    sim = simulate(mech, {inp["joint"]: vals}, points=ids)
    assert sim.assembled.all()
    return np.stack([sim.points[i].position for i in ids], axis=1)


def _centroid_and_diagonal(P: np.ndarray) -> tuple[np.ndarray, float]:
    """Independently: the centroid of the closed polyline (segment midpoints weighted
    by length) and the diagonal of its bounding box along the eigenvectors of its
    second moments."""
    Q = np.roll(P, -1, axis=0)
    L = np.hypot(*(Q - P).T)
    mid = 0.5 * (P + Q)
    c = (mid * L[:, None]).sum(axis=0) / L.sum()
    _, vec = np.linalg.eigh(np.cov((mid - c).T, aweights=L))
    R = (P - c) @ vec
    return c, float(np.hypot(*np.ptp(R, axis=0)))


def test_every_candidate_is_inside_the_default_bounds_and_reports_its_quality(db):
    P = _fourbar_curve(3)
    res = synthesize_curve(P, max_links=6, top=3, refinements=10, database=db, time_limit=300)
    assert res.candidates
    centre, diag = _centroid_and_diagonal(P)
    for c in res.candidates:
        d = c.to_dict()
        q = d["quality"]
        assert set(q) == {"size", "size_ratio", "link_ratio", "min_transmission_angle", "full_turn"}
        assert q["size_ratio"] <= 1.5 and q["link_ratio"] <= 10 and q["min_transmission_angle"] >= 30
        # the size, measured independently: every joint through simulate over the motion
        J = _joint_paths(d)
        size = float(np.max(np.hypot(*(J - centre).transpose(2, 0, 1))))
        assert size == pytest.approx(q["size"], rel=2e-2)
        assert q["size_ratio"] == pytest.approx(q["size"] / diag)
        assert d["topology"]
    assert res.to_dict()["bounds"]["max_size"] == 1.5


def test_bounds_lifted_only_when_asked_and_refused_when_impossible(db):
    P = _fourbar_curve(5)
    with pytest.raises(MechsynInputError, match="max_size"):
        synthesize_curve(P, max_size=0.2, database=db)
    with pytest.raises(MechsynInputError, match="prefer"):
        synthesize_curve(P, prefer="fast", database=db)
    res = synthesize_curve(P, max_links=4, top=2, refinements=6, max_size=None, max_link_ratio=None,
                           min_transmission=0, database=db, time_limit=300)
    assert res.to_dict()["bounds"]["max_size"] is None and res.candidates


def test_no_candidate_within_the_bounds_reports_the_nearest_miss(db, db_path, tmp_path, run_cli):
    P = _fourbar_curve(6)
    res = synthesize_curve(P, max_links=4, refinements=4, min_transmission=89, database=db, time_limit=300)
    assert res.candidates == [] and not res.feasible
    miss = res.nearest_miss
    assert miss is not None and miss.verified and miss.min_transmission_angle < 89
    assert "nearest miss" in res.reason and "--min-transmission-angle" in res.reason
    assert res.to_dict()["nearest_miss"]["quality"]["min_transmission_angle"] < 89
    f = tmp_path / "t.json"
    f.write_text(json.dumps({"points": P.tolist(), "closed": True}))
    code, out, err = run_cli("synth", "curve", f, "--max-links", "4", "--min-transmission-angle", "89",
                             "--database", db_path, "--time-limit", "10")
    assert code == 1 and "nearest miss" in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_fewest_links_first_within_the_tolerance_and_distinct_topologies(db):
    P = _fourbar_curve(8)
    res = synthesize_curve(P, max_links=6, top=4, refinements=16, database=db, time_limit=300)
    within = [c for c in res.candidates if c.chamfer <= 5e-3]
    assert within and within[0].topology.n_links == 4 and res.candidates[0] is within[0]
    links = [c.topology.n_links for c in within]
    first = res.candidates[:min(3, len(within))]
    assert len({c.topology.key for c in first}) == len(first)          # distinct topologies first
    assert links[0] == min(links)
    acc = synthesize_curve(P, max_links=6, top=4, refinements=16, database=db, time_limit=300, prefer="accuracy")
    errs = [c.chamfer for c in acc.candidates]
    assert errs == sorted(errs)


def _similar(P: np.ndarray, rng) -> tuple[np.ndarray, float]:
    ang = rng.uniform(0, 2 * np.pi)
    s = 10.0 ** rng.uniform(-3, 4)
    Q = P * [1, -1] if rng.random() < 0.5 else P.copy()
    R = np.array([[np.cos(ang), -np.sin(ang)], [np.sin(ang), np.cos(ang)]])
    return (Q @ R.T) * s + rng.uniform(-50, 50, 2) * s, s


@pytest.mark.slow
def test_similar_targets_give_the_same_design_transformed(db):
    rng = np.random.default_rng(29)
    kw = dict(max_links=6, top=3, refinements=6, database=db, time_limit=1e4, max_size=None)
    for seed in (1, 2):
        P = _fourbar_curve(seed)
        base = synthesize_curve(P, **kw)
        d0 = base.target.diagonal
        for _ in range(3):
            Q, s = _similar(P, rng)
            res = synthesize_curve(Q, **kw)
            assert [c.topology.key for c in res.candidates] == [c.topology.key for c in base.candidates]
            for a, b in zip(base.candidates, res.candidates):
                assert b.chamfer * res.target.diagonal / s == pytest.approx(a.chamfer * d0, rel=1e-6)
                assert b.link_length_ratio == pytest.approx(a.link_length_ratio, rel=1e-6)
                assert b.min_transmission_angle == pytest.approx(a.min_transmission_angle, rel=1e-6)
                # the reported design traces the transformed curve: its path is on Q
                J = _joint_paths(b.to_dict())[:, -1]
                gap = np.hypot(*(J[:, None] - b.path[None]).transpose(2, 0, 1)).min(axis=1).max()
                assert gap < 1e-6 * res.target.diagonal


@pytest.mark.slow
def test_scaled_targets_keep_their_answer_with_the_default_bounds(db):
    """x1e-3 and x1e4, turned by 90 degrees and mirrored: the bounding box maps exactly,
    so even the size bound is the same and the answer is the same design transformed."""
    P = _fourbar_curve(4)
    kw = dict(max_links=6, top=2, refinements=6, database=db, time_limit=1e4)
    base = synthesize_curve(P, **kw)
    for s, turn, mirror in ((1e-3, 1, False), (1e4, 3, True)):
        Q = np.rot90(np.eye(2), turn) @ (P * ([-1, 1] if mirror else [1, 1])).T
        res = synthesize_curve(Q.T * s + 7 * s, **kw)
        assert res.candidates
        for a, b in zip(base.candidates, res.candidates):
            assert b.chamfer == pytest.approx(a.chamfer, rel=1e-6)
            assert b.size_ratio == pytest.approx(a.size_ratio, rel=1e-6)
            assert b.verified


def test_sparse_points_are_a_smooth_curve_not_a_polygon(db):
    dense = _fourbar_curve(11, n=720)
    sparse = dense[::60]                                       # 12 points of the same curve
    truth = target_from_points(dense, closed=True)
    spline = smooth_samples(target_from_points(sparse, closed=True))
    from mechsyn.synthesis.curves.synthesis import curve_errors

    polygon_err = curve_errors(sparse, truth, True)[0]
    spline_err = curve_errors(spline.points, truth, True)[0]
    assert spline_err < 0.25 * polygon_err
    res = synthesize_curve(sparse, max_links=4, top=1, refinements=8, database=db, time_limit=300)
    assert any("smooth curve" in n for n in res.notes)
    c = res.candidates[0]
    assert curve_errors(c.path, truth, True)[0] < 0.5 * polygon_err


def test_sharp_features_found_on_a_heart_and_fitted():
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    heart = np.c_[16 * np.sin(t) ** 3, 13 * np.cos(t) - 5 * np.cos(2 * t) - 2 * np.cos(3 * t) - np.cos(4 * t)]
    F = sharp_features(heart, closed=True)
    # the cusp at the top (t = 0) and the point at the bottom (t = pi)
    assert any(np.hypot(*(f - heart[0])) < 0.5 for f in F)
    assert any(np.hypot(*(f - heart[200])) < 0.5 for f in F)
    e = np.c_[3 * np.cos(t), np.sin(t)]
    assert len(sharp_features(e, closed=True)) <= 2          # an ellipse: its two tips at most


def test_eight_bar_topologies_are_named():
    labels = [t.label for t in curve_topologies(8) if t.n_links == 8]
    assert labels and all(lb.startswith("8-bar chain ") for lb in labels)


def test_bad_target_files_fail_in_one_line(tmp_path, run_cli):
    cases = {
        "big_int.json": '{"points": [[1' + "0" * 5000 + ', 0], [1, 1], [2, 2]]}',
        "huge.json": '{"points": [[0, 0], [1e308, 1e308], [-1e308, 0]]}',
        "dot.json": '{"points": [[0, 0], [1, 0], [0, 0]]}',
        "tags.svg": "<svg>" + "<path " * 300_000 + "</svg>",      # no d=: one pass, not one per tag
    }
    for name, text in cases.items():
        f = tmp_path / name
        f.write_text(text)
        with pytest.raises(MechsynInputError):
            read_target(f)
        code, out, err = run_cli("synth", "curve", f)
        assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, (name, err)


def test_target_size_limits(tmp_path, monkeypatch):
    from mechsyn.synthesis.curves import target

    f = tmp_path / "t.csv"
    f.write_text("\n".join(f"{np.cos(a)},{np.sin(a)}" for a in np.linspace(0, 6, 50)))
    monkeypatch.setattr(target, "MAX_TARGET_BYTES", 100)
    with pytest.raises(MechsynInputError, match="larger than"):
        read_target(f)
    monkeypatch.setattr(target, "MAX_TARGET_BYTES", 10**6)
    monkeypatch.setattr(target, "MAX_TARGET_POINTS", 20)
    with pytest.raises(MechsynInputError, match="at most 20"):
        read_target(f)


def test_a_damaged_database_file_is_named(tmp_path):
    build_database(tmp_path, max_links=4, per_topology=30)
    (f,) = tmp_path.glob("*.npz")
    f.write_bytes(f.read_bytes()[:200])
    with pytest.raises(MechsynInputError, match="damaged"):
        load_database(tmp_path, build_if_missing=False)
    build_database(tmp_path, max_links=4, per_topology=30)      # rebuilt
    assert len(load_database(tmp_path, build_if_missing=False)) == 30
