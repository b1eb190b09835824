#!/usr/bin/env bash
# The documentation site builds with warnings as errors; its gallery runs the examples.
set -euo pipefail
. .ci/fresh-venv docs "docs"
MPLBACKEND=Agg mkdocs build --strict --site-dir "$(mktemp -d)"
