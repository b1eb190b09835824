"""The corpus of issue 18: every input that gave a traceback, a hang, a silent wrong answer,
a misleading message or a terminal injection, kept as a test. Each must exit 2 with one
line naming the file or option, the problem and the fix (or, where an answer exists,
exit 0 with an honest one)."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import pytest
import yaml

from mechsyn.errors import MechsynInputError

ROOT = Path(__file__).resolve().parents[2]
EX = ROOT / "examples"
FOURBAR = yaml.safe_load((EX / "kinematics" / "crank_rocker.yaml").read_text())
CAM = yaml.safe_load((EX / "kinematics" / "cam_polar.yaml").read_text())
PATH_CASES = ROOT / "tests" / "synthesis" / "data" / "synthesis_cases_public.json"
MECH_CASE = EX / "synthesis" / "slider_crank_path_case.yaml"


def fourbar(**edits) -> dict:
    d = copy.deepcopy(FOURBAR)
    for jid, point in edits.items():
        next(j for j in d["joints"] if j["id"] == jid)["point"] = point
    return d


def one_error_line(err: str) -> str:
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert lines and lines[0].startswith("error:"), err
    assert "Traceback" not in err
    return " ".join(ln.strip() for ln in lines)


def write(tmp_path: Path, name: str, data) -> Path:
    f = tmp_path / name
    if isinstance(data, bytes):
        f.write_bytes(data)
    elif isinstance(data, str):
        f.write_text(data, encoding="utf-8")
    else:
        f.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return f


# ----------------------------------------------------------------------- files every loader reads
LATIN1 = "name: caf\xe9\n".encode("latin-1")
DEEP_YAML = "name: " + "[" * 5000 + "]" * 5000 + "\n"
DEEP_BLOCK = "".join("  " * i + "- \n" for i in range(1500))
LAUGHS = "a: &a [x,x,x,x,x,x,x,x,x]\n" + "".join(
    f"{c}: &{c} [{', '.join(['*' + p] * 9)}]\n" for p, c in zip("abcdefgh", "bcdefghi"))

LOADER_COMMANDS = {
    "analyze": lambda f: ["analyze", f],
    "simulate": lambda f: ["simulate", f, "--input", "A=0:10:5"],
    "synth mechanism": lambda f: ["synth", "mechanism", f],
    "synth finger-design": lambda f: ["synth", "finger-design", f],
    "synth path": lambda f: ["synth", "path", f],
    "capability": lambda f: ["capability", f, "--direction", "1,0", "--point", "1,1"],
    "belt": lambda f: ["belt", "analyze", "--file", f],
}


UNREADABLE = {"latin1": (LATIN1, "not UTF-8"), "deep-flow": (DEEP_YAML, "nested more than"),
              "deep-block": (DEEP_BLOCK, "nested more than"), "aliases": (LAUGHS, "values")}
#: block nesting and aliases are YAML's: a JSON loader (synth path's case files) is not given them
_YAML_ONLY = ("deep-block", "aliases")


@pytest.mark.parametrize("command,content,expect", [
    pytest.param(command, *UNREADABLE[kind], id=f"{kind}-{command}")
    for kind in UNREADABLE for command in sorted(LOADER_COMMANDS)
    if not (command == "synth path" and kind in _YAML_ONLY)])
def test_unreadable_files_in_every_loader(run_cli, tmp_path, monkeypatch, command, content, expect):
    monkeypatch.setenv("MECHSYN_LIMIT_VALUES", "100000")  # the same refusal, sooner
    suffix = ".json" if command == "synth path" else ".yaml"
    f = write(tmp_path, "bad" + suffix, content)
    code, out, err = run_cli(*LOADER_COMMANDS[command](str(f)))
    assert code == 2, (command, err)
    msg = one_error_line(err)
    assert expect in msg and "bad" in msg


def test_belt_subcommand_exists(run_cli):
    code, out, _ = run_cli("belt", "--help")
    assert code == 0 and "synthesize" in out


# ----------------------------------------------------------------------- geometry and numbers
@pytest.mark.parametrize("data,expect", [
    (fourbar(B=[0.0, 0.0]), "link 'crank' has zero length"),
    ({**fourbar(A=[1, 1], B=[1, 1], C=[1, 1], D=[1, 1]), "points": {}, "loads": []},
     "all joints are at one point"),
    (fourbar(B=[True, False]), "true/false is not a number"),
    (fourbar(C=[1e308, 1e308]), "beyond"),
    (fourbar(C=[float("inf"), 0]), "finite"),
], ids=["zero-crank", "one-point", "bool-point", "1e308", "inf"])
@pytest.mark.parametrize("command", ["analyze", "structure", "simulate", "forces"])
def test_degenerate_geometry_is_an_error(run_cli, tmp_path, data, expect, command):
    f = write(tmp_path, "m.yaml", data)
    args = [command, f] + (["--input", "A=0:90:10"] if command in ("simulate", "forces") else [])
    code, out, err = run_cli(*args)
    assert code == 2
    msg = one_error_line(err)
    assert expect in msg and "actuated" not in msg   # not "mark more joints actuated"


RSSR = yaml.safe_load((EX / "textbook" / "rssr.yaml").read_text())


def rssr(**edits) -> dict:
    d = copy.deepcopy(RSSR)
    for jid, fields in edits.items():
        next(j for j in d["joints"] if j["id"] == jid).update(fields)
    return d


@pytest.mark.parametrize("data,expect", [
    (rssr(C={"point": [1, 0, 0]}), "link 'rod' has zero length: its joints B, C are at one point"),
    (rssr(B={"type": "U", "axis": [0, 0, 1], "axis2": [0, 1, 0]}, C={"point": [1, 0, 0]}),
     "link 'rod' has zero length"),
    ({**fourbar(), "joints": fourbar()["joints"] + [{**fourbar()["joints"][1], "id": "B2"}]},
     "joints B and B2 are the same R pair"),
], ids=["S-S rod", "U-S rod", "doubled pair"])
def test_degenerate_geometry_of_other_pairs(run_cli, tmp_path, data, expect):
    code, _, err = run_cli("analyze", write(tmp_path, "m.yaml", data))
    assert code == 2 and expect in one_error_line(err)


def test_crossed_hinges_at_one_point_are_a_hooke_cross_not_a_zero_length_link():
    from mechsyn.io import mechanism_from_dict

    d = rssr(B={"links": ["crank", "cross"], "type": "R", "axis": [0, 0, 1]})
    d["links"].append("cross")
    d["joints"].append({"id": "B2", "type": "R", "links": ["cross", "rod"], "point": [1, 0, 0], "axis": [0, 1, 0]})
    assert len(mechanism_from_dict(d, "m.yaml").joints) == 5
    d["joints"][-1]["axis"] = [0, 0, -1]  # parallel hinges at one point: the cross has zero length
    with pytest.raises(MechsynInputError, match="link 'cross' has zero length"):
        mechanism_from_dict(d, "m.yaml")


def test_slider_on_its_pivot_is_not_degenerate():
    from mechsyn.io import load_mechanism

    assert load_mechanism(EX / "textbook" / "slider_crank.yaml")  # the block's R and P at one point


def test_an_unforeseen_os_error_is_one_line(run_cli, tmp_path):
    """`schema --out` in a folder that cannot be made: the OSError net of the command line."""
    blocker = tmp_path / "file"
    blocker.write_text("")
    code, _, err = run_cli("schema", "--out", blocker / "sub" / "s.json")
    assert code == 2 and "fix: check the path" in one_error_line(err)


def test_negative_mass_names_the_field(run_cli, tmp_path):
    d = copy.deepcopy(FOURBAR)
    d["links"][1]["mass"] = -0.5
    code, _, err = run_cli("analyze", write(tmp_path, "m.yaml", d))
    msg = one_error_line(err)
    assert code == 2 and "links[1].mass" in msg and "text value" not in msg


def test_gear_ratio_zero(run_cli, tmp_path):
    d = {"name": "gears", "kind": "planar", "ground": "frame", "links": ["frame", "a", "b"],
         "joints": [{"id": "A", "type": "R", "links": ["frame", "a"], "point": [0, 0], "actuated": True},
                    {"id": "B", "type": "R", "links": ["frame", "b"], "point": [3, 0]},
                    {"id": "G", "type": "gear", "links": ["a", "b"], "point": [1, 0], "ratio": 0}]}
    code, _, err = run_cli("analyze", write(tmp_path, "g.yaml", d))
    assert code == 2 and "ratio 0" in one_error_line(err)


def test_cam_expression_200000_operators(run_cli, tmp_path):
    d = copy.deepcopy(CAM)
    d["joints"][1]["profile"]["polar"] = "1" + "+1" * 200_000
    code, _, err = run_cli("analyze", write(tmp_path, "cam.yaml", d))
    assert code == 2 and "MECHSYN_LIMIT_EXPRESSION_CHARS" in one_error_line(err)


def test_cam_expression_nested_too_deep(run_cli, tmp_path):
    d = copy.deepcopy(CAM)
    d["joints"][1]["profile"]["polar"] = "1" + "+t" * 3000
    code, _, err = run_cli("analyze", write(tmp_path, "cam.yaml", d))
    assert code == 2 and "polar" in one_error_line(err)


def test_forces_on_flat_collinear_fourbar(run_cli, tmp_path):
    d = fourbar(A=[0, 0], B=[1, 0], C=[4, 0], D=[5, 0])
    d["joints"][2]["point"] = [4, 0]
    code, out, err = run_cli("forces", write(tmp_path, "flat.yaml", d), "--input", "A=0:10:5", "--json")
    assert code in (0, 2) and "Traceback" not in err
    if code == 0:  # the singular position is reported, not printed as a number
        text = json.dumps(json.loads(out))
        assert "singular" in text


# ----------------------------------------------------------------------- sizes and limits
def test_simulate_huge_sweep_refused_before_allocating(run_cli):
    code, _, err = run_cli("simulate", EX / "kinematics" / "crank_rocker.yaml", "--input", "A=0:1e9:0.001")
    msg = one_error_line(err)
    assert code == 2 and "--input" in msg and "MECHSYN_LIMIT_SWEEP_POINTS" in msg


def test_sweep_limit_is_overridable(run_cli, monkeypatch):
    monkeypatch.setenv("MECHSYN_LIMIT_SWEEP_POINTS", "5")
    code, _, err = run_cli("simulate", EX / "kinematics" / "crank_rocker.yaml", "--input", "A=0:10:1")
    assert code == 2 and "limit of 5" in one_error_line(err)


@pytest.mark.parametrize("edit,expect", [
    ({"step_deg": 1e-9}, "step_deg"),
    ({"variables": [{"joint": "B", "coord": "x", "lower": -1e300, "upper": 1e300}]}, "beyond"),
    ({"step_deg": True}, "true/false"),
], ids=["step-1e-9", "bounds-1e300", "step-bool"])
def test_synthesis_case_limits(run_cli, tmp_path, edit, expect):
    d = yaml.safe_load(MECH_CASE.read_text())
    d["mechanism"] = str(MECH_CASE.parent / d["mechanism"])
    d.update(edit)
    code, _, err = run_cli("synth", "mechanism", write(tmp_path, "case.yaml", d), "--time-limit", "5")
    assert code == 2 and expect in one_error_line(err)


@pytest.mark.slow
def test_long_chain_refused_with_overridable_limit(run_cli, tmp_path):
    n = 62_000
    links = ["frame"] + [f"L{i}" for i in range(1, n)]
    joints = [{"id": f"J{i}", "type": "R", "links": [links[i - 1], links[i]], "point": [i, 0]}
              for i in range(1, n)]
    joints[0]["actuated"] = True
    text = json.dumps({"name": "chain", "kind": "planar", "ground": "frame", "links": links, "joints": joints})
    f = write(tmp_path, "chain.json", text)
    code, _, err = run_cli("analyze", f)
    msg = one_error_line(err)
    assert code == 2 and "MECHSYN_LIMIT_LINKS" in msg


@pytest.mark.parametrize("links", ["100", "16"])
def test_atlas_estimate_before_enumeration(run_cli, links):
    code, _, err = run_cli("atlas", "--links", links)
    msg = one_error_line(err)
    assert code == 2 and "chains" in msg and "MECHSYN_LIMIT_ATLAS_LINKS" in msg


def test_atlas_stream_never_overwrites_foreign_file(run_cli, tmp_path):
    notes = tmp_path / "notes.md"
    notes.write_text("my notes\n")
    code, _, err = run_cli("atlas", "--links", "6", "--stream", notes)
    assert code == 2 and "--force" in one_error_line(err)
    assert notes.read_text() == "my notes\n"
    code, _, _ = run_cli("atlas", "--links", "6", "--stream", notes, "--force", "--json")
    assert code == 0 and notes.read_text().startswith('{"mechsyn_chains"')


@pytest.mark.parametrize("args", [
    ["synth", "path", str(PATH_CASES), "--case", "P2_kk5_timing", "--out", "{bad}/x.yaml"],
    ["synth", "mechanism", str(MECH_CASE), "--out", "{bad}/x.yaml"],
    ["simulate", str(EX / "kinematics" / "crank_rocker.yaml"), "--input", "A=0:10:5", "--csv", "{bad}/x.csv"],
    ["atlas", "--links", "6", "--out", "{bad}/x.svg"],
    ["analyze", str(EX / "kinematics" / "crank_rocker.yaml"), "--json", "--out", "{bad}/x.json"],
    ["synth", "path", str(PATH_CASES), "--case", "P2_kk5_timing", "--checkpoint", "{bad}/ck.json"],
], ids=["synth-path", "synth-mechanism", "simulate", "atlas", "analyze", "checkpoint"])
def test_unwritable_output_checked_before_computing(run_cli, tmp_path, args):
    blocker = tmp_path / "file"
    blocker.write_text("")
    bad = str(blocker)          # a file where a folder is needed: nothing can be written below it
    code, _, err = run_cli(*[a.replace("{bad}", bad) for a in args], "--time-limit", "600") \
        if args[0] == "synth" else run_cli(*[a.replace("{bad}", bad) for a in args])
    assert code == 2 and "cannot write" in one_error_line(err)


# ----------------------------------------------------------------------- terminal safety
def test_markup_and_escapes_in_names_never_reach_the_terminal(tmp_path):
    import io

    from mechsyn.cli.common import SafeConsole, Table

    buf = io.StringIO()
    con = SafeConsole(file=buf, force_terminal=True, color_system="truecolor", width=80)
    name = "[link=https://evil.example]click[/link] \x1b[2J\x07"
    con.print(f"[bold]{name}[/]")
    t = Table()
    t.add_column("name")
    t.add_row(name)
    con.print(t)
    out = buf.getvalue()
    assert "\x1b]8;" not in out          # no OSC 8 hyperlink
    assert "\x1b[2J" not in out and "\x07" not in out
    assert "[link=https://evil.example]" in out


@pytest.mark.parametrize("command", ["analyze", "structure", "analyze --markdown"])
def test_names_printed_as_text(run_cli, tmp_path, command):
    d = copy.deepcopy(FOURBAR)
    d["name"] = "[link=https://evil.example]click[/link] \x1b[31mred"
    words = command.split()
    code, out, _ = run_cli(words[0], write(tmp_path, "m.yaml", d), *words[1:])
    assert code == 0 and "[link=https://evil.example]click[/link]" in out and "\x1b" not in out


MARKUP_NAMES = ["[/]", "a[/bold]b", "[crank]", "[@click=app.quit]x", "[bold]bold", "x\\", "[red]r[/red][/]"]


@pytest.mark.parametrize("command", ["analyze", "structure", "simulate --input A=0:360:90",
                                     "forces --input A=0:360:90", "export --svg {tmp}/m.svg --drawing {tmp}/d.svg"])
def test_markup_in_link_and_joint_names_is_text_not_a_crash(run_cli, tmp_path, command):
    """A link called "[/]" closed the command's own [bold] tag: rich raised MarkupError."""
    d = copy.deepcopy(FOURBAR)
    rename = dict(zip(["crank", "coupler", "rocker"], MARKUP_NAMES))
    d["name"] = MARKUP_NAMES[-1]
    for link in d["links"][1:]:
        link["name"] = rename[link["name"]]
    for j, new in zip(d["joints"], MARKUP_NAMES[3:]):
        j["id"] = new
    for j in d["joints"]:
        j["links"] = [rename.get(x, x) for x in j["links"]]
    for p in d.get("points", {}).values():
        p["link"] = rename.get(p["link"], p["link"])
    for load in d.get("loads", []):
        load["link"] = rename.get(load["link"], load["link"])
    d["joints"][0]["id"] = "A"
    words = command.replace("{tmp}", str(tmp_path)).split()
    code, out, err = run_cli(words[0], write(tmp_path, "m.yaml", d), *words[1:])
    assert "Traceback" not in err and "MarkupError" not in err, err
    assert code == 0, err
    assert "[/]" in out or command.startswith(("simulate", "export"))


