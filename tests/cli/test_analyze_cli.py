import json

from conftest import EXAMPLES

S = EXAMPLES / "structural"

CONTRACT_KEYS = {
    "name", "kind", "moving_links", "pairs_by_class", "independent_contours", "formulas", "contours",
    "structural_redundancy", "constructive_redundancy", "degrees_of_mobility", "mobility", "states",
}
FORMULA_KEYS = {"chebyshev", "grubler", "malyshev", "somov_malyshev", "ozol_redundant", "gokhman_contours"}
CONTOUR_KEYS = {"joints", "new_pairs", "S", "T", "Z", "A", "n_j", "n_k"}


def test_json_contract(cli_json):
    d = cli_json("analyze", S / "gripper_002_fig1_spatial.yaml")
    assert CONTRACT_KEYS <= set(d)
    assert FORMULA_KEYS <= set(d["formulas"])
    for f in d["formulas"].values():
        assert set(f) == {"value", "expression", "label", "counts", "value_text", "why_it_differs"}
    assert d["formulas"]["chebyshev"]["value"] is None  # spatial file
    for c in d["contours"]:
        assert CONTOUR_KEYS <= set(c)
    assert CONTRACT_KEYS - {"states"} <= set(d["states"]["clamped"])
    assert "external" in d["states"]["clamped"]


def test_terminal_report(run_cli):
    code, out, _ = run_cli("analyze", S / "robot_actuator_003.yaml")
    assert code == 0
    assert "W = 6·7 - 3·2 - 4·1 - 5·6 + 1 = 3" in out
    assert "S2 = 3 - (5-3)·2 - (5-5)·1 = -1" in out


def test_markdown_report(run_cli, tmp_path):
    out_file = tmp_path / "r.md"
    code, out, _ = run_cli("analyze", S / "gripper_002_fig1_remedy.yaml", "--markdown", "--remedies", "-o", out_file)
    assert code == 0 and out == ""
    text = out_file.read_text()
    assert text.startswith("# Central paired crank-slider gripper")
    assert "σ = 59 - [6(10 - 1) - 0 + 6 - 1] = 0" in text
    assert "## Remedies" in text


def test_remedies_json(cli_json):
    d = cli_json("analyze", S / "robot_actuator_003.yaml", "--remedies", "--max-variants", "3")
    assert len(d["remedies"]) == 3
    for r in d["remedies"]:
        assert all(c["S"] == 0 for c in r["contours"])
        assert r["mobility"] == 3


def test_schema(run_cli):
    code, out, _ = run_cli("schema")
    assert code == 0
    schema = json.loads(out)
    assert {"name", "ground", "links", "joints"} <= set(schema["required"])
    assert "class" in json.dumps(schema)


def test_formulas_table_reads_at_80_columns(run_cli):
    """The value column never wraps: its header and every number stand whole at 80 columns
    (the clamped state's long Ozol expression wraps inside its own column instead)."""
    from mechsyn.cli.common import console

    assert console.width == 80  # captured output: Rich's default width
    code, out, _ = run_cli("analyze", S / "gripper_002_fig1_spatial.yaml")
    assert code == 0
    heads = [ln for ln in out.splitlines() if "formula" in ln and "expression" in ln]
    assert len(heads) == 2 and all(ln.rstrip(" ┃").endswith("value") for ln in heads)
    rows = [ln for ln in out.splitlines() if ln.startswith("│ Malyshev (spatial)")]
    assert [ln.rstrip(" │").split()[-1] for ln in rows] == ["-10", "-15"]
    assert all(len(ln) <= 80 for ln in out.splitlines() if ln[:1] in "┏┃│└")


# --------------------------------------------------------------------------- the first answer (issue 26)
def _paragraphs(out: str, label: str = "note:") -> list[str]:
    """The notes of a terminal report, their wrapped lines joined back (one space each)."""
    paras, cur = [], None
    for ln in out.splitlines():
        if ln.startswith(label + " "):
            cur = [ln[len(label) + 1:]]
            paras.append(cur)
        elif cur is not None and ln.startswith(" " * (len(label) + 1)) and ln.strip():
            cur.append(ln.strip())
        else:
            cur = None
    return [" ".join(p) for p in paras]


def test_analyze_leads_with_the_verdict_of_the_rank_method(run_cli, cli_json):
    code, out, _ = run_cli("analyze", "fourbar")
    assert code == 0
    verdict = cli_json("analyze", "fourbar")["verdict"]
    assert (verdict["mobility"], verdict["idle_mobilities"], verdict["redundant_constraints"]) == (1, 0, 0)
    assert verdict["source"].startswith("exact rank method")
    flat = " ".join(out.replace("│", " ").split())
    assert flat.index("verdict: moves with 1 degree of freedom (finite); drives needed: 1; instantaneous mobility 1 "
                      "(no idle mobility), 0 redundant constraints") < flat.index("Formulas")


