"""The plain-file path (mechsyn.io.plain) accepts a subset of what pydantic's validation
accepts, never more, and builds the same models."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.io.files import read_data
from mechsyn.io.plain import plain_spec
from mechsyn.io.schema import MechanismFile

ROOT = Path(__file__).resolve().parents[2]
FILES = sorted(p for p in (ROOT / "examples").rglob("*.yaml")
               if isinstance(read_data(p)[0], dict) and "joints" in read_data(p)[0])
ODD = [1, 0, True, 1.5, -1.0, float("nan"), float("inf"), "x", "1", None, [], [1, 2], [0, 0, 1], {"a": 1},
       2 ** 60]


def same_models(a, b) -> bool:
    """Equal dumps (repr: 1 and 1.0 differ), fields set and extras, down to nested models."""
    if repr(a.model_dump()) != repr(b.model_dump()) or a.model_fields_set != b.model_fields_set:
        return False
    nested = [(x, y) for f in ("links", "joints", "loads") for x, y in zip(getattr(a, f), getattr(b, f))
              if not isinstance(x, str)] + [(a.points[k], b.points[k]) for k in a.points]
    return all(repr(x.model_dump()) == repr(y.model_dump()) and x.model_fields_set == y.model_fields_set
               and x.model_extra == y.model_extra for x, y in nested)


def check(data) -> bool:
    """The invariant; returns whether the plain path took the data."""
    spec = plain_spec(data)
    try:
        valid = MechanismFile.model_validate(data)
    except Exception:
        assert spec is None, data  # never accepts what validation refuses
        return False
    assert spec is None or same_models(spec, valid), data
    return spec is not None


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_example_files_same_models(path):
    check(read_data(path)[0])


def test_plain_path_is_taken_for_the_common_files():
    taken = [p.name for p in FILES if check(read_data(p)[0])]
    assert "fourbar.yaml" in taken and len(taken) >= len(FILES) * 2 // 3


def test_odd_values_anywhere_never_accepted_beyond_validation():
    base = read_data(ROOT / "examples" / "kinematics" / "crank_rocker.yaml")[0]  # points and loads
    taken = 0
    places = [(base, k) for k in base] + [(j, k) for j in base["joints"] for k in j] \
        + [(j, k) for j in base["joints"] for k in ("class", "pitch", "radius", "vll", "actuated", "bogus")] \
        + [(p, k) for p in base["points"].values() for k in p] + [(x, k) for x in base["loads"] for k in x]
    for where, key in places:
        for value in ODD:
            saved = where.get(key, KeyError)
            where[key] = copy.deepcopy(value)
            taken += check(base)
            if saved is KeyError:
                del where[key]
            else:
                where[key] = saved
    assert taken > 0  # the plain path took some of the variants (those validation takes as they are)


def test_errors_are_validation_errors(tmp_path):
    f = tmp_path / "bad.yaml"
    f.write_text("name: m\nground: frame\nlinks: [frame, crank]\njoints:\n"
                 "  - {id: A, type: R, links: [frame, crank], actuated: maybe}\n")
    with pytest.raises(Exception) as err:
        load_mechanism(f)
    assert "actuated" in str(err.value) and "bad.yaml:5" in str(err.value)
    m = mechanism_from_dict({"name": "m", "ground": "frame", "links": ["frame", "crank"],
                             "joints": [{"id": 7, "type": "R", "links": ["frame", "crank"], "point": [0, 0],
                                         "actuated": True}]})
    assert m.joints[0].id == "7" and m.joints[0].actuated