def test_guard_markup_keeps_styles_escapes_the_rest():
    from mechsyn.cli.common import guard_markup

    assert guard_markup("[bold red]e[/] [/bold]") == "[bold red]e[/] [/bold]"
    assert guard_markup("[crank] [@click=x] [link=y]") == "\\[crank] \\[@click=x] \\[link=y]"


def test_numbers_never_cut_at_80_columns(run_cli):
    from mechsyn.cli.common import console

    old = console.width
    console.width = 80
    try:
        code, out, _ = run_cli("simulate", EX / "kinematics" / "crank_rocker.yaml", "--input", "A=0:360:1")
    finally:
        console.width = old
    assert code == 0 and "…" not in out
    assert "tables show 25 of 361 positions" in out


def test_float_noise_prints_as_zero():
    from mechsyn.cli.common import fmt_number

    assert fmt_number(-1.38778e-15) == "0" and fmt_number(1.6e-3) == "0.0016"


def test_api_raises_input_errors_not_bare_ones():
    from mechsyn.io import mechanism_from_dict

    for data in (fourbar(B=[0, 0]), fourbar(B=[True, 0]), fourbar(B="x"), [1, 2], None,
                 {"name": "x", "ground": "frame", "links": [["a"]], "joints": [{}]}):
        with pytest.raises(MechsynInputError):
            mechanism_from_dict(data, "m.yaml")


