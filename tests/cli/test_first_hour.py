"""The small stumbles of a first hour (issue 26 §7): "did you mean", every written file
named on stderr, the link table in columns at 80 columns, each example listed once."""

from __future__ import annotations

import pytest

from conftest import EXAMPLES


def test_a_mistyped_example_name_gets_did_you_mean(run_cli):
    code, out, err = run_cli("analyze", "fourbarr")
    assert code == 2 and out == ""
    assert "did you mean the example 'fourbar'" in err and len(err.strip().splitlines()) == 1
    code, _, err = run_cli("simulate", "crank_rockr", "-i", "A=0:10:5")
    assert code == 2 and "'crank_rocker'" in err
    code, _, err = run_cli("analyze", "nothing_like_any_example")
    assert code == 2 and "did you mean" not in err


def test_a_mistyped_command_gets_did_you_mean(run_cli):
    code, _, err = run_cli("analyz", "fourbar")
    assert code == 2 and "Did you mean 'analyze'" in err
    code, _, err = run_cli("synth", "pth")
    assert code == 2 and "Did you mean 'path'" in err


def test_examples_module_suggests_names():
    import mechsyn as ms
    from mechsyn.errors import MechsynInputError

    with pytest.raises(MechsynInputError, match="did you mean 'crank_rocker'"):
        ms.examples.load("crank_roker")


def test_each_example_is_listed_once_and_a_yaml_before_its_urdf():
    import mechsyn as ms

    table = ms.examples.list()
    keys = [(e.folder, e.name) for e in table]
    assert len(keys) == len(set(keys))
    arm = [e for e in table if e.name == "paper004_3r"]
    assert len(arm) == 1 and arm[0].path == ms.examples.path("paper004_3r")


@pytest.mark.parametrize("argv, written", [
    (["simulate", "crank_rocker", "-i", "A=0:360:60", "--plot", "{d}/p.png", "--animate", "{d}/a.gif",
      "--csv", "{d}/c.csv"], ["p.png", "a.gif", "c.csv"]),
    (["analyze", "fourbar", "--markdown", "-o", "{d}/r.md"], ["r.md"]),
    (["analyze", "fourbar", "--json", "-o", "{d}/r.json"], ["r.json"]),
    (["schema", "-o", "{d}/s.json"], ["s.json"]),
    (["convert", str(EXAMPLES / "pyslvs" / "crank_rocker.pyslvs"), "-o", "{d}/m.yaml"], ["m.yaml"]),
    (["export", "fourbar", "--drawing", "{d}/d.svg", "--svg", "{d}/plates.svg"], ["d.svg", "plates.svg"]),
    (["atlas", "-n", "4", "--mechanisms", "{d}/chains", "--out", "{d}/atlas.svg"], ["chains", "atlas.svg"]),
])
def test_every_written_file_is_named_on_stderr(argv, written, run_cli, tmp_path):
    code, _, err = run_cli(*[a.replace("{d}", str(tmp_path)) for a in argv])
    assert code == 0, err
    for name in written:
        assert (tmp_path / name).exists()
        assert f"wrote {tmp_path / name}" in err, err


def test_link_table_has_a_column_per_quantity_at_80_columns(run_cli, cli_json):
    from mechsyn.cli.common import console

    assert console.width == 80
    argv = ("simulate", "crank_rocker", "-i", "A=0:360:60")
    code, out, _ = run_cli(*argv)
    assert code == 0
    assert all(len(ln) <= 80 for ln in out.splitlines())
    heads = [[h.strip() for h in ln.strip("┃").split("┃")] for ln in out.splitlines() if ln.startswith("┃ A deg")]
    link_heads = [h for hs in heads for h in hs if h.split()[-1] in ("θ", "ω", "α")]
    d = cli_json(*argv)
    links = list(d["links"])
    assert link_heads == [f"{n} {q}" for n in links[:4] for q in ("θ", "ω", "α")]
    # every cell one number: the crank's angle column reads the inputs back
    lines = out.splitlines()
    start = next(k for k, ln in enumerate(lines) if ln.startswith(f"┃ A deg ┃ {links[0]} θ"))
    crank_col = [h.strip() for h in lines[start].strip("┃").split("┃")].index(f"{links[0]} θ")
    first_table = [ln for ln in lines[start:] if ln.startswith("│")][:7]
    values = [float(r.strip("│").split("│")[crank_col]) for r in first_table]
    assert values == pytest.approx(d["links"][links[0]]["angle"], abs=1e-3)
