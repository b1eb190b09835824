"""Fixtures of the dimensional-synthesis tests: the public path-synthesis cases."""

import json
from pathlib import Path

import pytest

SPEC = Path(__file__).resolve().parents[2] / ".." / ".." / "shared" / "spec" / "data" / "synthesis_cases_public.json"
SPEC = SPEC.resolve()
if not SPEC.exists():  # worktree layout /work/wt/<name>; main repo /work/main
    SPEC = Path("/work/shared/spec/data/synthesis_cases_public.json")


@pytest.fixture(scope="session")
def public_data():
    if not SPEC.exists():
        pytest.skip("synthesis_cases_public.json not available")
    return json.loads(SPEC.read_text())


@pytest.fixture(scope="session")
def public_cases(public_data):
    from mechsyn.synthesis.path import PathCase

    return {c["id"]: PathCase.from_dict(c) for c in public_data["cases"]}
