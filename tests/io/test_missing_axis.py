"""A planar P pair without `axis` is an error naming the field and the fix (issue 12 §5),
never a silent slide along x."""

from __future__ import annotations

import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.io import mechanism_from_dict


def _slider_crank(axis=None) -> dict:
    slide = {"id": "D", "type": "P", "links": ["slider", "frame"], "point": [0, 3]}
    if axis is not None:
        slide["axis"] = axis
    return {"name": "vertical slider-crank", "kind": "planar", "ground": "frame",
            "links": ["frame", "crank", "rod", "slider"],
            "joints": [{"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
                       {"id": "B", "type": "R", "links": ["crank", "rod"], "point": [1, 0]},
                       {"id": "C", "type": "R", "links": ["rod", "slider"], "point": [0, 3]}, slide]}


def test_planar_p_without_axis_is_an_error_with_the_fix():
    with pytest.raises(MechsynInputError) as exc:
        mechanism_from_dict(_slider_crank())
    text = str(exc.value)
    assert "axis" in text and "D" in text and "axis: [1, 0]" in text


def test_planar_p_with_axis_loads():
    m = mechanism_from_dict(_slider_crank([0, 1]))
    assert list(m.joint("D").axis) == [0, 1]


def test_topology_only_p_needs_no_axis():
    d = _slider_crank()
    for j in d["joints"]:
        j.pop("point")
    assert mechanism_from_dict(d).joint("D").axis is None


def test_cli_reports_the_missing_axis(tmp_path, run_cli):
    import yaml

    f = tmp_path / "slider.yaml"
    f.write_text(yaml.safe_dump(_slider_crank()))
    code, out, err = run_cli("simulate", f, "--input", "A=0:90:10")
    assert code == 2 and "axis" in err and out == ""
