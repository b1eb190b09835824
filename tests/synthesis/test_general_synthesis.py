"""Path / motion synthesis of any planar mechanism file (mechsyn.synthesis.general,
``mechsyn synth mechanism``)."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from mechsyn.cli.main import main
from mechsyn.synthesis.general import (MechanismProblem, evaluate_mechanism_design, load_mechanism_case,
                                       mechanism_case_from_dict, start_vector, synthesize_mechanism)
from mechsyn.synthesis.path import PathCase
from mechsyn.synthesis.path import evaluate_design as fourbar_evaluate

ROOT = Path(__file__).resolve().parents[2]
FOURBAR = ROOT / "examples" / "textbook" / "fourbar.yaml"
SIXBAR_CASE = ROOT / "examples" / "synthesis" / "sixbar_path_case.yaml"
SLIDER_CASE = ROOT / "examples" / "synthesis" / "slider_crank_path_case.yaml"
VALUES = [40, 50, 60, 70, 80, 90]
X_TRUE = np.array([0.8, 4.2, 5.2, 3.8])        # B.x, C.x, D.x, M.y
FAST = {"maxiter": 40}   # generations: deterministic budgets (no timing in the tests)


def fourbar_case(targets=None, variables=None, **extra):
    data = {"mechanism": str(FOURBAR), "input": {"joint": "A", "values_deg": VALUES}, "point": "M",
            "targets": targets if targets is not None else [[0, 0]] * len(VALUES),
            "variables": variables or [{"joint": "B", "coord": "x", "lower": 0.5, "upper": 1.5},
                                       {"joint": "C", "coord": "x", "lower": 3.5, "upper": 4.5},
                                       {"joint": "D", "coord": "x", "lower": 4.5, "upper": 5.5},
                                       {"point": "M", "coord": "y", "lower": 3.5, "upper": 4.5}]}
    data.update(extra)
    return mechanism_case_from_dict(data, source="<test>")


def targets_of(case, x):
    ev = evaluate_mechanism_design(case, x)
    assert ev.feasible, ev.reason
    return ev.achieved.tolist()


def test_recovers_known_fourbar_design():
    c0 = fourbar_case()
    case = fourbar_case(targets_of(c0, X_TRUE))
    assert evaluate_mechanism_design(case, start_vector(case)).error > 0.1        # the file's design is off
    res = synthesize_mechanism(case, seed=1, time_limit=120, restarts=1, options=FAST)
    assert res.feasible and res.method == "assur"
    assert res.error < 1e-12
    assert np.allclose(list(res.design.values()), X_TRUE, atol=1e-5)


def _fourbar_pathcase(d, case):
    """The closed-form four-bar path module's case for the drawn four-bar dict ``d``."""
    P = {j["id"]: np.array(j["point"], float) for j in d["joints"]}
    A, B, C, D = P["A"], P["B"], P["C"], P["D"]
    M = np.array(d["points"]["M"]["at"], float)
    th0 = np.arctan2(*(D - A)[::-1])
    u = (C - B) / np.linalg.norm(C - B)
    n = np.array([-u[1], u[0]])
    g = D - B
    branch = -1 if g[0] * (C - B)[1] - g[1] * (C - B)[0] > 0 else 1    # C left of B->D: Cabrera's minus root
    fixed = {"x0": A[0], "y0": A[1], "theta0": th0, "r1": np.linalg.norm(D - A), "r2": np.linalg.norm(B - A),
             "r3": np.linalg.norm(C - B), "r4": np.linalg.norm(D - C), "rcx": (M - B) @ u, "rcy": (M - B) @ n}
    pc = PathCase.from_dict({
        "id": "general-vs-fourbar", "targets": case.targets.tolist(),
        "timing": {"type": "prescribed", "theta2": (np.radians(case.values_deg) - th0).tolist()},
        "fixed": {k: float(v) for k, v in fixed.items()}, "variables": [],
        "kinematics": {"branch": branch}})
    return pc


