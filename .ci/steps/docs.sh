#!/usr/bin/env bash
# The documentation site builds with warnings as errors; its gallery runs the examples.
set -euo pipefail
python -m pip install --quiet -e ".[docs]"
MPLBACKEND=Agg mkdocs build --strict --site-dir "$(mktemp -d)"