@pytest.mark.parametrize("args,expect", [
    (["simulate"], "Missing argument"), (["simulat"], "No such command"),
    (["atlas", "--links", "x"], "--links"), (["synth", "path", "--bogus"], "--bogus"),
])
def test_usage_errors_are_one_line(run_cli, args, expect):
    code, _, err = run_cli(*args)
    msg = one_error_line(err)
    assert code == 2 and expect in msg and "-h" in msg
    assert len(err.strip().splitlines()) <= 2


@pytest.mark.parametrize("command, shows", [("structure", "Assur groups of 4 links"), ("analyze", "reading m.yaml")])
def test_long_steps_of_big_files_show_a_spinner(run_cli, tmp_path, monkeypatch, command, shows):
    """Reading a big file and decomposing a large mechanism take seconds: the terminal shows
    the step (thresholds lowered here so a four-bar counts as large)."""
    import mechsyn.cli.working as working
    from mechsyn.cli.common import err_console

    monkeypatch.setattr(working, "BIG_FILE_BYTES", 10)
    monkeypatch.setattr(working, "LARGE_JOINTS", 2)
    from contextlib import nullcontext

    shown = []
    monkeypatch.setattr(err_console, "_force_terminal", True)
    monkeypatch.setattr(err_console, "status", lambda what, **kw: shown.append(what) or nullcontext())
    code, out, err = run_cli(command, write(tmp_path, "m.yaml", FOURBAR))
    assert code == 0 and any(shows in s for s in shown), shown