@pytest.mark.parametrize("x", [X_TRUE, np.array([1.0, 4.0, 5.0, 4.0]), np.array([1.3, 3.7, 4.8, 3.6])])
def test_error_agrees_with_closed_form_fourbar_module(x):
    from mechsyn.synthesis.general import apply_mechanism_design

    case = fourbar_case(targets_of(fourbar_case(), X_TRUE + [0.05, -0.1, 0.1, 0.2]))
    ev = evaluate_mechanism_design(case, x)
    pc = _fourbar_pathcase(apply_mechanism_design(case, x), case)
    ref = fourbar_evaluate(pc, {})
    assert ev.feasible and ref["feasible"]
    assert ev.error == pytest.approx(ref["error"], rel=1e-9, abs=1e-14)
    assert np.allclose(ev.achieved, ref["path"], atol=1e-10)


def test_sixbar_reaches_small_error_from_perturbed_design_targets():
    case = load_mechanism_case(SIXBAR_CASE)
    assert evaluate_mechanism_design(case, start_vector(case)).error == pytest.approx(0.7122631869, rel=1e-6)
    res = synthesize_mechanism(case, seed=0, time_limit=120, restarts=1, options=FAST)
    assert res.feasible and res.method == "assur"
    assert res.error < 1e-10


def test_newton_and_closed_form_evaluations_agree_on_the_sixbar():
    case = load_mechanism_case(SIXBAR_CASE)
    newton = dataclasses.replace(case, method="newton")
    for x in (start_vector(case), np.array([5.3, 5.8, 6.7, 6.2, 4.8]), np.array([4.6, 6.4, 7.0, 5.5, 4.5])):
        a, b = evaluate_mechanism_design(case, x), evaluate_mechanism_design(newton, x)
        assert (a.method, b.method) == ("assur", "newton")
        assert a.feasible and b.feasible
        assert b.error == pytest.approx(a.error, rel=1e-8, abs=1e-14)


@pytest.mark.slow
def test_slider_crank_path_synthesis_closed_form():
    case = load_mechanism_case(SLIDER_CASE)
    res = synthesize_mechanism(case, seed=0, time_limit=120, restarts=1, options=FAST)
    assert res.feasible and res.method == "assur"
    assert res.error < 1e-10
    # the crank length of the generating design (B = (0.6, 0.9)) is recovered
    assert np.hypot(res.design["B.x"], res.design["B.y"]) == pytest.approx(np.hypot(0.6, 0.9), rel=1e-6)


def test_motion_generation_recovers_coupler_poses():
    c0 = mechanism_case_from_dict({"mechanism": str(FOURBAR), "input": {"joint": "A", "values_deg": VALUES},
                         "link": "coupler", "poses": [[0, 0, 0]] * len(VALUES),
                         "variables": [{"joint": "C", "coord": "x", "lower": 3.5, "upper": 4.5},
                                       {"joint": "D", "coord": "x", "lower": 4.5, "upper": 5.5}]}, "<test>")
    xt = np.array([4.2, 5.2])
    ev = evaluate_mechanism_design(c0, xt)
    poses = np.column_stack([ev.achieved, ev.achieved_angles_deg]).tolist()
    case = dataclasses.replace(c0, targets=np.array(poses)[:, :2], angles_deg=np.array(poses)[:, 2])
    assert evaluate_mechanism_design(case, xt).error < 1e-20
    assert evaluate_mechanism_design(case, start_vector(case)).error > 1e-3
    res = synthesize_mechanism(case, seed=0, time_limit=120, restarts=1, options=FAST)
    assert res.error < 1e-12 and np.allclose(list(res.design.values()), xt, atol=1e-5)


def test_infeasible_designs_score_above_every_feasible_one():
    wide = [{"joint": "B", "coord": "x", "lower": -3, "upper": 3},
            {"joint": "C", "coord": "x", "lower": 0, "upper": 8},
            {"joint": "C", "coord": "y", "lower": -4, "upper": 6},
            {"joint": "D", "coord": "x", "lower": 2, "upper": 12}]
    case = fourbar_case([[30.0, -20.0]] * len(VALUES), wide)        # far targets: big feasible errors
    prob = MechanismProblem(case)
    X = np.random.default_rng(0).uniform(prob.lower, prob.upper, size=(300, 4))
    evs = prob.evaluate(X)
    f = prob.fitness(X)
    feas = np.array([e.feasible for e in evs])
    assert feas.sum() > 10 and (~feas).sum() > 10
    assert f[~feas].min() > f[feas].max()
    assert np.all(f[feas] == np.array([e.error for e in evs])[feas])     # not capped here


