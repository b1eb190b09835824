"""One drive too many, said before any simulation: one line in ``analyze``'s verdict (text,
JSON, Markdown), exit 2 with one line from ``simulate`` and ``forces``."""

from __future__ import annotations

import json

import pytest

import mechsyn as ms
from mechsyn.io import mechanism_from_dict, mechanism_to_dict, write_mechanism

LINE = "2 drives (A, D) for mobility 1"


@pytest.fixture
def two_drives(tmp_path):
    """The four-bar example with its rocker's pivot D driven too."""
    d = mechanism_to_dict(ms.examples.load("fourbar"))
    next(j for j in d["joints"] if j["id"] == "D")["actuated"] = True
    path = tmp_path / "fourbar_two_drives.yaml"
    write_mechanism(mechanism_from_dict(d), path)
    return path


@pytest.mark.parametrize("method", ["both", "rank", "formulas"])
def test_analyze_names_the_drive_in_excess_in_its_verdict(two_drives, run_cli, method):
    code, out, err = run_cli("analyze", two_drives, "--method", method)
    assert code == 0, err
    line = next(ln for ln in out.splitlines() if "drives:" in ln and LINE in ln)
    assert "drop `actuated: true` on D" in line  # the whole message on one line of the panel
    code, out, _ = run_cli("analyze", two_drives, "--method", method, "--json")
    v = json.loads(out)
    assert v["verdict"]["over_actuation"].startswith(LINE)
    assert v["drive_check"]["excess"] == ["D"] and v["drive_check"]["mobility"] == 1
    assert v["drive_check"]["source"] == ("formulas" if method == "formulas" else "rank method")
    code, out, _ = run_cli("analyze", two_drives, "--method", method, "--markdown")
    assert f"{LINE}: drop `actuated: true` on D" in out.split("**Verdict**")[1].splitlines()[0]


def test_analyze_of_a_mechanism_with_its_drives_says_nothing_of_them(run_cli, cli_json):
    for name in ("fourbar", "five_bar_5r", "delta"):
        d = cli_json("analyze", name)
        assert d["verdict"]["over_actuation"] is None and d["drive_check"]["excess"] == [], name
    code, out, _ = run_cli("analyze", "fourbar")
    assert "drives:" not in out.split("╰")[0]


@pytest.mark.parametrize("command", ["simulate", "forces"])
def test_simulate_refuses_in_one_line_before_the_sweep(two_drives, run_cli, command):
    code, out, err = run_cli(command, two_drives, "--input", "A=0:90:10")
    assert code == 2 and out == ""
    assert err.strip().splitlines() == [
        f"error: {two_drives}: {LINE}: give --input for D or drop `actuated: true` on D"]


def test_simulate_runs_when_every_drive_is_given_or_the_drives_are_independent(two_drives, run_cli, cli_json):
    """Both drives given: the user's choice (the sweep says where it does not assemble). A
    five-bar (mobility 2) with one of its two drives given holds the other: it moves."""
    code, _, err = run_cli("simulate", two_drives, "--input", "A=63.4349", "--input", "D=71.5651")
    assert code == 0, err
    d = cli_json("simulate", "five_bar_5r", "--input", "A=80:100:5")
    assert all(d["assembled"])


def test_the_library_raises_the_error_with_the_check():
    from mechsyn.errors import MechsynInputError, OverActuatedError

    d = mechanism_to_dict(ms.examples.load("fourbar"))
    next(j for j in d["joints"] if j["id"] == "D")["actuated"] = True
    with pytest.raises(OverActuatedError) as err:
        ms.simulate(mechanism_from_dict(d), {"A": [0.0, 10.0]})
    assert isinstance(err.value, MechsynInputError)
    assert err.value.check.excess == ["D"] and err.value.check.mobility == 1
    assert "give D an input too" in str(err.value)
