#!/usr/bin/env bash
# The docstring examples are tests: every public name's example runs (issue 13).
set -euo pipefail
MPLBACKEND=Agg python -m pytest -q -p no:cacheprovider --doctest-modules src/mechsyn
