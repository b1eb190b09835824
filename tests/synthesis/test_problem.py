"""One SynthesisResult base, one seed convention, one progress convention (issue 13)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import mechsyn as ms
from mechsyn._result import Result
from mechsyn.belt import BeltSynthesis, synthesize_belt
from mechsyn.synthesis.curves.synthesis import CurveSynthesisResult, _result
from mechsyn.synthesis.curves.target import target_from_points
from mechsyn.synthesis.fourbar import fourbar_position
from mechsyn.synthesis.general import MechanismSynthesisResult, load_mechanism_case, synthesize_mechanism
from mechsyn.synthesis.optimize import PathSynthesisResult, restart_seeds, synthesize_path
from mechsyn.synthesis.path import PathCase
from mechsyn.synthesis.problem import COMMON_KEYS, Progress, SynthesisResult, as_generator, resolve_seed

from mechsyn.synthesis.finger.design import FingerDesign  # noqa: E402

FAST = {"maxiter": 6, "popsize": 6}


def _path_case() -> PathCase:
    th = [0.0, 0.4, 0.8, 1.2, 1.6]
    C = fourbar_position(3.0, 1.0, 3.0, 2.5, np.array(th), branch=-1, rcx=1.0, rcy=1.0).C
    return PathCase.from_dict({
        "id": "known", "targets": C.tolist(), "timing": {"type": "prescribed", "theta2": th},
        "fixed": {"x0": 0.0, "y0": 0.0, "theta0": 0.0},
        "variables": [{"name": n, "lower": lo, "upper": 6.0} for n, lo in
                      (("r1", 0.1), ("r2", 0.1), ("r3", 0.1), ("r4", 0.1), ("rcx", -6.0), ("rcy", -6.0))]})


def _path(seed, **kw):
    return synthesize_path(_path_case(), seed=seed, time_limit=60, restarts=2, options=FAST, n_polish=1, **kw)


@pytest.mark.parametrize("cls", [PathSynthesisResult, MechanismSynthesisResult, CurveSynthesisResult,
                                 BeltSynthesis, FingerDesign])
def test_every_synthesis_result_is_one(cls):
    assert issubclass(cls, SynthesisResult) and issubclass(cls, Result)


def test_path_result_has_the_common_keys_and_repeats_with_int_and_generator():
    states: list[Progress] = []
    a = _path(11, progress=states.append)
    assert isinstance(a, SynthesisResult) and set(COMMON_KEYS) <= set(a.to_dict())
    assert a.seed == 11 and a.x.size > 0 and set(a.design) >= {"r1", "r2", "r3", "r4"}
    assert a.feasible == (a.reason == "" or a.reason.startswith("a bound decides this result"))
    assert states and all(isinstance(s, Progress) and s.total == 2 for s in states) and states[-1].done == 2
    assert np.array_equal(_path(11).x, a.x)
    g1, g2 = _path(np.random.default_rng(5)), _path(np.random.default_rng(5))
    assert g1.seed == g2.seed and np.array_equal(g1.x, g2.x)
    # the recorded seed repeats a Generator's run
    assert np.array_equal(_path(g1.seed).x, g1.x)


def test_mechanism_result_has_the_common_keys_and_repeats():
    case = load_mechanism_case(ms.examples.path("slider_crank_path_case"))
    states: list[Progress] = []
    run = lambda seed, **kw: synthesize_mechanism(case, seed=seed, time_limit=60, restarts=1,  # noqa: E731
                                                  options=FAST, n_polish=1, **kw)
    a = run(np.random.default_rng(3), progress=states.append)
    d = a.to_dict()
    assert set(COMMON_KEYS) <= set(d) and d["design"] == a.design and np.array_equal(d["x"], a.x)
    assert a.x.size == len(a.design) and states and states[-1].done == 1
    assert np.array_equal(run(a.seed).x, a.x)


def test_curve_and_belt_results_have_the_common_keys():
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    res = _result(target_from_points(np.c_[3 * np.cos(t), np.sin(t)]), [], 0.5, 0, 0, 0, False,
                  ["no database design matched the options"])
    d = res.to_dict()
    assert set(COMMON_KEYS) <= set(d) and not res.feasible and "no verified candidate" in res.reason
    assert math.isnan(res.error) and res.seed is None
    b = synthesize_belt((-350, 600), (300, 560), math.radians(-55), 75)
    assert set(COMMON_KEYS) <= set(b.to_dict())


def test_seed_helpers():
    assert resolve_seed(4) == 4 and resolve_seed(np.int64(4)) == 4
    fresh = resolve_seed(None)
    assert isinstance(fresh, int) and fresh >= 0
    g = as_generator(9)
    assert isinstance(g, np.random.Generator) and as_generator(g) is g
    assert restart_seeds(np.random.default_rng(1), 3) == restart_seeds(np.random.default_rng(1), 3)
    assert restart_seeds(7, 3) == [int(s.generate_state(1)[0]) for s in np.random.SeedSequence(7).spawn(3)]
    for bad in (-1, 1.5, "7", True):
        with pytest.raises(ms.MechsynInputError) as e:
            resolve_seed(bad)
        assert e.value.field == "seed"


def test_a_search_reports_the_one_progress_of_mechsyn():
    import mechsyn.progress

    assert Progress is mechsyn.progress.Progress and ms.synthesis.Progress is Progress  # no second one
    p = Progress(done=3, total=4, stage="refine", best=0.1)
    assert p.fraction == 0.75 and p.to_dict() == {"done": 3, "total": 4, "stage": "refine", "best": 0.1, "message": ""}
