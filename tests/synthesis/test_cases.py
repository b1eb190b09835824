"""Synthesis case files (mechsyn.synthesis.cases): loading validates and runs no solver."""

from pathlib import Path

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.synthesis import cases, general, path
from mechsyn.synthesis.cases import PathCase, mechanism_case_from_dict, load_mechanism_case

ROOT = Path(__file__).resolve().parents[2]
FOURBAR = ROOT / "examples" / "textbook" / "fourbar.yaml"
SIXBAR_CASE = ROOT / "examples" / "synthesis" / "sixbar_path_case.yaml"


def test_one_case_format_per_concept():
    assert path.PathCase is cases.PathCase and path.load_cases is cases.load_cases
    assert general.MechanismCase is cases.MechanismCase and general.load_mechanism_case is cases.load_mechanism_case
    assert not hasattr(general, "_err") and not hasattr(general, "_floats")


def test_loading_runs_no_solver(monkeypatch):
    def solver(*_a, **_k):
        raise AssertionError("the solver ran while a case was loaded")

    monkeypatch.setattr(general, "_drawing_branch", solver)
    case = load_mechanism_case(SIXBAR_CASE)
    assert case.reference is None
    monkeypatch.undo()
    signs = general.reference_branch(case)
    assert signs is case.reference and len(signs) >= 1 and all(abs(s) == 1 for s in signs)
    # the design the file draws keeps its own branch
    assert general.evaluate_mechanism_design(case, general.start_vector(case)).feasible


def test_a_design_off_the_drawn_branch_is_refused_without_synthesize():
    """evaluate_mechanism_design alone (no synthesize_mechanism) still checks the drawing's branch."""
    case = load_mechanism_case(SIXBAR_CASE)
    ev = general.evaluate_mechanism_design(case, general.start_vector(case))
    flipped = list(-np.asarray(general.reference_branch(case)))
    case.reference = flipped
    bad = general.evaluate_mechanism_design(case, general.start_vector(case))
    assert ev.feasible and not bad.feasible and "branch" in bad.reason


@pytest.mark.parametrize("data, field", [
    ({"targets": [[0, 1]], "timing": {"type": "prescribed", "theta2": [0, 1]}}, "timing.theta2"),
    ({"targets": [[0, 1], [1, 1]], "timing": {"type": "prescribed_increment"}}, "timing"),
    ({"targets": [[0, 1]], "timing": {"type": "free"}, "fixed": {"r9": 1}}, "fixed.r9"),
    ({"targets": [[0, 1]], "timing": {"type": "free"}, "fixed": {"r1": [1, 2]}}, "fixed.r1"),
    ({"targets": [[0, 1]], "timing": {"type": "prescribed", "theta2": [0]}, "options": {"order": "up"}},
     "variables"),
])
def test_path_case_errors_name_the_field(data, field):
    with pytest.raises(MechsynInputError) as exc:
        PathCase.from_dict(data, "c.json")
    assert exc.value.field == field and "c.json" in str(exc.value)


def test_path_case_increments_and_options():
    names = ("r1", "r2", "r3", "r4", "rcx", "rcy", "theta2_1")
    case = PathCase.from_dict({
        "targets": [[0, 1], [1, 1], [1, 0]], "timing": {"type": "prescribed_increment", "step": 0.5},
        "variables": [{"name": k, "lower": 0.1, "upper": 5} for k in names],
        "constraints": ["Grashof"], "options": {"transmission_angle_min_deg": None, "order": "cw"},
        "kinematics": {"branch": 1}})
    assert np.allclose(case.theta2, [0.0, 0.5, 1.0])
    assert (case.grashof, case.order, case.branch, case.transmission_angle_min_deg) == (True, "cw", 1, 0.0)
    assert case.fixed == {"x0": 0.0, "y0": 0.0, "theta0": 0.0}


@pytest.mark.parametrize("change, field", [
    ({"bogus": 1}, "bogus"),
    ({"input": {"joint": "Z", "values_deg": [0]}}, "input.joint"),
    ({"step_deg": 0}, "step_deg"),
    ({"method": "magic"}, "method"),
    ({"variables": [{"joint": "B", "coord": "z", "lower": 0, "upper": 1}]}, "variables[0]"),
    ({"variables": [{"point": "nowhere", "coord": "x", "lower": 0, "upper": 1}]}, "variables[0]"),
    ({"variables": [{"joint": "B", "coord": "x", "lower": 0, "upper": 1}] * 2}, "variables"),
    ({"targets": [[0, 0]]}, "input.values_deg"),
])
def test_mechanism_case_errors_name_the_field(change, field):
    data = {"mechanism": str(FOURBAR), "input": {"joint": "A", "values_deg": [40, 50]}, "point": "M",
            "targets": [[0, 0], [1, 0]], "variables": [{"joint": "B", "coord": "x", "lower": 0, "upper": 1}]}
    data.update(change)
    with pytest.raises(MechsynInputError) as exc:
        mechanism_case_from_dict(data, "case.yaml")
    assert exc.value.field == field and "case.yaml" in str(exc.value)
