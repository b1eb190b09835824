#!/usr/bin/env bash
# The dependency floors in pyproject.toml are true: a second environment gets the lowest
# version every direct requirement allows (uv's lowest-direct resolution) and runs the tests.
set -euo pipefail
python3 -m venv .venv-lowest
# shellcheck disable=SC1091
. .venv-lowest/bin/activate
python -m pip install --quiet --upgrade pip uv
uv pip install --quiet --resolution lowest-direct -e ".[test]"
python -c "import numpy, scipy, networkx, matplotlib, pydantic, typer, rich, yaml; \
print('lowest:', 'numpy', numpy.__version__, 'scipy', scipy.__version__, 'networkx', networkx.__version__, \
'matplotlib', matplotlib.__version__, 'pydantic', pydantic.__version__, 'typer', typer.__version__)"
python -m pytest -q -p no:cacheprovider