def test_spatial_readings_of_a_planar_file_stand_apart_and_say_so(run_cli, cli_json):
    """The crank-rocker's Malyshev W = -2 and paper 003's S_Σ = 3 come after a labelled
    heading, never among the planar formulas, and the negative W is explained in one note."""
    code, out, _ = run_cli("analyze", "fourbar")
    heading = out.index("Spatial reading of this planar mechanism")
    assert out.index("Chebyshev (planar)") < heading < out.index("Malyshev (spatial)")
    assert heading < out.index("counted as a 3-D build: S_Σ = 3")
    d = cli_json("analyze", "fourbar")
    assert d["formula_sections"]["spatial_reading_of_planar"] == ["malyshev", "somov_malyshev"]
    assert d["formula_readings"]["malyshev"] == "spatial" and d["formula_readings"]["chebyshev"] == "planar"
    why = d["formula_explanations"]["malyshev"]
    assert why.startswith("W = -2 < 0") and any(why in p for p in _paragraphs(out, "differs:"))
    assert set(d["formula_explanations"]) == {"malyshev"}  # nothing else is negative
    md_out = run_cli("analyze", "fourbar", "--markdown")[1]
    assert md_out.index("**Verdict**") < md_out.index("## Formulas (planar") \
        < md_out.index("## Spatial reading") < md_out.index("Malyshev (spatial)")


def test_negative_q_of_a_spatial_file_is_explained_against_the_rank_method(cli_json):
    d = cli_json("analyze", S / "gough_stewart_6sps.yaml")
    assert d["formula_sections"]["spatial_reading_of_planar"] == []
    assert d["formulas"]["ozol_redundant"]["value"] < 0
    why = d["formula_explanations"]["ozol_redundant"]
    rank = d["rank"]
    assert f"below the instantaneous mobility {rank['mobility']}" in why
    v = d["verdict"]
    assert v["instantaneous_mobility"] == rank["mobility"] == v["mobility"] + v["idle_mobilities"]


def test_without_geometry_the_verdict_takes_the_planar_reading(tmp_path, cli_json):
    f = tmp_path / "fourbar_topology.yaml"
    f.write_text("name: four-bar, no geometry\nkind: planar\nground: g\nlinks: [g, a, b, c]\njoints:\n"
                 "  - {id: A, type: R, links: [g, a]}\n  - {id: B, type: R, links: [a, b]}\n"
                 "  - {id: C, type: R, links: [b, c]}\n  - {id: D, type: R, links: [c, g]}\n")
    v = cli_json("analyze", f)["verdict"]
    assert (v["mobility"], v["redundant_constraints"], v["idle_mobilities"]) == (1, 0, None)
    assert "formulas, planar reading" in v["source"]


def test_notes_wrap_at_word_boundaries_at_80_columns(run_cli, cli_json):
    from mechsyn.cli.common import console

    assert console.width == 80
    for target in ("fourbar", S / "gough_stewart_6sps.yaml", S / "gripper_002_fig1_spatial.yaml"):
        code, out, _ = run_cli("analyze", target)
        d = cli_json("analyze", target)
        notes = d.get("notes", []) + d["rank"]["notes"]
        paras = _paragraphs(out)
        assert notes and all(any(n in p for p in paras) for n in notes), [n for n in notes if not any(n in p for p in paras)]
        assert [ln for ln in out.splitlines() if len(ln) > 80] == []


def test_no_table_has_two_columns_of_one_name(run_cli):
    for target in ("fourbar", S / "gough_stewart_6sps.yaml"):
        out = run_cli("analyze", target)[1]
        for ln in out.splitlines():
            if ln.startswith("┃"):
                heads = [h.strip() for h in ln.strip("┃").split("┃") if h.strip()]
                assert len(heads) == len(set(heads)), ln


def test_no_grashof_class_for_a_spatial_four_r_mechanism():
    """Four links and four R pairs make a Grashof four-bar only in the plane (issue 25 §6)."""
    import numpy as np

    import mechsyn as ms
    from mechsyn.kinematics.report import derived_quantities
    from mechsyn.structure.rank import as_spatial

    planar = ms.examples.load("crank_rocker")
    sim = ms.simulate(planar, {"A": np.linspace(0, 90, 4)})
    assert "grashof" in derived_quantities(planar, sim)
    assert "grashof" not in derived_quantities(as_spatial(planar), sim)


def test_every_printed_formula_names_its_reading(run_cli):
    for target in ("fourbar", S / "gough_stewart_6sps.yaml"):
        out = run_cli("analyze", target)[1]
        titles = [ln.split("│")[1].strip() for ln in out.split("Contours")[0].splitlines()
                  if ln.startswith("│") and ln.count("│") == 4 and ln.split("│")[1].strip()]
        assert titles and all(t.endswith(("(planar)", "(spatial)", "(topology)")) for t in titles), titles
