"""The smaller stumbles of a first hour, second pass (issue 39 §7): Ctrl-C during a lazy
import, a plot of nothing refused, ``belt analyze`` short and consistent, ``mechsyn
examples``, the curve database's first build said, plain wording."""

from __future__ import annotations

import json

import pytest

from conftest import EXAMPLES


# --------------------------------------------------------------------------- Ctrl-C
def _cut_import(*args):
    """An import cut by Ctrl-C, as Python sometimes reports it: a RuntimeError from it."""
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as ki:
        raise RuntimeError(f"module mechsyn.cli.{name} failed to import") from ki


def test_ctrl_c_during_a_lazy_import_exits_130_without_a_traceback(monkeypatch, run_cli):
    import mechsyn.cli.main as cli_main

    # (where the command's module is imported, or was by an earlier test)
    monkeypatch.setattr(cli_main, "build_cli", _cut_import)
    code, out, err = run_cli("analyze", "fourbar")
    assert code == 130 and out == ""
    assert err.strip() == "interrupted"


def test_a_bug_raised_without_ctrl_c_is_not_called_an_interruption(monkeypatch, run_cli):
    import mechsyn.cli.main as cli_main

    def broken():
        raise RuntimeError("a bug")
    monkeypatch.setattr(cli_main, "build_cli", broken)
    with pytest.raises(RuntimeError, match="a bug"):
        run_cli("analyze", "fourbar")


# --------------------------------------------------------------------------- --plot of nothing
@pytest.mark.parametrize("command", ["simulate", "forces"])
def test_plot_of_a_range_where_nothing_assembles_is_refused_and_nothing_written(command, run_cli, tmp_path):
    png, csv = tmp_path / "p.png", tmp_path / "t.csv"
    code, out, err = run_cli(command, "fourbar", "--input", "A=150:200:5", "--plot", png, "--csv", csv)
    assert code == 2 and out == ""
    assert err.strip().splitlines() == [
        "error: nothing to plot: the mechanism is not assembled at any input (fix: widen the input range, or "
        "start it inside the working range)"]
    assert not png.exists() and not csv.exists()


# --------------------------------------------------------------------------- belt analyze
def test_belt_analyze_is_short_consistent_and_names_no_class(run_cli, cli_json):
    case = EXAMPLES / "belt" / "paper001.yaml"
    code, out, err = run_cli("belt", "analyze", "--file", case)
    assert code == 0, err
    lines = out.splitlines()
    assert len(lines) < 100  # 159 positions: two tables of at most 25 rows, and the summary tables
    assert "tables show 25 of 159 positions" in " ".join(out.split())
    assert "Law" not in out and "input law: trapezoidal speed" in out
    quality = next(ln for ln in lines if ln.startswith("│ travel with"))
    belt_row = next(ln for ln in lines if ln.startswith("│ belt "))
    h_travel = quality.strip("│ ").split("│")[-1].strip()
    assert belt_row.rstrip(" │").split()[-1] == h_travel  # one travel figure, the same in both tables
    d = cli_json("belt", "analyze", "--file", case)
    assert d["paths"]["H"]["translation_length"] == pytest.approx(
        d["four_bar_comparison"]["belt"]["H"]["translation_length"], rel=1e-9)
    assert d["motion"]["law_text"].startswith("trapezoidal speed")
    assert len(d["rows"]) == 159  # the JSON keeps every position


# --------------------------------------------------------------------------- mechsyn examples
def test_examples_lists_every_bundled_example_by_folder(run_cli, cli_json):
    import mechsyn as ms

    code, out, _ = run_cli("examples")
    assert code == 0 and all(len(ln) <= 80 for ln in out.splitlines())
    names = {ln.split()[0] for ln in out.splitlines() if ln.startswith("  ")}
    assert names == {e.name for e in ms.examples.list()}
    assert "textbook/" in out.splitlines() and "kinematics/" in out.splitlines()
    listed = cli_json("examples")
    assert {e["name"] for e in listed} == names
    assert all(ms.examples.path(e["name"]).exists() for e in listed)


def test_examples_by_folder_and_by_word(run_cli, cli_json):
    assert {e["folder"] for e in cli_json("examples", "--folder", "textbook")} == {"textbook"}
    found = cli_json("examples", "bennett")
    assert {e["name"] for e in found} == {"bennett", "bennett_4dp", "bennett_tilted"}
    assert {e["name"] for e in cli_json("examples", "four", "--folder", "textbook")} >= {"fourbar", "fourbar_taut"}
    code, _, err = run_cli("examples", "--folder", "txtbook")
    assert code == 2 and "--folder" in err and "did you mean 'textbook'" in err
    code, _, err = run_cli("examples", "no-such-word-anywhere")
    assert code == 2 and "no example matches" in err and len(err.strip().splitlines()) == 1


def test_a_missing_file_points_to_mechsyn_examples(run_cli):
    code, _, err = run_cli("analyze", "fourbarr")
    assert code == 2 and "`mechsyn examples` lists them all" in err
    code, _, err = run_cli("analyze", "no/such/file.yaml")
    assert code == 2 and "`mechsyn examples`" in err


# --------------------------------------------------------------------------- the curve database
def test_the_first_build_of_the_curve_database_is_said(tmp_path, capsys):
    from mechsyn.cli.synth_curve import _say_first_build

    _say_first_build(tmp_path / "db")
    assert "building the curve database on first use" in capsys.readouterr().err
    (tmp_path / "db").mkdir()
    (tmp_path / "db" / "fourbar.npz").write_bytes(b"")
    _say_first_build(tmp_path / "db")
    assert capsys.readouterr().err == ""


# --------------------------------------------------------------------------- wording
def test_wording_no_parenthesised_plurals_and_the_rocker_angle_said(run_cli):
    code, out, _ = run_cli("analyze", "delta")
    assert code == 0 and "(ies)" not in out
    code, out, _ = run_cli("synth", "function", "--help")
    flat = " ".join(out.split())
    assert "rocker's direction from its frame pivot D" in flat and "counter-clockwise" in flat


def test_fourbar_mechanism_dict_refuses_in_one_line_with_a_mechsyn_error():
    from mechsyn.errors import MechsynError
    from mechsyn.synthesis.export import fourbar_mechanism_dict

    with pytest.raises(MechsynError) as err:
        fourbar_mechanism_dict(10.0, 1.0, 2.0, 2.0, 0.0)
    assert "does not assemble at crank angle 0 deg" in str(err.value) and "\n" not in str(err.value)
    assert json.loads(json.dumps(fourbar_mechanism_dict(4.0, 1.0, 3.5, 3.0, 0.0)))["joints"][0]["actuated"]
