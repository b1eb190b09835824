"""Issue 40: the mechanism file's length unit, read, written and used by DXF and SVG."""

from __future__ import annotations

import re

import pytest

import mechsyn as ms
from mechsyn.errors import MechsynInputError
from mechsyn.export.dxf import layout_to_dxf
from mechsyn.export.plates import link_plates
from mechsyn.export.svg import plates_svg as layout_to_svg
from mechsyn.io import mechanism_from_dict, mechanism_to_dict


def fourbar(**extra):
    return mechanism_from_dict({**mechanism_to_dict(ms.load("fourbar")), **extra})


@pytest.mark.parametrize("unit, code", [("mm", 4), ("cm", 5), ("m", 6), ("in", 1)])
def test_dxf_insunits_is_the_files_unit(unit, code):
    m = fourbar(unit=unit)
    assert mechanism_to_dict(m)["unit"] == unit
    assert layout_to_dxf(link_plates(m)).header["$INSUNITS"] == code


def test_a_file_without_unit_is_unitless_not_metres():
    m = fourbar()
    assert "unit" not in mechanism_to_dict(m)
    assert layout_to_dxf(link_plates(m)).header["$INSUNITS"] == 0


def test_the_older_units_spelling_is_read_and_a_wrong_unit_named():
    assert fourbar(units="mm").attrs["unit"] == "mm"
    with pytest.raises(MechsynInputError, match="unit"):
        fourbar(unit="furlong")
    with pytest.raises(MechsynInputError, match="disagree"):
        fourbar(unit="mm", units="in")


def test_svg_is_sized_in_the_files_unit():
    layout = link_plates(fourbar(unit="m"))
    svg = layout_to_svg(layout)
    w = re.search(r'width="([0-9.]+)mm"', svg)
    box = [float(x) for x in re.search(r'viewBox="([^"]+)"', svg).group(1).split()]
    assert w and float(w.group(1)) == pytest.approx(1000 * box[2])
    svg_in = layout_to_svg(link_plates(fourbar(unit="in")))
    assert re.search(r'width="[0-9.]+in"', svg_in)