ARM_FILE = EX / "capability" / "paper004_3r.yaml"


@pytest.mark.parametrize("args", [
    ["--point", "1300,900", "--direction", "0,0"],
    ["--point", "1300,900", "--direction", "1,0", "--step", "0"],
    ["--point", "1300,900", "--direction", "1,0", "--measure", "fastest"],
    ["--point", "1300,900", "--direction", "1,0", "--csv", "x.csv"],
    ["--grid", "1300:2100:200", "--direction", "1,0"],
    ["--grid", "0:1e9:1,0:1:1", "--direction", "1,0"],
    ["--grid", "0:3000:1,0:3000:1", "--direction", "1,0"],
    ["--grid", "1300:1700:100,300:700:100", "--direction", "1,0", "--interpolate", "0,0"],
    ["--grid", "1300:1700:100,300:700:100"],
])
def test_capability_errors_name_the_fix(run_cli, tmp_path, monkeypatch, args):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli("capability", ARM_FILE, *args)
    assert code == 2 and "(fix:" in one_error_line(err), err


@pytest.mark.parametrize("edit, fix", [
    ({"link_lengths": [1000, -1, 500]}, ": link_lengths must be finite and >= 0 (fix: correct the value named"),
    ({"kind": "scara"}, "kind: planar_serial"),
    ({"bogus": 1}, "delete it or check its spelling"),
])
def test_arm_file_errors_name_the_fix(run_cli, tmp_path, edit, fix):
    data = {**yaml.safe_load(ARM_FILE.read_text()), **edit}
    code, _, err = run_cli("capability", write(tmp_path, "arm.yaml", data), "--point", "1300,900", "--direction", "1,0")
    assert code == 2 and fix in one_error_line(err), err


