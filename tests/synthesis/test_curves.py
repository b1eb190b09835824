"""Curve synthesis machinery on small cases: descriptors, alignment, topologies, targets,
database, retrieval + refinement, CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.io.load import mechanism_from_dict
from mechsyn.kinematics import simulate
from mechsyn.progress import Progress
from mechsyn.synthesis.curves.database import build_database, load_database
from mechsyn.synthesis.curves.descriptors import align, fourier_descriptor, resample, swap_direction
from mechsyn.synthesis.curves.synthesis import synthesize_curve
from mechsyn.synthesis.curves.target import read_target, target_from_points
from mechsyn.synthesis.curves.topologies import curve_topologies, six_bar_name


def _blob(m=50):
    t = np.linspace(0, 2 * np.pi, m, endpoint=False)
    r = 1 + 0.3 * np.cos(3 * t) + 0.1 * np.sin(2 * t)
    return np.c_[r * np.cos(t), 0.7 * r * np.sin(t)]


def test_descriptor_invariant_to_similarity_and_start_point():
    P = _blob()
    z = resample(P, 64)
    moved = (np.roll(P[:, 0] + 1j * P[:, 1], 17) * 2.5 * np.exp(1.1j)) + (3 - 4j)
    d1, d2 = fourier_descriptor(z), fourier_descriptor(resample(moved, 64))
    np.testing.assert_allclose(d1, d2, atol=2e-3)
    back = fourier_descriptor(resample(P[::-1], 64))
    np.testing.assert_allclose(swap_direction(d1), back, atol=2e-3)
    assert not np.allclose(d1, fourier_descriptor(resample(np.c_[np.cos(np.linspace(0, 6, 50)), np.sin(np.linspace(0, 6, 50)) ** 3], 64)), atol=1e-2)


def test_alignment_recovers_a_mirrored_reversed_similarity():
    w = resample(_blob(), 64)
    z = np.conj(np.roll(w[::-1], 9) * (0.3 + 0.4j) + 2)      # mirrored, reversed, moved
    a = align(z[None], w)
    assert a.rms[0] < 1e-9 and a.mirror[0]


def test_topologies_of_four_and_six_links():
    topos = curve_topologies(6)
    assert sum(t.n_links == 4 for t in topos) == 1
    names = {t.name for t in topos if t.n_links == 6}
    assert names == {"Watt I", "Watt II", "Stephenson I", "Stephenson III"}
    for t in topos:  # every candidate: a crank and RRR dyads, tracer not jointed to the frame
        assert t.plan.n_dyads == (t.n_links - 2) // 2
        assert not t.chain.graph().has_edge(t.tracer, t.frame)
    watt = next(t.chain for t in topos if t.name == "Watt I")
    deg = watt.degrees()
    assert six_bar_name(watt, deg.index(3)) == "Watt II"


def test_target_files(tmp_path):
    (tmp_path / "c.csv").write_text("x,y\n0,0\n1,0\n1,1\n0,1\n0,0.001\n")
    t = read_target(tmp_path / "c.csv")
    assert t.closed and len(t.points) == 5
    (tmp_path / "o.json").write_text(json.dumps({"points": [[0, 0], [1, 0], [2, 1]], "closed": False}))
    assert not read_target(tmp_path / "o.json").closed
    (tmp_path / "p.svg").write_text('<svg><path d="M 0 0 C 10 0 10 10 0 10 L -5 5 Z"/></svg>')
    s = read_target(tmp_path / "p.svg")
    assert s.closed and len(s.points) > 20 and s.points[:, 1].min() < -9  # y flipped
    (tmp_path / "bad.json").write_text('{"points": [[0, 0], [1, "a"]]}')
    with pytest.raises(MechsynInputError, match="points"):
        read_target(tmp_path / "bad.json")
    (tmp_path / "arc.svg").write_text('<svg><path d="M 0 0 A 5 5 0 0 1 10 0"/></svg>')
    with pytest.raises(MechsynInputError, match="arcs"):
        read_target(tmp_path / "arc.svg")
    with pytest.raises(MechsynInputError, match="3 distinct"):
        target_from_points([[0, 0], [1, 1]])


@pytest.fixture(scope="module")
def small_db(tmp_path_factory):
    d = tmp_path_factory.mktemp("curvedb")
    build_database(d, max_links=6, per_topology=250)
    return d


def test_database_is_resumable_and_extends(small_db, tmp_path):
    db = load_database(small_db, build_if_missing=False)
    assert len(db) == 250 * len(db.topologies) and len(db.topologies) == len(curve_topologies(6))
    before = {p.name: p.stat().st_mtime_ns for p in small_db.glob("*.npz")}
    build_database(small_db, max_links=6, per_topology=250)      # nothing to do
    assert before == {p.name: p.stat().st_mtime_ns for p in small_db.glob("*.npz")}
    d = tmp_path / "db"
    build_database(d, max_links=4, per_topology=100)
    build_database(d, max_links=4, per_topology=180)
    again = load_database(d, build_if_missing=False)
    assert len(again) == 180
    first = load_database(d, build_if_missing=False).designs[:100]
    np.testing.assert_array_equal(np.array(first), np.array(again.designs[:100]))


def _fourbar_curve(seed: int):
    """A crank-rocker drawn independently of the database sampler (Grashof by lengths)."""
    rng = np.random.default_rng(seed)
    while True:
        g, a, b, c = 1.0, rng.uniform(0.15, 0.4), rng.uniform(0.6, 1.4), rng.uniform(0.6, 1.4)
        if a + max(g, b, c) <= sum(sorted([g, b, c])[:2]) + 1e-3:
            break
    th = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    A = a * np.exp(1j * th)
    d = g - A
    t = np.abs(d) ** 2
    al = (b * b - c * c + t) / (2 * t)
    B = A + d * (al + 1j * np.sqrt(b * b / t - al * al))
    p = complex(rng.uniform(-0.5, 1.0), rng.uniform(0.2, 1.0))
    M = A + (B - A) * p
    return np.c_[M.real, M.imag] * 40 + [5, -3]


def test_recovers_a_four_bar_curve_and_verifies_it(small_db):
    target = target_from_points(_fourbar_curve(4), closed=True)
    states = []
    res = synthesize_curve(target, max_links=4, top=2, refinements=6, database=load_database(small_db),
                           progress=states.append)
    best = res.candidates[0]
    assert best.chamfer < 0.01 and best.verified
    assert all(isinstance(s, Progress) for s in states) and states[-1].stage
    d = res.to_dict()["candidates"][0]
    assert set(d) >= {"mechanism", "tracer", "input", "links", "topology", "error", "min_transmission_angle"}
    # the reported mechanism, input and tracer re-simulate to the reported path
    mech = mechanism_from_dict(d["mechanism"])
    vals = np.concatenate([[best.reference_input], np.linspace(d["input"]["start"], d["input"]["stop"], 73)])
    sim = simulate(mech, {d["input"]["joint"]: vals}, points=[d["tracer"]])
    assert sim.assembled.all()
    P = sim.points["T"].position[1:]
    assert np.max(np.hypot(*(P[:, None, :] - target.points[None]).transpose(2, 0, 1)).min(axis=1)) \
        < 0.05 * target.diagonal
    assert "error" in str(res) and d["error"]["chamfer"] == best.chamfer
    assert best.role.endswith("most accurate") and d["role"] == best.role


def test_options_are_kept_or_refused(small_db):
    target = target_from_points(_fourbar_curve(7), closed=True)
    box = (-1e9, -1e9, 1e9, 1e9)
    res = synthesize_curve(target, max_links=6, top=3, refinements=4, crank=True, max_link_ratio=8.0,
                           ground_region=box, database=load_database(small_db))
    for c in res.candidates:
        assert c.link_length_ratio <= 8.0 * (1 + 1e-6) and c.stop - c.start == 360.0
    with pytest.raises(MechsynInputError, match="crank"):
        synthesize_curve(target_from_points(_blob()[:20], closed=False), crank=True,
                         database=load_database(small_db))


def test_cli_synth_curve_and_curves_build(small_db, tmp_path, cli_json, run_cli):
    f = tmp_path / "t.json"
    f.write_text(json.dumps({"points": _fourbar_curve(11).tolist(), "closed": True}))
    out = tmp_path / "out"
    data = cli_json("synth", "curve", f, "--max-links", "4", "--top", "1", "--time-limit", "4",
                    "--database", small_db, "--out", out)
    c = data["candidates"][0]
    assert c["links"] == 4 and c["topology"] == "four-bar" and c["tracer"] == "T"
    assert (out / "candidate_1.yaml").exists() and (out / "candidate_1.png").exists()
    code, _, err = run_cli("synth", "curve", tmp_path / "missing.csv", "--database", small_db)
    assert code == 2 and "no such target file" in err
    s = cli_json("curves", "build", "--links", "4", "--per-topology", "50", "--database", tmp_path / "db")
    assert s["curves"] == 50 and s["topologies"] == 1


def test_default_database_builds_on_first_use(tmp_path, monkeypatch):
    from mechsyn.synthesis.curves import database

    monkeypatch.setattr(database, "DEFAULT_PER_TOPOLOGY", 40)
    monkeypatch.setenv("MECHSYN_CURVE_DB", str(tmp_path / "cache"))
    states = []
    db = load_database(max_links=4, progress=states.append)
    assert len(db) == 40 and (tmp_path / "cache").is_dir()
    assert states[0].done == 0 and states[-1].done == states[-1].total == 1 and states[-1].stage == "build"
    assert states[-1].message == "40 curves"
    with pytest.raises(MechsynInputError, match="no curve database"):
        load_database(tmp_path / "empty", build_if_missing=False)


def test_eight_bar_candidates_run_in_closed_form_and_match_simulate():
    from mechsyn.synthesis.curves.database import evaluate_designs, sample_designs

    eight = [t for t in curve_topologies(8) if t.n_links == 8]
    assert len(eight) == 279 and all(t.plan.n_dyads == 3 for t in eight)
    assert len({t.chain.certificate for t in eight}) == 12   # 4 of the 16 chains need a triad whatever the frame
    rng = np.random.default_rng(8)
    for t in (eight[0], eight[140], eight[-1]):
        ev = evaluate_designs(t, sample_designs(t, 300, rng))
        assert ev.closed.any()
        x = ev.designs[np.flatnonzero(ev.closed)[0]]
        mech = mechanism_from_dict(t.mechanism(x))
        from mechsyn.kinematics.batch import compile_plan, simulate_batch

        off = np.arange(0.0, 360.0, 5.0)
        ref = compile_plan(mech, points=["T"]).reference_input
        sim = simulate(mech, {t.plan.input_joint: ref + off}, points=["T"])
        np.testing.assert_allclose(simulate_batch(t.plan, x, off).paths["T"][0], sim.points["T"].position,
                                   atol=1e-9)
