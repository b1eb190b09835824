#!/usr/bin/env bash
# Every documented command runs as written, the long ones included (synthesis runs,
# fine capability grids): the default suite runs only the quick ones.
set -euo pipefail
# -m "": the long ones are marked slow, which the default run leaves out
MECHSYN_DOC_COMMANDS=all python -m pytest tests/docs/test_doc_commands.py tests/docs/test_doc_python.py \
    -q -p no:cacheprovider -n 0 -m ""  # in page order, one process
