#!/usr/bin/env bash
# The dependency floors in pyproject.toml are true: a second environment (.venv-lowest,
# git-ignored) gets the lowest version every direct requirement allows (uv's lowest-direct
# resolution; the indirect ones resolve to their newest) and runs the test suite on every
# core. The install takes about 30 s; the suite about as long as the main job's (measured
# at one load, 2 cores at load average ~20: 31 min here, 29 min for the main suite).
set -euo pipefail
cd "$(dirname "$0")/../.."
python3 -m venv .venv-lowest
# shellcheck disable=SC1091
. .venv-lowest/bin/activate
python -m pip install --quiet --upgrade pip uv
uv pip install --quiet --resolution lowest-direct -e ".[test]"
python - <<'PY'
from importlib.metadata import version
names = ("numpy", "scipy", "networkx", "matplotlib", "pydantic", "typer", "click", "rich", "pyyaml",
         "python-igraph", "threadpoolctl", "numba")
print("lowest:", ", ".join(f"{n} {version(n)}" for n in names))
PY
MPLBACKEND=Agg python -m pytest -q -p no:cacheprovider -n auto
