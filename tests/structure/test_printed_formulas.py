"""Every formula `analyze` prints is arithmetically true (issue 12 §5).

For every example file, the Markdown report and every string of the JSON report are
scanned for chains ``a = b = c``; each link of a chain that is a plain arithmetic
expression (numbers, + - · * /, parentheses, |x|; a number followed by a word of three
letters or more, as in ``1 useful + 0 idle``, reads as the number) is evaluated, and all of a chain's values must
be equal. A chain such as "Ozol's q = 0 = S_Σ + G_Σ = 3 + 0" fails.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
FILES = sorted(EXAMPLES.rglob("*.yaml"))
_NUMERIC = re.compile(r"^[0-9.\s+\-*/()]+$")


def _value(part: str) -> float | None:
    """The value of one link of a chain, or None when it is not plain arithmetic."""
    s = part.strip().strip("`").replace("·", "*").replace("−", "-").replace("≠", "!")
    s = re.sub(r"(\d)\s+[A-Za-z_]{3,}", r"\1", s)  # "1 useful + 0 idle" -> "1 + 0" (not "a = 5 c = 3")
    s = re.sub(r"\|([^|]+)\|", r"abs(\1)", s)
    s = re.sub(r"(\d)\s*\(", r"\1*(", s)
    if not s or not _NUMERIC.match(s.replace("abs", "")) or not re.search(r"\d", s):
        return None
    try:
        return float(eval(s, {"__builtins__": {}}, {"abs": abs}))  # noqa: S307 - digits and operators only
    except (SyntaxError, ZeroDivisionError, TypeError, NameError):
        return None


def chains(text: str) -> list[list[str]]:
    """The ``=`` chains of a text: one per clause (clauses end at ``;``, ``: ``, a table cell
    or a line); a parenthesis that holds its own ``=`` is a chain of its own."""
    out = []
    for line in text.splitlines():
        for cell in line.split(" | "):
            inner = re.findall(r"\(([^()]*=[^()]*)\)", cell)
            cell = re.sub(r"\(([^()]*=[^()]*)\)", " ", cell)
            for clause in re.split(r";|: |—", cell) + inner:
                if "=" in clause:
                    out.append(clause.split("="))
    return out


def false_chains(text: str) -> list[str]:
    bad = []
    for parts in chains(text):
        vals = [v for v in (_value(p) for p in parts) if v is not None]
        if vals and max(vals) - min(vals) > 1e-9 * max(1.0, max(abs(v) for v in vals)):
            bad.append(" = ".join(p.strip() for p in parts))
    return bad


def _strings(obj) -> list[str]:
    if isinstance(obj, str):
        return [obj]
    if isinstance(obj, dict):
        return [s for v in obj.values() for s in _strings(v)]
    if isinstance(obj, list):
        return [s for v in obj for s in _strings(v)]
    return []


def test_the_checker_catches_a_false_chain():
    assert false_chains("note: Ozol's q = 0 = S_Σ + G_Σ = 3 + 0: it also counts") == ["Ozol's q = 0 = S_Σ + G_Σ = 3 + 0"]
    assert false_chains("m = 4 - 3 = 1 = 1 useful + 0 idle; T = 0.5·((2.5 - 3)/|2.5 - 3| + 1) = 0") == []
    assert false_chains("pulley a = 500 c = 350 h = 100") == []
    assert false_chains("| Grübler | `W = 3(4 - 1) - 2·4 - 0 = 2` | 2 |") == ["`W = 3(4 - 1) - 2·4 - 0 = 2`"]


def _is_mechanism(path: Path) -> bool:
    text = path.read_text()
    return "joints:" in text and "links:" in text and "kind:" in text


@pytest.mark.parametrize("path", [p for p in FILES if _is_mechanism(p)], ids=lambda p: p.stem)
def test_every_printed_formula_is_true(path, run_cli):
    code, md, err = run_cli("analyze", path, "--markdown")
    if code == 2:  # not a mechanism file the analysis reads (e.g. a synthesis case)
        pytest.skip(err.strip())
    assert code == 0, err
    code, js, err = run_cli("analyze", path, "--json")
    assert code == 0, err
    texts = [md] + _strings(json.loads(js))
    bad = [c for t in texts for c in false_chains(t)]
    assert not bad, bad


def test_each_formula_states_its_reading(run_cli):
    code, md, _ = run_cli("analyze", EXAMPLES / "textbook/fourbar.yaml", "--markdown")
    assert code == 0
    for text in ("Chebyshev (planar)", "Grübler (N with the frame) (planar)", "Malyshev (spatial)",
                 "Ozol: redundant constraints (002) (planar)", "Contours (paper 003, spatial reading)",
                 "Ozol's q = 0 is the planar reading", "Ozol q = W + 3K - f (002, planar)"):
        assert text in md, text
