#!/usr/bin/env bash
# docs/tutorial.ipynb runs top to bottom (committed without outputs; executed here with nbclient).
set -euo pipefail
python -m pip install --quiet -e ".[notebook]"
workdir=$(mktemp -d)
MPLBACKEND=Agg python - "$workdir" <<'PY'
import sys
import nbclient
import nbformat

nb = nbformat.read("docs/tutorial.ipynb", as_version=4)
assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code"), "commit the notebook without outputs"
nbclient.NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": sys.argv[1]}}).execute()
print("docs/tutorial.ipynb: ok")
PY
rm -rf "$workdir"
