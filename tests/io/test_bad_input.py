"""Bad mechanism files: one clear message naming the file, line and field; exit status 2."""

import json
import textwrap

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism, mechanism_from_dict, mechanism_from_text

GOOD = textwrap.dedent("""\
    name: Four-bar linkage
    kind: planar
    ground: frame
    links: [frame, crank, coupler, rocker]
    joints:
      - {id: A, type: R, links: [frame, crank], point: [0, 0], actuated: true}
      - {id: B, type: R, links: [crank, coupler], point: [1, 2]}
      - {id: C, type: R, links: [coupler, rocker], point: [4, 3]}
      - {id: D, type: R, links: [rocker, frame], point: [5, 0]}
    contours:
      - [A, B, C, D]
    """)


def write(tmp_path, text, name="m.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p


CASES = [
    # (description, replacement (old, new), expected words in the message, line)
    ("yaml syntax", ("point: [5, 0]}", "point: [5, 0]"), ["YAML syntax error"], None),
    ("unknown link", ("[coupler, rocker]", "[coupler, rockr]"), ["joints[2].links[1]", "unknown link 'rockr'"], 8),
    ("duplicate joint id", ("{id: C,", "{id: B,"), ["joints[2].id", "duplicate joint id 'B'"], 8),
    ("duplicate link", ("[frame, crank, coupler, rocker]", "[frame, crank, crank, rocker]"), ["links[2]", "duplicate link name"], 4),
    ("no frame", ("ground: frame\n", ""), ["ground", "required field is missing"], None),
    ("unknown frame", ("ground: frame", "ground: base"), ["ground", "unknown link 'base'"], 3),
    ("unknown pair type", ("{id: B, type: R", "{id: B, type: Q"), ["joints[1].type", "unknown pair type 'Q'"], 7),
    ("class out of range", ("{id: B, type: R,", "{id: B, type: generic, class: 7,"), ["joints[1].class", "out of 1..5"], 7),
    ("spatial pair in planar", ("{id: B, type: R", "{id: B, type: S"), ["joints[1].type", "spatial", "planar"], 7),
    ("contour not closed", ("[A, B, C, D]", "[A, C, B, D]"), ["contours[0]", "not a closed loop"], 11),
    ("contour unknown joint", ("[A, B, C, D]", "[A, B, C, X]"), ["contours[0][3]", "unknown joint 'X'"], 11),
    ("point dimension", ("point: [4, 3]", "point: [4, 3, 1]"), ["joints[2].point", "2"], 8),
    ("unknown field", ("actuated: true}", "actuated: true, colour: red}"), ["joints[0].colour", "unknown field"], 6),
    ("same link twice", ("[crank, coupler]", "[crank, crank]"), ["joints[1].links", "two different links"], 7),
]


@pytest.mark.parametrize("desc, change, words, line", CASES, ids=[c[0] for c in CASES])
def test_bad_file_message(tmp_path, desc, change, words, line):
    old, new = change
    assert old in GOOD
    p = write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(MechsynInputError) as err:
        load_mechanism(p)
    msg = str(err.value)
    assert str(p) in msg
    for w in words:
        assert w in msg, msg
    if line is not None:
        assert err.value.line == line, msg


@pytest.mark.parametrize("desc, change, words, line", CASES, ids=[c[0] for c in CASES])
def test_bad_file_cli_exits_2(tmp_path, run_cli, desc, change, words, line):
    old, new = change
    p = write(tmp_path, GOOD.replace(old, new, 1))
    code, out, err = run_cli("analyze", p)
    assert code == 2
    assert "Traceback" not in err and out == ""
    assert "error:" in err


def test_disconnected(tmp_path):
    text = GOOD.replace("[frame, crank, coupler, rocker]", "[frame, crank, coupler, rocker, stray]")
    with pytest.raises(MechsynInputError) as err:
        load_mechanism(write(tmp_path, text))
    assert "disconnected" in str(err.value) and "stray" in str(err.value)


def test_json_syntax_error_line(tmp_path):
    p = write(tmp_path, '{\n  "name": "x",\n  "kind": "planar"\n  "ground": "frame"\n}\n', "m.json")
    with pytest.raises(MechsynInputError) as err:
        load_mechanism(p)
    assert err.value.line == 4 and "JSON syntax error" in str(err.value)


def test_missing_file(run_cli, tmp_path):
    code, _, err = run_cli("analyze", tmp_path / "nope.yaml")
    assert code == 2 and "no such file" in err


def test_links_by_integer_id():
    data = {
        "name": "ids", "kind": "planar", "ground": 0,
        "links": [{"id": 0, "name": "frame"}, {"id": 1, "name": "crank"}, {"id": 2}, {"id": 3, "name": "rocker"}],
        "joints": [{"id": "A", "type": "R", "links": [0, 1]}, {"id": "B", "type": "revolute", "links": [1, 2]},
                   {"id": "C", "type": "R", "links": [2, 3]}, {"id": "D", "type": "R", "links": [3, 0]}],
    }
    m = mechanism_from_dict(data)
    assert m.ground == "frame" and m.joint("B").type == "R" and m.joint("C").links == ("2", "rocker")


def test_json_and_yaml_same_model(tmp_path):
    import yaml

    data = yaml.safe_load(GOOD)
    a = load_mechanism(write(tmp_path, GOOD))
    b = load_mechanism(write(tmp_path, json.dumps(data), "m.json"))
    assert [j.links for j in a.joints] == [j.links for j in b.joints]


def test_round_trip(tmp_path):
    from mechsyn.io import mechanism_to_dict, write_mechanism

    a = load_mechanism(write(tmp_path, GOOD))
    write_mechanism(a, tmp_path / "out.yaml")
    b = load_mechanism(tmp_path / "out.yaml")
    assert mechanism_to_dict(a) == {**mechanism_to_dict(b), "name": a.name}


# -- property tests: random and broken input never escapes as anything but MechsynInputError

json_values = st.recursive(
    st.none() | st.booleans() | st.integers(-5, 5) | st.floats(allow_nan=True) | st.text(max_size=5),
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4),
    max_leaves=20,
)

FIELDS = ["name", "kind", "ground", "links", "joints", "contours", "points", "states", "mobility"]


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.dictionaries(st.sampled_from(FIELDS), json_values, max_size=9))
def test_random_data_gives_input_error(data):
    try:
        mechanism_from_dict(data, "fuzz.yaml")
    except MechsynInputError as err:
        assert err.source == "fuzz.yaml"


@settings(max_examples=200, deadline=None)
@given(st.integers(0, len(GOOD) - 1), st.integers(1, 20), st.text(max_size=6))
def test_mangled_text_gives_input_error(start, length, junk):
    text = GOOD[:start] + junk + GOOD[start + length:]
    try:
        mechanism_from_text(text, "fuzz.yaml")
    except MechsynInputError:
        pass


@settings(max_examples=100, deadline=None)
@given(st.lists(st.sampled_from(["A", "B", "C", "D", "X", 3]), max_size=6))
def test_random_contours(contour):
    import yaml

    data = yaml.safe_load(GOOD)
    data["contours"] = [contour]
    try:
        m = mechanism_from_dict(data, "fuzz.yaml")
    except MechsynInputError:
        return
    assert set(m.contours[0]) == {"A", "B", "C", "D"}
