"""``mechsyn.belt.analyze_case`` -> BeltReport: the library behind ``mechsyn belt analyze``;
each belt command's ``--json`` is its library result's ``to_dict()``."""

from __future__ import annotations

import ast
import json
import math
from pathlib import Path

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.belt import (BeltDesign, BeltReport, BeltSynthesis, TrapezoidalLaw, analyze, analyze_case,
                          inverse_input, synthesize_belt)
from mechsyn.belt.report import phi_range
from mechsyn.results import dumps

PAPER = BeltDesign(a=500, c=350, h=100, r=75)
ARGS = ["--a", "500", "--c", "350", "--h", "100", "--r", "75"]
SRC = Path(__file__).resolve().parents[2] / "src" / "mechsyn"


def _same(cli_out: str, result) -> None:
    """The command's JSON is the result's ``to_dict()`` (but for the run's wall-clock time)."""
    got, want = json.loads(cli_out), json.loads(dumps(result.to_dict()))
    got.pop("seconds", None), want.pop("seconds", None)
    assert got == want


def test_analyze_json_is_the_report(run_cli):
    code, out, err = run_cli("belt", "analyze", *ARGS, "--phi", "-73:85:2", "--segment", "-60:0", "--tol", "2",
                             "--law", "trapezoidal", "--omega-max", "90", "--accel", "200", "--samples", "51",
                             "--json")
    assert code == 0, err
    rep = analyze_case(PAPER, phi_range(-73, 85, 2), segment=(math.radians(-60), 0.0),
                       translation_tol=math.radians(2),
                       law=TrapezoidalLaw(math.radians(-73), math.radians(85), math.radians(90), math.radians(200)),
                       samples=51)
    _same(out, rep)


def test_synthesize_json_is_the_result(run_cli):
    code, out, err = run_cli("belt", "synthesize", "--h0", "-350,600", "--hf", "300,560", "--phi", "-55",
                             "--r", "75", "--json")
    assert code == 0, err
    _same(out, synthesize_belt((-350, 600), (300, 560), math.radians(-55), 75))


def test_inverse_json_is_the_result(run_cli):
    code, out, err = run_cli("belt", "inverse", *ARGS, "--phi", "-73:0:1", "--speed", "800", "--accel", "50",
                             "--point", "C", "--json")
    assert code == 0, err
    _same(out, inverse_input(analyze(PAPER, phi_range(-73, 0, 1)), 800, 50, "C"))


def test_report_reads_in_a_notebook():
    rep = analyze_case(PAPER, phi_range(-73, 85, 1), name="paper 001")
    assert isinstance(rep, BeltReport) and rep.valid_positions == 159
    # the spec's figures: C ≈ 45 mm and H ≈ 21 mm above the design tangent, H ≈ 270 mm travel
    assert rep.paths["C"].max_positive_deviation == pytest.approx(44.92, abs=0.01)
    assert rep.paths["H"].max_positive_deviation == pytest.approx(20.94, abs=0.01)
    assert rep.paths["H"].translation_length == pytest.approx(270, abs=1)
    text = str(rep)
    assert text.startswith("BeltReport") and len(text.splitlines()) < 12 and "44.92" in text
    md = rep._repr_markdown_()
    for title in ("transfer functions", "paths of C and H", "straight-line quality", "belt mechanism vs."):
        assert f"**{title}" in md
    assert md.count("\n| -73.00 |") == 2          # the first row of both position tables
    d = rep.to_dict()
    assert d["motion"]["law"] == "ConstantSpeedLaw" and d["warnings"] == []
    assert ms.belt.analyze_case is analyze_case


def test_report_plot_draws_on_the_given_axes():
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    rep = analyze_case(PAPER, phi_range(-73, 85, 5))
    assert rep.plot(ax=ax) is ax
    labels = [line.get_label() for line in ax.lines]
    assert "path of C (h = 0)" in labels and "equivalent four-bar: H" in labels


def test_synthesis_carried_into_the_report():
    s = synthesize_belt((-350, 600), (300, 560), math.radians(-55), 75)
    rep = analyze_case(s, phi_range(-55, 0, 1))
    assert rep.synthesis is s and rep.design is s.design
    assert json.loads(dumps(rep.to_dict()))["synthesis"]["a"] == s.design.a