def test_dead_point_between_targets_is_infeasible():
    # the file's four-bar is a triple rocker: one full crank turn from 60 to 420 deg passes
    # its dead points, although it assembles at both targets (the same position)
    case = fourbar_case(input={"joint": "A", "values_deg": [60, 420]}, targets=[[0, 0], [0, 0]])
    ev = evaluate_mechanism_design(case, start_vector(case))
    assert not ev.feasible and "not assembled" in ev.reason
    case1 = fourbar_case(input={"joint": "A", "values_deg": [60]}, targets=[[0, 0]])
    case2 = fourbar_case(input={"joint": "A", "values_deg": [420]}, targets=[[0, 0]])
    assert evaluate_mechanism_design(case1, start_vector(case1)).feasible
    assert evaluate_mechanism_design(case2, start_vector(case2)).feasible


def test_other_assembly_branch_is_infeasible():
    case = fourbar_case(variables=[{"joint": "C", "coord": "x", "lower": -10, "upper": 10},
                                   {"joint": "C", "coord": "y", "lower": -10, "upper": 10}])
    B, D, C = np.array([1.0, 2.0]), np.array([5.0, 0.0]), np.array([4.0, 3.0])
    u = (D - B) / np.linalg.norm(D - B)
    mirror = B + 2 * ((C - B) @ u) * u - (C - B)        # C reflected in the line B-D: same lengths
    assert evaluate_mechanism_design(case, C).feasible
    ev = evaluate_mechanism_design(case, mirror)
    assert not ev.feasible and "branch" in ev.reason
    assert MechanismProblem(case).fitness(mirror[None, :])[0] > MechanismProblem(case).penalty_base


def test_free_timing_keeps_order_and_fits():
    c0 = fourbar_case()
    T = targets_of(c0, X_TRUE)
    case = fourbar_case(T, [{"point": "M", "coord": "y", "lower": 3.5, "upper": 4.5}],
                        input={"joint": "A", "values_deg": [v + 4 for v in VALUES], "free": True,
                               "range_deg": [30, 100]})
    assert case.names[-1] == "A_6" and len(case.lower) == 1 + len(VALUES)
    x = np.concatenate([[3.8], VALUES])
    assert evaluate_mechanism_design(case, x).feasible
    x_bad = np.concatenate([[3.8], VALUES[::-1][:1] + VALUES[1:-1] + VALUES[:1]])  # out of order
    ev = evaluate_mechanism_design(case, x_bad)
    assert not ev.feasible and "order" in ev.reason
    res = synthesize_mechanism(case, seed=0, time_limit=120, restarts=1, options=FAST)
    assert res.feasible
    th = np.array([res.design[f"A_{i + 1}"] for i in range(len(VALUES))])
    assert np.all(np.diff(th) > 0)
    assert res.error < evaluate_mechanism_design(case, np.concatenate([[3.8], [v + 4 for v in VALUES]])).error


