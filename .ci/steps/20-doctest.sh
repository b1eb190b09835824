#!/usr/bin/env bash
# The docstring examples are tests: every public name's example runs. In the README's
# environment (.venv-ci, activated by .ci/run): they need nothing beyond the test extra.
set -euo pipefail
MPLBACKEND=Agg python -m pytest -q -p no:cacheprovider --doctest-modules src/mechsyn -n 2