def test_slack_positions_are_reported_not_hidden():
    rep = analyze_case(BeltDesign(a=100, c=300, h=0, r=200), phi_range(-30, 40, 1))
    n = int(np.count_nonzero(~rep.state.valid))
    assert n > 0 and rep.warnings and f"at {n} of 71 positions" in rep.warnings[0]
    assert "warning" in str(rep)


@pytest.mark.parametrize("kwargs, fld", [
    ({"translation_tol": 0.0}, "tol"), ({"samples": 1}, "samples"),
    ({"segment": (math.radians(50), math.radians(60))}, "segment"),
])
def test_bad_arguments_name_the_parameter(kwargs, fld):
    with pytest.raises(ms.MechsynInputError) as e:
        analyze_case(PAPER, phi_range(0, 10, 1), **kwargs)
    assert e.value.field == fld


def test_whole_range_slack_raises():
    with pytest.raises(ms.MechsynInputError, match="slack") as e:
        analyze_case(BeltDesign(a=100, c=300, h=0, r=200), phi_range(-100, -20, 1))
    assert e.value.field == "phi"


def test_inverse_refuses_a_slack_range():
    st = analyze(BeltDesign(a=100, c=300, h=0, r=200), phi_range(-30, 40, 1))
    with pytest.raises(ms.MechsynInputError, match="slack") as e:
        inverse_input(st, 100.0)
    assert e.value.field == "phi"


def _lengths(path: Path) -> dict[str, int]:
    tree = ast.parse(path.read_text())
    return {n.name: n.end_lineno - n.lineno + 1 for n in ast.walk(tree)
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))}


def test_functions_are_short():
    for path in [*sorted((SRC / "belt").glob("*.py")), SRC / "plot" / "belt.py"]:
        long = {k: v for k, v in _lengths(path).items() if v > 100}
        assert not long, (path.name, long)
    commands = {k: v for k, v in _lengths(SRC / "cli" / "belt.py").items() if k.endswith("_cmd")}
    assert len(commands) == 3 and max(commands.values()) <= 40, commands


def test_computing_modules_import_no_presentation():
    for path in sorted((SRC / "belt").glob("*.py")):
        if path.name == "case_file.py":          # the file format: pydantic is its schema
            continue
        text = path.read_text()
        for lib in ("matplotlib", "pydantic", "yaml", "typer", "rich"):
            assert f"import {lib}" not in text and f"from {lib}" not in text, (path.name, lib)


def test_belt_synthesis_is_a_synthesis_result():
    from mechsyn.synthesis.problem import COMMON_KEYS, SynthesisResult

    s = synthesize_belt((-350, 600), (324.62, 597.49), math.radians(-60), 75)   # the spec's scene
    assert isinstance(s, BeltSynthesis) and isinstance(s, SynthesisResult)
    d = s.to_dict()
    assert set(COMMON_KEYS) <= set(d)
    assert d["design"]["a"] == s.design.a and d["nfev"] == 0 and d["seed"] is None
    assert s.error == pytest.approx(d["Hf_miss"]) and s.feasible and s.reason == ""
    assert s.x.tolist() == pytest.approx([s.design.a, s.design.c, s.design.h])
    # a scene the belt cannot serve: the checks pass, but H misses Hf by half a metre
    far = synthesize_belt((-350, 600), (300, 560), math.radians(-55), 75)
    assert all(far.checks.values()) and not far.feasible and far.error > 500
    assert "H misses Hf by 508.9" in far.reason


def test_case_file_through_the_library_is_the_command(run_cli):
    from mechsyn.belt import case_inputs, load_belt_case

    path = ms.examples.path("paper001")
    code, out, err = run_cli("belt", "analyze", "--file", path, "--json")
    assert code == 0, err
    args, kwargs = case_inputs(load_belt_case(str(path)))
    _same(out, analyze_case(*args, **kwargs))


def test_motion_law_names_what_is_missing():
    from mechsyn.belt import motion_law

    with pytest.raises(ms.MechsynInputError) as e:
        motion_law("trapezoidal", np.radians([0, 10]), omega_max_deg_s=90)
    assert e.value.field == "accel_deg_s2"
    with pytest.raises(ms.MechsynInputError, match="unknown law"):
        motion_law("wobble", np.radians([0, 10]))
    law = motion_law("constant", np.radians([10, 0]))
    assert law.evaluate([0.0])[1][0] == pytest.approx(-math.radians(60))
