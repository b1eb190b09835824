"""Every Python block of the README and docs runs, and the values it shows are checked.

A page's ``python`` blocks run in order in one namespace, in a temporary directory that
sees the repository's ``examples/`` (as the commands of tests/docs/test_doc_commands.py
do). A line ``expression  # -> value`` shows what the expression gives: the test checks
it (a number to the decimals shown, anything else exactly; the text after two spaces is
a comment). A block whose fence says ``title="sketch..."`` shows an interface with names
of the reader's own (``fn``, ``tasks``) and is not run. Blocks that run a search for
seconds (``LONG``) run with ``MECHSYN_DOC_COMMANDS=all``, as CI does.
"""

from __future__ import annotations

import ast
import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
_FENCE = re.compile(r"^```python([^\n]*)\n(.*?)^```", re.M | re.S)
_CHECK = re.compile(r"^(?P<code>\S.*?)\s*# -> (?P<expected>.+?)(?:\s{2,}.*)?$")
LONG = ("design_finger(", "synthesize_path(", "synthesize_chains(10", "synthesize_belt(")
RUN_ALL = os.environ.get("MECHSYN_DOC_COMMANDS") == "all"


def doc_blocks() -> dict[str, list[tuple[int, str]]]:
    """page -> its runnable Python blocks (first line number, code)."""
    out: dict[str, list[tuple[int, str]]] = {}
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for m in _FENCE.finditer(text):
            if 'title="sketch' in m.group(1):
                continue
            line = text.count("\n", 0, m.start()) + 2
            out.setdefault(str(page.relative_to(ROOT)), []).append((line, m.group(2)))
    return out


def checked_source(code: str, first_line: int) -> str:
    """``code`` with each ``expression  # -> value`` line turned into a check."""
    lines = []
    for k, line in enumerate(code.splitlines()):
        m = _CHECK.match(line)
        if m:
            lines.append(f"__check__(({m.group('code')}), {m.group('expected')!r}, {first_line + k})")
        else:
            lines.append(line)
    return "\n".join(lines) + "\n"


def _plain(value):
    if hasattr(value, "item") and getattr(value, "ndim", 1) == 0:
        return value.item()
    if isinstance(value, (tuple, list)):
        return type(value)(_plain(v) for v in value)
    return value


def check(value, expected: str, line: int) -> None:
    """``value`` equals the ``expected`` text: a float to its shown decimals, else exactly."""
    try:
        want = ast.literal_eval(expected)
    except (ValueError, SyntaxError):
        assert str(value) == expected, f"line {line}: {value!r} shown as {expected}"
        return
    got = _plain(value)
    if isinstance(want, float):
        decimals = len(expected.split(".")[1]) if "." in expected else 0
        assert abs(float(got) - want) <= 0.5 * 10 ** -decimals + 1e-12, f"line {line}: {got!r} shown as {expected}"
    else:
        assert got == want, f"line {line}: {got!r} shown as {expected}"


def test_checks_catch_a_wrong_value():
    ns = {"__check__": check}
    exec(checked_source("x = 2.0 / 3\nx  # -> 0.6667", 1), ns)  # noqa: S102
    exec(checked_source("x  # -> 0.667", 1), ns)  # noqa: S102 - 0.66667 to three decimals
    with pytest.raises(AssertionError, match="shown as 0.668"):
        exec(checked_source("x  # -> 0.668", 1), ns)  # noqa: S102
    exec(checked_source("(1, 'a')  # -> (1, 'a')   a comment", 1), ns)  # noqa: S102


def _params():
    for page, blocks in doc_blocks().items():
        long = any(k in code for _, code in blocks for k in LONG)
        if long and not RUN_ALL:
            continue
        yield pytest.param(page, marks=[pytest.mark.slow] if long else [], id=page)


def test_docs_show_python():
    blocks = doc_blocks()
    assert "docs/python.md" in blocks and sum(len(b) for b in blocks.values()) >= 8
    assert sum(code.count("# -> ") for b in blocks.values() for _, code in b) >= 10


@pytest.mark.parametrize("page", list(_params()))
def test_python_blocks_run_and_show_what_they_give(page, tmp_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    ns: dict = {"__check__": check, "__name__": "__doc__"}
    try:
        for line, code in doc_blocks()[page]:
            exec(compile(checked_source(code, line), f"{page}:{line}", "exec"), ns)  # noqa: S102
    finally:
        plt.close("all")
