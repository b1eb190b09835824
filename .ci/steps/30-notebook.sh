#!/usr/bin/env bash
# docs/tutorial.ipynb runs top to bottom in an environment of its own (.venv-notebook: the
# notebook extra). It is committed with its outputs (a reader on GitHub sees them); here a
# copy is executed again with nbclient, so a change that breaks a cell fails CI. To refresh
# the committed outputs: the same lines with nbformat.write(nb, "docs/tutorial.ipynb").
set -euo pipefail
. .ci/fresh-venv notebook "notebook"
workdir=$(mktemp -d)
MPLBACKEND=Agg python - "$workdir" <<'PY'
import sys
import nbclient
import nbformat

nb = nbformat.read("docs/tutorial.ipynb", as_version=4)
code = [c for c in nb.cells if c.cell_type == "code"]
assert all(c.get("outputs") for c in code), "commit the notebook with its outputs"
nbclient.NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": sys.argv[1]}}).execute()
errors = [o for c in code for o in c.outputs if o.get("output_type") == "error"]
assert not errors, errors
print(f"docs/tutorial.ipynb: {len(code)} code cells ran")
PY
rm -rf "$workdir"
