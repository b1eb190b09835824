"""The size bound of ``synth path``: a four-bar's
frame pivots and pin circles stay within ``--max-size`` / ``options.max_size`` target
diagonals of the targets' centre; without either, the bounds a case states on its
variables are its design space; a bound the design sits on is named with how to lift it."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from dimsynth_data import public_cases, public_data  # noqa: F401  (fixtures)

from mechsyn.errors import MechsynInputError
from mechsyn.synthesis.curves.target import principal_diagonal
from mechsyn.synthesis.fourbar import fourbar_position
from mechsyn.synthesis.optimize import synthesize_path, with_size_bound
from mechsyn.synthesis.path import PathCase, PathProblem


def _known_case(r=(3.0, 1.0, 3.0, 2.5), rc=(1.0, 1.0)) -> tuple[PathCase, np.ndarray]:
    th = [0.0, 0.4, 0.8, 1.2, 1.6]
    C = fourbar_position(*r, np.array(th), branch=-1, rcx=rc[0], rcy=rc[1]).C
    case = PathCase.from_dict({
        "id": "known", "targets": C.tolist(), "timing": {"type": "prescribed", "theta2": th},
        "fixed": {"x0": 0.0, "y0": 0.0, "theta0": 0.0},
        "variables": [{"name": n, "lower": lo, "upper": 6.0} for n, lo in
                      (("r1", 0.1), ("r2", 0.1), ("r3", 0.1), ("r4", 0.1), ("rcx", -6.0), ("rcy", -6.0))]})
    return case, np.array([*r, *rc])


def test_the_known_large_linkage_is_outside_a_size_bound_and_inside_when_lifted():
    case, x = _known_case()
    bounded = PathProblem(with_size_bound(case, 1.5))
    lifted = PathProblem(with_size_bound(case, 0))
    assert with_size_bound(case, 1.5).max_size == 1.5 and lifted.case.max_size is None
    vals = bounded.unpack(x[None])[0]
    T = case.targets
    diag = principal_diagonal(T)
    # independently: the centroid of the closed polyline through the targets (each side's
    # midpoint weighted by its length), not the bounding box's centre
    sides = np.roll(T, -1, axis=0) - T
    w = np.hypot(*sides.T)
    centre = ((T + 0.5 * sides) * w[:, None]).sum(axis=0) / w.sum()
    assert np.hypot(*(centre - 0.5 * (T.min(axis=0) + T.max(axis=0)))) > 0.05 * diag
    # independently: pivot O2 at the origin, O4 at (r1, 0); crank and rocker circles
    expect = max(np.hypot(*centre) + x[1], np.hypot(*(centre - [x[0], 0])) + x[3])
    assert bounded.size(vals)[0] == pytest.approx(expect)
    assert expect / diag > 1.5
    assert lifted.evaluate(x[None]).feasible[0] and not bounded.evaluate(x[None]).feasible[0]
    assert PathProblem(with_size_bound(case, expect / diag * 1.01)).evaluate(x[None]).feasible[0]


def test_a_case_keeps_its_own_design_space_and_finds_its_exact_design():
    case, x = _known_case()
    assert with_size_bound(case).max_size is None     # no default overrides the case's variable bounds
    res = synthesize_path(case, seed=0, time_limit=60, restarts=2)
    d = res.to_dict()
    assert d["max_size"] is None and res.feasible and res.error < 1e-12
    assert d["size_ratio"] > 1.5 and d["limited_by"] == ""     # larger than the old default: nothing decided it
    with pytest.raises(MechsynInputError, match="max_size"):
        with_size_bound(case, -1.0)


def test_a_bound_that_decides_the_result_is_named_with_how_to_lift_it(cli_json, tmp_path):
    case, _ = _known_case()
    res = synthesize_path(case, seed=0, time_limit=60, restarts=3, max_size=2.0)
    assert res.feasible and res.error > 1e-6 and res.size_ratio == pytest.approx(2.0, rel=1e-5)
    assert "size bound 2" in res.limited_by and "--max-size 0" in res.limited_by
    assert res.reason == f"a bound decides this result: {res.limited_by}" == res.to_dict()["reason"]
    tight = dataclasses.replace(case, variables=tuple(
        dataclasses.replace(v, upper=2.0) if v.name == "r1" else v for v in case.variables))
    res = synthesize_path(tight, seed=0, time_limit=60, restarts=2)
    assert "r1 = 2 sits on its upper bound" in res.to_dict()["limited_by"]


def test_literature_cases_keep_their_design_space(public_cases):
    lit = public_cases["P2_kk5_timing"]
    assert with_size_bound(lit).max_size is None
    assert with_size_bound(dataclasses.replace(lit, published=())).max_size is None
    assert with_size_bound(lit, 2.0).max_size == 2.0


def test_case_option_and_cli_option(tmp_path, cli_json):
    case, _ = _known_case()
    raw = dict(case.raw, options={"max_size": 0})
    assert PathCase.from_dict(raw).max_size == 0 and with_size_bound(PathCase.from_dict(raw)).max_size is None
    with pytest.raises(MechsynInputError, match="options.max_size"):
        PathCase.from_dict(dict(case.raw, options={"max_size": "big"}))
    f = tmp_path / "case.json"
    f.write_text(json.dumps(case.raw))
    data = cli_json("synth", "path", f, "--restarts", "1", "--time-limit", "30", "--max-size", "0")
    assert data["max_size"] is None and data["feasible"]


def test_an_angle_limit_the_design_sits_on_is_named_too():
    from mechsyn.synthesis.optimize import bounds_deciding

    case, x = _known_case()
    d = dict(zip(("r1", "r2", "r3", "r4", "rcx", "rcy"), x))
    lim = case.transmission_angle_min_deg
    on = bounds_deciding(case, d, None, {"worst_transmission_angle_deg": lim, "fold_distance_deg": 40.0})
    assert on.startswith(f"the worst transmission angle {lim:g} deg sits on its limit") and "0 lifts it" in on
    assert bounds_deciding(case, d, None, {"worst_transmission_angle_deg": lim + 0.5}) == ""
    assert "fold" not in on     # a case without a Grashof constraint has no fold margin
    grashof = dataclasses.replace(case, grashof=True, fold_margin_deg=5.0)
    both = bounds_deciding(grashof, d, None, {"worst_transmission_angle_deg": 35.0, "fold_distance_deg": 5.0})
    assert "sits on the fold margin 5 (--fold-margin" in both and "transmission" not in both
