"""The papers' formulas in ``analyze`` say what they count and, where they disagree with the
verdict's exact answer, why, in one sentence; the internal keys are never shown (the JSON
keeps them as keys, with labels beside them)."""

from __future__ import annotations

import json
import re

import pytest
from test_printed_formulas import _strings  # every string of a JSON document

KEYS = ("chebyshev", "grubler", "malyshev", "somov_malyshev", "gokhman_contours", "scheme_check",
        "ozol_redundant", "redundant_from_mobility")
NAMES = ["fourbar", "delta", "bennett", "double_parallelogram", "watt_sixbar", "gripper_003", "rssr"]


@pytest.mark.parametrize("name", NAMES)
def test_no_internal_key_reaches_a_reader(name, run_cli):
    texts = []
    for fmt in ((), ("--markdown",), ("--json",)):
        code, out, err = run_cli("analyze", name, *fmt)
        assert code == 0, err
        if fmt == ("--json",):
            data = json.loads(out)
            assert set(data["formula_sections"]["own"]) <= set(data["formulas"])  # lists of keys, for programs
            del data["formula_sections"]
            texts += _strings(data)
        else:
            texts.append(out)
    for text in texts:
        found = [k for k in KEYS if re.search(rf"\b{k}\b", text)]
        assert not found, (found, text[:200])


@pytest.mark.parametrize("name", NAMES)
def test_every_formula_that_disagrees_with_the_exact_answer_says_why(name, cli_json):
    d = cli_json("analyze", name)
    v = d["verdict"]
    rank = d["rank"]
    for key, f in d["formulas"].items():
        assert f["label"] and f["counts"], key
        if f["value"] is None or d["formula_readings"][key] == "topology":
            continue
        if f["counts"] == "mobility" and rank is not None and f["value"] != v["mobility"]:
            assert f["why_it_differs"], key
        if f["counts"] == "redundant constraints" and rank is not None and f["value"] != v["redundant_constraints"]:
            assert f["why_it_differs"], key
        if f["why_it_differs"]:
            assert f["why_it_differs"].count(". ") == 0, f["why_it_differs"]  # one sentence
    s = d["formula_summary"]
    if rank is not None:
        assert bool(s["drives"]["why_it_differs"]) == (s["drives"]["value"] != rank["useful_mobility"])
    assert d["formulas"]["scheme_check"]["value_text"] in ("yes", "no")


def test_delta_at_80_columns_labels_each_line_and_says_why(run_cli):
    code, out, _ = run_cli("analyze", "delta")
    assert code == 0 and all(len(ln) <= 80 for ln in out.splitlines())
    lines = out.splitlines()

    def block(start: str) -> str:
        k = next(i for i, ln in enumerate(lines) if ln.startswith(start))
        end = next(i for i in range(k + 1, len(lines)) if not lines[i].startswith(" "))
        return " ".join(ln.strip() for ln in lines[k:end])

    assert "W = 0" in block("mobility by the formulas") and "the mobility is 3" in block("mobility by the formulas")
    assert "= 4" in block("drives by paper 003's rule") and "needs 3 drives" in block("drives by paper 003's rule")
    red = block("redundant constraints per contour")
    assert "S_Σ = -9" in red and "finds 0 redundant constraints and 6 idle mobilities" in red
    assert "│   yes │" in out  # the scheme check's 1 read as yes


def test_fourbar_spatial_reading_says_why_it_finds_3_redundant_constraints(run_cli, cli_json):
    code, out, _ = run_cli("analyze", "fourbar")
    assert code == 0 and all(len(ln) <= 80 for ln in out.splitlines())
    text = " ".join(out.split())
    assert "counted as a 3-D build: S_Σ = 3" in text
    assert "the planar mechanism has 0 (the verdict)" in text
    d = cli_json("analyze", "fourbar")
    assert d["formula_summary"]["redundancy"]["why_it_differs"].startswith("A planar loop repeats 3")
    assert d["formula_summary"]["mobility"]["why_it_differs"] is None  # Chebyshev agrees with the rank
