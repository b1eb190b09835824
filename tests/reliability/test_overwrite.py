"""Outputs never replace a file the command did not write, unless --force (issue 18):
``--out`` of ``synth path``/``synth mechanism``/``synth finger-design`` and
``convert -o`` refuse, before any work, an existing file that is not a mechanism file."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from mechsyn.cli.common import check_overwrite, is_mechanism_file
from mechsyn.errors import MechsynInputError

ROOT = Path(__file__).resolve().parents[2]
EX = ROOT / "examples"
PYSLVS = EX / "pyslvs" / "crank_rocker.pyslvs"
NOTES = "my design notes: do not lose\n"


@pytest.mark.parametrize("name, text, expected", [
    ("m.yaml", (EX / "fingers" / "two_phalanx_vll_000.yaml").read_text(), True),
    ("m.json", '{"name": "x", "links": ["ground", "a"], "joints": []}', True),
    ("empty.yaml", "", True),
    ("m.pyslvs", PYSLVS.read_text(), True),
    ("notes.yaml", NOTES, False),
    ("case.yaml", (EX / "fingers" / "finger_design_case.yaml").read_text(), False),   # a case, not a mechanism
    ("list.json", '[1, 2]', False),
    ("bad.json", '{"links": [', False),
    ("m.txt", NOTES, False),
])
def test_what_counts_as_a_mechanism_file(tmp_path, name, text, expected):
    path = tmp_path / name
    path.write_text(text)
    assert is_mechanism_file(path) is expected


def test_binary_file_is_not_a_mechanism_file(tmp_path):
    path = tmp_path / "plot.yaml"
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe")
    assert not is_mechanism_file(path)


def test_check_overwrite_refuses_names_option_and_fix(tmp_path):
    path = tmp_path / "notes.yaml"
    path.write_text(NOTES)
    with pytest.raises(MechsynInputError, match="not a mechanism file; not overwritten") as exc:
        check_overwrite(path, "--out")
    assert "--force" in str(exc.value) and "--out" in str(exc.value)
    check_overwrite(path, "--out", force=True)              # --force: allowed
    check_overwrite(tmp_path / "new.yaml", "--out")         # a new file: allowed
    check_overwrite(None, "--out")
    check_overwrite("-", "--out")                           # stdout


def _notes(tmp_path, name="notes.yaml"):
    path = tmp_path / name
    path.write_text(NOTES)
    return path


def _no_work(*args, **kwargs):
    raise AssertionError("the search ran before the output was checked")


@pytest.mark.parametrize("command, target", [
    (["synth", "path", EX / "synthesis" / "path_cases_public.json", "--case", "P2_kk5_timing"],
     "mechsyn.synthesis.reports.path_synthesis"),
    (["synth", "mechanism", EX / "synthesis" / "slider_crank_path_case.yaml"],
     "mechsyn.synthesis.reports.mechanism_synthesis"),
    (["synth", "finger-design", EX / "fingers" / "finger_design_case.yaml"],
     "mechsyn.synthesis.finger.design.design_finger"),
])
def test_synth_out_refuses_a_foreign_file_before_any_work(run_cli, tmp_path, monkeypatch, command, target):
    monkeypatch.setattr(target, _no_work)
    notes = _notes(tmp_path)
    code, out, err = run_cli(*command, "--out", notes)
    assert code == 2 and "not a mechanism file; not overwritten" in err and "--force" in err
    assert len(err.strip().splitlines()) == 1 and notes.read_text() == NOTES


def test_synth_out_replaces_its_own_output_and_force_replaces_anything(run_cli, tmp_path):
    data = yaml.safe_load((EX / "fingers" / "finger_design_case.yaml").read_text())
    data["mechanism"] = str(EX / "fingers" / data["mechanism"])
    data["optimizer"] = {"maxiter": 4, "popsize": 5, "force_maxiter": 1, "vll_steps": 3, "candidates": 1}
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump(data))
    out = tmp_path / "best.yaml"
    for _ in range(2):                                       # the second run replaces the first's file
        code, _, err = run_cli("synth", "finger-design", case, "--json", "--out", out)
        assert code == 0, err
        assert is_mechanism_file(out)
    notes = _notes(tmp_path)
    code, _, err = run_cli("synth", "finger-design", case, "--json", "--out", notes, "--force")
    assert code == 0, err
    assert is_mechanism_file(notes)


def test_convert_refuses_a_foreign_file_unless_force(run_cli, tmp_path):
    notes = _notes(tmp_path)
    code, _, err = run_cli("convert", PYSLVS, "-o", notes)
    assert code == 2 and "not overwritten" in err and notes.read_text() == NOTES
    code, _, err = run_cli("convert", PYSLVS, "-o", notes, "--force")
    assert code == 0, err
    assert is_mechanism_file(notes)
    code, _, err = run_cli("convert", PYSLVS, "-o", notes)   # now a mechanism file: replaced
    assert code == 0, err
    back = _notes(tmp_path, "back.pyslvs")
    code, _, err = run_cli("convert", notes, "-o", back)
    assert code == 2 and "not overwritten" in err
    back.unlink()
    for _ in range(2):
        code, _, err = run_cli("convert", notes, "-o", back)
        assert code == 0, err
