"""``synth mechanism`` on the topology-keyed fast path (issue 30, part D): each design's
numbers filled into the case's parsed mechanism and compiled plan give the evaluations
and the synthesis results of the general path (each design's dict parsed and its
constraint system built), recorded here by calling the general path explicitly
(``fast=False``)."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import mechsyn.synthesis.general as general
from mechsyn.synthesis.general import (MechanismProblem, evaluate_mechanism_design, load_mechanism_case,
                                       mechanism_case_from_dict, synthesize_mechanism)

ROOT = Path(__file__).resolve().parents[2]
FOURBAR = ROOT / "examples" / "textbook" / "fourbar.yaml"
FINGER = ROOT / "examples" / "fingers" / "two_phalanx_vll_000.yaml"
VALUES = [40, 50, 60, 70, 80, 90]
WIDE = [{"joint": "B", "coord": "x", "lower": -3, "upper": 3},
        {"joint": "B", "coord": "y", "lower": -1, "upper": 3},
        {"joint": "C", "coord": "x", "lower": 0, "upper": 8},
        {"joint": "D", "coord": "x", "lower": 2, "upper": 12},
        {"point": "M", "coord": "y", "lower": 3, "upper": 5}]


def _fourbar(**extra):
    data = {"mechanism": str(FOURBAR), "input": {"joint": "A", "values_deg": VALUES}, "point": "M",
            "targets": [[3.0, 4.0]] * len(VALUES), "variables": WIDE}
    data.update(extra)
    data = {k: v for k, v in data.items() if v is not None}
    return mechanism_case_from_dict(data, "<test>")


def _finger(mechanism=FINGER, variables=None):
    return mechanism_case_from_dict({
        "mechanism": str(mechanism), "input": {"joint": "E", "values_deg": [0, 10, 20, 30, 40]},
        "point": "tip", "targets": [[0, 60], [-5, 60], [-10, 58], [-15, 55], [-20, 50]],
        "variables": variables or [{"joint": "S", "length": True, "lower": 24, "upper": 34},
                                   {"joint": "C", "coord": "x", "lower": 4, "upper": 12}]}, "<test>")


def _cases(tmp):
    active = tmp / "finger_active.yaml"  # the VLL driven: its P joint stays, its axis moves with the length
    active.write_text(FINGER.read_text().replace("vll: locked", "vll: active"))
    return {
        "slider-crank (RRP)": load_mechanism_case(ROOT / "examples" / "synthesis" / "slider_crank_path_case.yaml"),
        "Watt six-bar": load_mechanism_case(ROOT / "examples" / "synthesis" / "sixbar_path_case.yaml"),
        "four-bar, wide bounds": _fourbar(),
        "four-bar, motion": _fourbar(point=None, targets=None, link="coupler",
                                     poses=[[3.0, 4.0, 10.0 * k] for k in range(len(VALUES))]),
        "four-bar, free timing": _fourbar(input={"joint": "A", "values_deg": VALUES, "free": True,
                                                "range_deg": [20, 120]}),
        "finger, locked VLL length": _finger(),
        "finger, driven VLL length (Newton)": _finger(active),
    }


def _same(a, b, what):
    """Every field of two evaluations equal (arrays and numbers to 1e-12, texts exactly)."""
    for f in dataclasses.fields(a):
        u, v = getattr(a, f.name), getattr(b, f.name)
        if isinstance(u, np.ndarray) or isinstance(v, np.ndarray):
            assert u is not None and v is not None and np.shape(u) == np.shape(v), (what, f.name)
            assert np.allclose(u, v, rtol=0, atol=1e-12, equal_nan=True), (what, f.name)
        elif isinstance(u, float) and np.isfinite(u):
            assert v == pytest.approx(u, rel=1e-12, abs=1e-12), (what, f.name)
        else:
            assert u == v, (what, f.name)


def test_fast_path_evaluates_every_design_as_the_general_path(tmp_path):
    rng = np.random.default_rng(7)
    for name, case in _cases(tmp_path).items():
        assert general._template(case) is not None, name  # the case is on the fast path
        lo, hi = case.lower, case.upper
        n = 6 if "Newton" in name else 40
        X = rng.uniform(lo - 0.3 * (hi - lo), hi + 0.3 * (hi - lo), size=(n, len(lo)))  # infeasible ones too
        if case.free:  # most in order
            X[: n // 2, case.n_design:] = np.sort(X[: n // 2, case.n_design:], axis=1)
        kinds = set()
        for x in X:
            a, b = evaluate_mechanism_design(case, x), evaluate_mechanism_design(case, x, fast=False)
            _same(a, b, name)
            kinds.add(a.feasible)
        assert True in kinds, name


def test_designs_the_reader_refuses_get_its_message_on_the_fast_path():
    pins = [{"joint": j, "coord": c, "lower": -8, "upper": 8} for j in "BC" for c in (0, 1)]
    case = _fourbar(variables=[{**v, "coord": "xy"[v["coord"]]} for v in pins])
    # B on A: the crank has zero length; C on B: the coupler (the reader's geometry check)
    for x, word in (([0.0, 0.0, 4.0, 3.0], "'crank' has zero length"),
                    ([1.0, 2.0, 1.0, 2.0], "'coupler' has zero length")):
        a, b = evaluate_mechanism_design(case, x), evaluate_mechanism_design(case, x, fast=False)
        assert not a.feasible and a.reason.startswith("cannot build") and word in a.reason, a.reason
        _same(a, b, word)


def test_fast_path_parses_nothing_per_design(monkeypatch):
    case = _fourbar()
    assert general._template(case) is not None
    general.reference_branch(case)  # once per case, as the template

    def refuse(*args, **kwargs):
        raise AssertionError("a design was parsed or built on the fast path")

    monkeypatch.setattr(general, "mechanism_from_dict", refuse)
    monkeypatch.setattr(general, "build_system", refuse)
    monkeypatch.setattr(general.dyads, "decompose", refuse)
    X = np.random.default_rng(0).uniform(case.lower, case.upper, size=(10, len(case.lower)))
    evs = MechanismProblem(case, batch=False).evaluate(X)
    assert any(e.feasible for e in evs)


def test_cases_off_the_fast_path_fall_back_to_the_general_path():
    # a variable moves the VLL's P joint: its coincidence with the piston's pivot is the
    # design's, checked by the general path
    case = _finger(variables=[{"joint": "S", "coord": "x", "lower": 2, "upper": 6}])
    assert general._template(case) is None
    for x in ([4.0], [5.0]):
        a, b = evaluate_mechanism_design(case, x), evaluate_mechanism_design(case, x, fast=False)
        _same(a, b, "P joint moved")
    assert "VLL S" in evaluate_mechanism_design(case, [5.0]).reason


@pytest.mark.parametrize("name", [pytest.param("slider-crank (RRP)", marks=pytest.mark.slow),
                                  pytest.param("four-bar, motion", marks=pytest.mark.slow),
                                  "finger, locked VLL length"])
def test_same_seed_same_synthesis_on_both_paths(tmp_path, name):
    case = _cases(tmp_path)[name]
    opts = {"maxiter": 12}  # generations: a budget no time limit cuts
    runs = [synthesize_mechanism(case, seed=3, time_limit=600, restarts=2, n_polish=1, batch=False, options=opts,
                                 fast=fast)
            for fast in (False, True)]
    old, new = (r.to_dict() for r in runs)
    assert not runs[1].stopped_by_time_limit and runs[1].nfev == runs[0].nfev
    for key in old:
        if key == "seconds":
            continue
        u, v = old[key], new[key]
        if isinstance(u, (np.ndarray, list)) or isinstance(u, float):
            assert np.allclose(np.asarray(v, float), np.asarray(u, float), rtol=1e-12, atol=1e-12,
                               equal_nan=True), key
        else:
            assert u == v, key
    assert runs[0].mechanism == runs[1].mechanism and list(runs[0].x) == pytest.approx(list(runs[1].x), abs=1e-12)
