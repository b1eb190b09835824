"""Fixtures of the dimensional-synthesis tests: the public path-synthesis cases."""

import json
from pathlib import Path

import pytest

# The public cases of the project's spec (shared/spec/data/synthesis_cases_public.json:
# literature path-synthesis cases with their published best errors), copied here so the
# suite runs on a clone with nothing beside it.
DATA = Path(__file__).resolve().parent / "data" / "synthesis_cases_public.json"


@pytest.fixture(scope="session")
def public_data():
    return json.loads(DATA.read_text())


@pytest.fixture(scope="session")
def public_cases(public_data):
    from mechsyn.synthesis.path import PathCase

    return {c["id"]: PathCase.from_dict(c) for c in public_data["cases"]}
