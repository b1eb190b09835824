#!/usr/bin/env bash
# Every documented command runs as written, the long ones included (synthesis runs,
# fine capability grids): the default suite runs only the quick ones.
set -euo pipefail
MECHSYN_DOC_COMMANDS=all python -m pytest tests/docs -q -p no:cacheprovider -n 0  # in page order, one process
