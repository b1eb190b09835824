#!/usr/bin/env bash
# The documentation site builds with warnings as errors (mkdocs build --strict, run by the
# test), its gallery runs the examples, and the built pages show no raw reStructuredText
# (roles, double backticks, RST tables), in code blocks too. In an environment of its own
# (.venv-docs: the docs and test extras).
set -euo pipefail
. .ci/fresh-venv docs "docs,test"
MPLBACKEND=Agg python -m pytest -q -p no:cacheprovider -n 0 -m slow tests/docs/test_site.py
