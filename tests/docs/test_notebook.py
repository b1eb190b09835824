"""The notebook tutorial (docs/tutorial.ipynb) is committed with its outputs: a reader on
GitHub or in the documentation sees every cell's result without running it. CI executes it
again (.ci/steps/30-notebook.sh)."""

from __future__ import annotations

import json
from pathlib import Path

NOTEBOOK = Path(__file__).resolve().parents[2] / "docs" / "tutorial.ipynb"


def test_every_code_cell_of_the_tutorial_has_its_output():
    nb = json.loads(NOTEBOOK.read_text(encoding="utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert len(code) >= 10
    missing = [i for i, c in enumerate(code) if not c.get("outputs") or c.get("execution_count") is None]
    assert not missing, f"code cells without outputs: {missing} (run the notebook and commit it)"
    errors = [o for c in code for o in c["outputs"] if o.get("output_type") == "error"]
    assert not errors
    counts = [c["execution_count"] for c in code]
    assert counts == sorted(counts), "run top to bottom in one kernel"
