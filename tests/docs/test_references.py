"""No docstring cites a seed paper only by its number: every module that names "paper 00N"
carries the paper's full reference in its docstring's References section, and the
references page lists all five."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SRC = ROOT / "src" / "mechsyn"
_CITE = re.compile(r"[Pp]apers? (00[0-4])((?:,? (?:and )?00[0-4])*)")
#: words of each paper's reference that a citation by number alone lacks
FULL = {
    "000": ("Borisov", "Kolyubin", "variable-length"),
    "001": ("servicing technological machines",),
    "002": ("crank-slider mechanisms of gripping",),
    "003": ("Egorov", "Buynov", "10.17587/mau.17.239-244"),
    "004": ("Pritykin", "Rinsel'man", "mobility of planar manipulator"),
}


def _cited(text: str) -> set[str]:
    out = set()
    for m in _CITE.finditer(text):
        out.add(m.group(1))
        out.update(re.findall(r"00[0-4]", m.group(2)))
    return out


def _docstrings(tree: ast.Module) -> list[str]:
    nodes = [tree, *(n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.ClassDef,
                                                               ast.AsyncFunctionDef)))]
    return [d for d in (ast.get_docstring(n) for n in nodes) if d]


MODULES = sorted(p for p in SRC.rglob("*.py") if _cited("\n".join(_docstrings(ast.parse(p.read_text())))))


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(SRC)))
def test_module_docstring_gives_full_references(path):
    tree = ast.parse(path.read_text())
    module_doc = ast.get_docstring(tree) or ""
    refs = module_doc.split("\nReferences\n----------\n", 1)
    assert len(refs) == 2, f"{path.name}: cites a seed paper but its docstring has no References"
    refs_text = " ".join(refs[1].split())
    for number in sorted(_cited("\n".join(_docstrings(tree)))):
        missing = [w for w in FULL[number] if w not in refs_text]
        assert not missing, f"{path.name}: paper {number} cited, its reference lacks {missing}"


def test_references_page_lists_every_paper_in_full():
    page = " ".join((ROOT / "docs" / "references.md").read_text().split())
    for number, words in FULL.items():
        assert f"Paper {number}" in page
        assert all(w in page for w in words), number


def test_the_check_finds_a_citation_by_number():
    assert _cited("as in paper 003; seed papers 002 and 004") == {"002", "003", "004"}
    assert not _cited("examples/capability/paper004_3r.yaml")