def test_float_noise_is_zero_in_every_table_and_path_extent(run_cli):
    """A fixed pivot's path extent printed 'y -1.38778e-15 .. 9.71445e-16'; a unit vector's
    component printed '-0.0000'."""
    code, out, _ = run_cli("simulate", EX / "kinematics" / "triple_rocker.yaml", "--input", "A=0:360:2")
    assert code == 0 and "path of D: x 4.5 .. 4.5, y 0 .. 0 (width 0, height 0)" in " ".join(out.split())
    code, out, _ = run_cli("simulate", EX / "fingers" / "two_phalanx_vll_000.yaml", "--input", "E=-15:60:1",
                           "--points", "tip")
    # the link table prints each of θ, ω, α in a column of its own: an exact zero reads "0",
    # never "-0" or "-0.0000"
    assert code == 0 and "-0.0000" not in out and not re.search(r"│\s+-0(\.0+)?\s+│", out)
    assert re.search(r"│\s+0(\.0+)?\s+│", out)


def test_a_name_too_long_for_the_file_system_is_one_clear_error(run_cli):
    """Found by the fuzzing suite: a case's `mechanism: xxx...` (300 characters) raised OSError."""
    with pytest.raises(MechsynInputError, match="File name too long"):
        from mechsyn.io import load_mechanism

        load_mechanism("x" * 300)
    code, _, err = run_cli("analyze", "y" * 300)
    assert code == 2 and "each name at most 255 bytes" in one_error_line(err)
