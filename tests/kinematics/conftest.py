from pathlib import Path

import numpy as np
import pytest

from mechsyn.io import load_mechanism

ROOT = Path(__file__).resolve().parents[2]
EX = ROOT / "examples"


@pytest.fixture
def ex():
    def load(rel: str):
        return load_mechanism(EX / rel)
    return load


