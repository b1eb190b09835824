"""The command-line findings of issue 27, kept as tests: each gave a traceback, a hang or a
silent wrong answer on the code before; each must now exit 2 with one line naming the
file (or option), the problem and the fix."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
import yaml

from mechsyn.errors import MechsynInputError

from test_corpus import FOURBAR, one_error_line

ROOT = Path(__file__).resolve().parents[2]
CRANK_ROCKER = (ROOT / "examples" / "kinematics" / "crank_rocker.yaml").read_text()


def _analyze(run_cli, path: Path) -> str:
    code, out, err = run_cli("analyze", path)
    assert code == 2, (code, out, err)
    return one_error_line(err)


# ------------------------------------------------------------------ text and numbers
@pytest.mark.parametrize("suffix, text", [
    (".yaml", CRANK_ROCKER.replace("point: [0.0, 0.0]", "point: [" + "9" * 5000 + ", 0.0]", 1)),
    (".json", json.dumps(FOURBAR).replace('"point": [0.0, 0.0]', '"point": [' + "9" * 5000 + ", 0.0]", 1)),
])
def test_integers_of_thousands_of_digits(run_cli, tmp_path, suffix, text):
    assert "9" * 5000 in text
    f = tmp_path / f"m{suffix}"
    f.write_text(text)
    assert "too long to read" in _analyze(run_cli, f)


@pytest.mark.parametrize("suffix, text", [
    (".yaml", CRANK_ROCKER.replace("name: ", 'name: "\\ud800" #', 1)),
    (".json", json.dumps({**FOURBAR, "name": "x"}).replace('"name": "x"', '"name": "\\ud800"')),
])
def test_lone_surrogates(run_cli, tmp_path, suffix, text):
    f = tmp_path / f"m{suffix}"
    f.write_text(text)
    msg = _analyze(run_cli, f)  # LibYAML refuses the escape itself; JSON decodes it
    assert "lone surrogate" in msg or "invalid Unicode character escape" in msg


def test_duplicate_yaml_keys_are_refused_with_the_line(run_cli, tmp_path):
    lines = CRANK_ROCKER.splitlines()
    at = next(i for i, ln in enumerate(lines) if ln.startswith("ground:"))
    lines.insert(at + 1, "ground: crank")  # the last one won, silently
    f = tmp_path / "m.yaml"
    f.write_text("\n".join(lines) + "\n")
    msg = _analyze(run_cli, f)
    assert f"m.yaml:{at + 2}:" in msg and "duplicate key 'ground'" in msg


def test_duplicate_json_keys_are_refused_with_the_line(run_cli, tmp_path):
    text = json.dumps(FOURBAR, indent=1)
    text = text.replace('"kind": "planar",', '"kind": "planar",\n "kind": "spatial",', 1)
    f = tmp_path / "m.json"
    f.write_text(text)
    line = text.splitlines().index(' "kind": "spatial",') + 1
    msg = _analyze(run_cli, f)
    assert f"m.json:{line}:" in msg and "'kind' is written twice" in msg


@pytest.mark.parametrize("char", ["\u202e", "\u200b", "\u2066", "\ufeff"])
def test_hidden_characters_in_ids(run_cli, tmp_path, char):
    d = json.loads(json.dumps(FOURBAR))
    d["joints"][1]["id"] += char  # "B" and "B\u200b" look the same
    f = tmp_path / "m.yaml"
    f.write_text(yaml.safe_dump(d, allow_unicode=True))
    assert f"U+{ord(char):04X}" in _analyze(run_cli, f)


def test_hidden_characters_in_a_name_are_accepted(run_cli, tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text(yaml.safe_dump({**FOURBAR, "name": "four\u200dbar"}, allow_unicode=True))
    assert run_cli("analyze", f, "--json")[0] == 0


# ------------------------------------------------------------------ special files
def test_dev_zero_is_refused_at_once(run_cli):
    assert "not a regular file" in _analyze(run_cli, Path("/dev/zero"))


def test_a_fifo_is_refused_without_blocking(run_cli, tmp_path):
    fifo = tmp_path / "m.yaml"
    os.mkfifo(fifo)  # nobody ever writes: reading it blocked forever
    assert "not a regular file" in _analyze(run_cli, fifo)


# ------------------------------------------------------------------ arms
URDF = """<robot name="r">
<link name="a"/><link name="b"/><link name="c"/>
<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>{axis}<limit velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="b"/><child link="c"/><limit velocity="1"/></joint>
{extra}</robot>
"""
CLOSE = '<joint name="j3" type="revolute"><parent link="c"/><child link="b"/><limit velocity="1"/></joint>\n'


def _capability(run_cli, arm: Path) -> str:
    code, out, err = run_cli("capability", arm, "--direction", "1,0,0", "--point", "0,0,0")
    assert code == 2, (code, out, err)
    return one_error_line(err)


@pytest.mark.parametrize("tip", [False, True])
def test_urdf_joint_cycle_is_refused_naming_the_joint(run_cli, tmp_path, tip):
    """A cycle hung capability forever (with tip_link, memory grew about 25 MB/s)."""
    (tmp_path / "r.urdf").write_text(URDF.format(axis="", extra=CLOSE))
    arm = tmp_path / "r.urdf"
    if tip:
        arm = tmp_path / "arm.yaml"
        arm.write_text("kind: urdf\nurdf: r.urdf\nbase_link: a\ntip_link: c\n"
                       "joint_speed_limits_deg_s: [1, 1]\n")
    assert "joint 'j3' closes a cycle" in _capability(run_cli, arm)


def test_urdf_zero_axis_is_refused(run_cli, tmp_path):
    (tmp_path / "r.urdf").write_text(URDF.format(axis='<axis xyz="0 0 0"/>', extra=""))
    assert "joint 'j1': axis" in _capability(run_cli, tmp_path / "r.urdf")


def test_an_arm_of_ten_thousand_joints_is_refused_by_a_limit(run_cli, tmp_path):
    arm = tmp_path / "arm.yaml"
    arm.write_text(yaml.safe_dump({"kind": "planar_serial", "link_lengths": [1.0] * 10_000,
                                   "joint_speed_limits_deg_s": [1.0] * 10_000}))
    msg = _capability(run_cli, arm)
    assert "10,000 joints" in msg and "MECHSYN_LIMIT_ARM_JOINTS" in msg


# ------------------------------------------------------------------ atlas
@pytest.mark.parametrize("damage", ["[1, 2]", '{"n_links": 6}', '{"done": 5}',
                                    '{"n_links": 6, "mobility": 1, "edges": [[0, 99]], "assortment": {}, '
                                    '"degenerate": false, "fractionated": false, "planar_graph": true}'])
def test_damaged_atlas_stream_lines(run_cli, tmp_path, damage):
    stream = tmp_path / "s.jsonl"
    assert run_cli("atlas", "-n", "6", "--stream", stream)[0] == 0
    lines = stream.read_text().splitlines()
    lines[1] = damage
    stream.write_text("\n".join(lines) + "\n")
    code, out, err = run_cli("atlas", "-n", "6", "--stream", stream)
    assert code == 2
    assert "s.jsonl:2:" in one_error_line(err) and "damaged chain stream" in err


def test_atlas_out_refuses_too_many_chains_before_enumerating(run_cli, tmp_path, monkeypatch):
    import mechsyn.synthesis.atlas as atlas

    def never(*a, **k):
        raise AssertionError("enumerated before refusing")

    monkeypatch.setattr(atlas, "synthesize_chains", never)
    code, out, err = run_cli("atlas", "-n", "12", "-o", tmp_path / "a.svg")
    assert code == 2 and "too many to draw" in one_error_line(err)


# ------------------------------------------------------------------ curve cache
def test_a_truncated_curve_cache_file_is_one_error_then_rebuilt(tmp_path):
    from mechsyn.synthesis.curves.database import build_database, load_database

    build_database(tmp_path, max_links=4, per_topology=30)
    f = sorted(tmp_path.glob("*.npz"))[0]
    f.write_bytes(f.read_bytes()[: f.stat().st_size // 2])
    with pytest.raises(MechsynInputError, match="the curve database file is damaged") as err:
        load_database(tmp_path, max_links=4)
    assert err.value.source.endswith(f.name) and "mechsyn curves build" in err.value.hint
    build_database(tmp_path, max_links=4, per_topology=30)  # builds it again
    assert len(load_database(tmp_path, max_links=4)) > 0


def test_hidden_characters_are_stripped_from_displayed_names(run_cli, tmp_path):
    """A right-to-left override in a name reordered the terminal's line."""
    f = tmp_path / "m.yaml"
    f.write_text(yaml.safe_dump({**FOURBAR, "name": "four\u202e bar\u200b"}, allow_unicode=True))
    code, out, err = run_cli("analyze", f)
    assert code == 0 and "four bar" in out
    assert not any(c in out for c in "\u202e\u200b")
