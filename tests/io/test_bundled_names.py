"""A ``pip install mechsyn`` user has no examples/ folder: every reader takes a bundled
example's name, and a case file's relative mechanism path is read beside the bundled case."""

from __future__ import annotations

import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.io.convert import load_any
from mechsyn.io.files import resolve_path


@pytest.fixture
def elsewhere(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # no examples/ here
    return tmp_path


def test_case_files_by_name_find_their_mechanism_beside_them(elsewhere):
    from mechsyn.synthesis.cases import load_mechanism_case
    from mechsyn.synthesis.finger.cases import load_case

    assert load_case("finger_design_case").mech_dict["joints"]
    assert load_mechanism_case("sixbar_path_case").n_targets > 0


def test_a_pyslvs_example_by_folder_and_file(elsewhere):
    m = load_any("pyslvs/jansen.pyslvs")
    assert len(m.links) >= 8


def test_a_local_file_wins_over_the_example_of_that_name(elsewhere):
    (elsewhere / "fourbar.yaml").write_text("name: mine\n")
    assert resolve_path("fourbar.yaml").resolve() == (elsewhere / "fourbar.yaml").resolve()


@pytest.mark.parametrize("name", ["pyslvs/../../../etc/passwd", "../examples/pyslvs/jansen.pyslvs", "/nonexistent/x.yaml"])
def test_names_do_not_reach_outside_the_bundled_folder(elsewhere, name):
    with pytest.raises(MechsynInputError):
        load_any(name)
