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
        assert set(f) == {"value", "expression"}
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