def test_cli_writes_file_that_simulate_reproduces(tmp_path, capsys):
    c0 = fourbar_case()
    T = targets_of(c0, X_TRUE)
    f = tmp_path / "case.yaml"      # two variables only: the optimum keeps a non-zero error
    f.write_text(yaml.safe_dump({"mechanism": str(FOURBAR), "input": {"joint": "A", "values_deg": VALUES},
                                 "point": "M", "targets": T,
                                 "variables": [{"joint": "D", "coord": "x", "lower": 4.5, "upper": 5.5},
                                               {"point": "M", "coord": "x", "lower": 2.5, "upper": 3.5}]}))
    out, png = tmp_path / "best.yaml", tmp_path / "best.png"
    assert main(["synth", "mechanism", str(f), "--seed", "3", "--time-limit", "30", "--restarts", "1",
                 "--json", "--out", str(out), "--plot", str(png)]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("error", "design", "feasible", "assembled_at_all_targets", "seconds", "achieved", "targets"):
        assert key in data
    assert data["feasible"] and set(data["design"]) == {"D.x", "M.x"}
    case = load_mechanism_case(f)
    assert 1e-8 < data["error"] < evaluate_mechanism_design(case, start_vector(case)).error
    assert png.stat().st_size > 1000
    assert main(["simulate", str(out), "-i", "A=" + ",".join(map(str, VALUES)), "--points", "M", "--json"]) == 0
    sim = json.loads(capsys.readouterr().out)
    P = np.array(sim["points"]["M"]["position"])
    assert np.sum((P - np.array(T)) ** 2) == pytest.approx(data["error"], rel=1e-9)
    assert main(["analyze", str(out), "--json"]) == 0            # the other tools read it
    assert json.loads(capsys.readouterr().out)["formulas"]["chebyshev"]["value"] == 1


def test_cli_table_on_sixbar_example(capsys):
    assert main(["synth", "mechanism", str(SIXBAR_CASE), "--time-limit", "2", "--restarts", "1"]) == 0
    out = capsys.readouterr().out
    assert "G.x" in out and "error" in out


@pytest.mark.parametrize("patch, opts, word", [
    ({"mechanism": "nope.yaml"}, [], "nope.yaml"),
    ({"colour": 1}, [], "unknown key"),
    ({"point": "Z"}, [], "no point"),
    ({"input": {"joint": "B", "values_deg": VALUES}}, [], "actuated"),
    ({"input": {"joint": "A", "values_deg": VALUES[:3]}}, [], "targets"),
    ({"variables": [{"joint": "Q", "coord": "x", "lower": 0, "upper": 1}]}, [], "no joint"),
    ({"variables": [{"joint": "B", "coord": "z", "lower": 0, "upper": 1}]}, [], "coord"),
    ({"variables": [{"joint": "B", "coord": "x", "lower": 2, "upper": 1}]}, [], "lower < upper"),
    ({"variables": [{"joint": "B", "length": True, "lower": 0, "upper": 1}]}, [], "variable-length"),
    ({"link": "coupler"}, [], "either"),
    ({}, ["--time-limit", "0"], "positive"),
    ({}, ["--plot", "x.jpg"], ".png"),
])
def test_cli_bad_inputs_exit_2(tmp_path, capsys, patch, opts, word):
    data = {"mechanism": str(FOURBAR), "input": {"joint": "A", "values_deg": VALUES}, "point": "M",
            "targets": [[1, 1]] * len(VALUES),
            "variables": [{"joint": "B", "coord": "x", "lower": 0.5, "upper": 1.5}]}
    data.update(patch)
    f = tmp_path / "case.yaml"
    f.write_text(yaml.safe_dump(data))
    assert main(["synth", "mechanism", str(f), *opts]) == 2
    assert word in capsys.readouterr().err


def test_cli_missing_case_file_exits_2(tmp_path, capsys):
    assert main(["synth", "mechanism", str(tmp_path / "none.yaml")]) == 2


def test_vll_length_variable_on_paper_000_finger():
    """A locked VLL's length (paper 000's finger) as a design variable: the locked model is
    evaluated (closed form), and Newton on the same model agrees."""
    finger = ROOT / "examples" / "fingers" / "two_phalanx_vll_000.yaml"
    data = {"mechanism": str(finger), "input": {"joint": "E", "values_deg": [0, 10, 20, 30, 40]},
            "point": "tip", "targets": [[0, 0]] * 5,
            "variables": [{"joint": "S", "length": True, "lower": 24, "upper": 34},
                          {"joint": "C", "coord": "x", "lower": 4, "upper": 12}]}
    c0 = mechanism_case_from_dict(data, "<test>")
    assert start_vector(c0)[0] == pytest.approx(np.hypot(16, 24))     # |KL| of the file
    data["targets"] = targets_of(c0, [30.0, 9.0])
    case = mechanism_case_from_dict(data, "<test>")
    newton = dataclasses.replace(case, method="newton")
    a, b = evaluate_mechanism_design(case, [29.0, 8.0]), evaluate_mechanism_design(newton, [29.0, 8.0])
    assert (a.method, b.method) == ("assur", "newton")
    assert b.error == pytest.approx(a.error, rel=1e-8)
    res = synthesize_mechanism(case, seed=0, time_limit=120, restarts=1, options=FAST)
    assert res.error < 1e-12
    assert res.design["S.length"] == pytest.approx(30.0, abs=1e-5)
    # the written design keeps the VLL, drawn at the synthesised length
    S = next(j for j in res.mechanism["joints"] if j["id"] == "S")
    K = next(j for j in res.mechanism["joints"] if j["id"] == "K")
    assert np.hypot(*np.subtract(S["point"], K["point"])) == pytest.approx(res.design["S.length"])
    assert S["vll"] == "locked"


def test_cli_reports_infeasible_case_and_writes_nothing(tmp_path, capsys):
    f = tmp_path / "case.yaml"      # a full turn of the triple rocker: no design within the bounds moves so
    f.write_text(yaml.safe_dump({"mechanism": str(FOURBAR), "input": {"joint": "A", "values_deg": [60, 420]},
                                 "point": "M", "targets": [[0, 0], [0, 0]],
                                 "variables": [{"point": "M", "coord": "y", "lower": 3.5, "upper": 4.5}]}))
    assert main(["synth", "mechanism", str(f), "--time-limit", "5", "--restarts", "1", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["feasible"] is False and data["error"] is None and "not assembled" in data["reason"]
    out = tmp_path / "x.yaml"
    assert main(["synth", "mechanism", str(f), "--time-limit", "5", "--restarts", "1", "--out", str(out)]) == 2
    assert not out.exists() and "no feasible design" in capsys.readouterr().err



def _batch_equals_engine(case, Z):
    fast, slow = MechanismProblem(case), MechanismProblem(case, batch=False)
    assert fast.batch is not None and slow.batch is None
    a, b = fast.evaluate(Z), slow.evaluate(Z)
    assert [e.feasible for e in a] == [e.feasible for e in b]
    assert 0 < sum(e.feasible for e in b) < len(b)   # both kinds are compared
    for ea, eb in zip(a, b):
        if ea.feasible:
            assert abs(ea.error - eb.error) <= 1e-9 * max(1.0, eb.error)
            np.testing.assert_allclose(ea.achieved, eb.achieved, atol=1e-9)
    np.testing.assert_allclose(fast.fitness(Z), slow.fitness(Z), rtol=1e-9)
    np.testing.assert_allclose(fast.residuals(Z[0]), slow.residuals(Z[0]), atol=1e-9)


def _population(case, rng, spread):
    from mechsyn.synthesis.general import start_vector

    p = MechanismProblem(case, batch=False)
    Z = p.lower + rng.random((30, len(p.lower))) * (p.upper - p.lower)
    Z[0] = np.clip(start_vector(case), p.lower, p.upper)
    Z[15:] = Z[0] + rng.normal(scale=spread, size=(15, len(p.lower)))   # outside the bounds too
    return Z


def test_batch_population_evaluation_equals_the_engine():
    case = load_mechanism_case(SIXBAR_CASE)
    _batch_equals_engine(case, _population(case, np.random.default_rng(0), 1.5))


def test_batch_equals_the_engine_when_the_crank_moves():
    case = mechanism_case_from_dict({
        "mechanism": str(FOURBAR), "input": {"joint": "A", "values_deg": [40, 50, 60, 70, 80, 90]},
        "point": "M", "targets": [[3, 4]] * 6,
        "variables": [{"joint": "B", "coord": "x", "lower": 0.5, "upper": 1.5},
                      {"joint": "B", "coord": "y", "lower": 1.5, "upper": 2.5},
                      {"joint": "D", "coord": "x", "lower": 4.8, "upper": 5.2},
                      {"point": "M", "coord": "y", "lower": 3.8, "upper": 4.2}]}, "<test>")
    _batch_equals_engine(case, _population(case, np.random.default_rng(1), 1.0))
