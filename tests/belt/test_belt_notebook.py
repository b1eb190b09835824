"""A long belt report in a notebook shows each table's head and tail with its size
(issue 26 §5: two 159-row tables filled the notebook)."""

from __future__ import annotations

import re

import mechsyn as ms


def test_long_tables_show_head_tail_and_size():
    rep = ms.belt.analyze_case(ms.BeltDesign(a=100, c=300, h=0, r=200), ms.belt.phi_range(-30, 128, 1))
    tables = rep.tables()
    assert len(tables[0].rows) == 159
    md = rep._repr_markdown_()
    assert md.count("159 rows: the first 5 and the last 5 shown") == 2
    data_rows = [ln for ln in md.splitlines() if re.match(r"\| -?\d+\.\d\d \|", ln)]
    assert len(data_rows) == 2 * rep.NOTEBOOK_ROWS
    for t in tables[:2]:
        first, last = t.rows[0][0], t.rows[-1][0]
        assert f"| {first} |" in md and f"| {last} |" in md
    assert md.count("… 149 rows …") == 2
    # the short tables stay whole
    assert tables[2].markdown(rep.NOTEBOOK_ROWS) == tables[2].markdown()
