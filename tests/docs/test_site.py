"""The documentation site a user reads: cross references are links, no internal notes,
the home page shows a picture, the studio and the two-command start (issue 26 §6)."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("roles_hook", ROOT / "docs" / "hooks" / "roles.py")
roles = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(roles)

RAW_ROLE = re.compile(r":(?:func|class|meth|mod|attr|data|obj|exc):<code>")
#: reStructuredText that survived into a code block of the built site (an indented docstring
#: paragraph becomes a code block in Markdown: roles, double backticks and RST tables show raw)
RAW_IN_CODE = re.compile(r":(?:func|class|meth|mod|attr|data|obj|exc|const):`|``[^`\s]|^ *={4,} +={4,}", re.M)
_PRE = re.compile(r"<(?:pre|code)[^>]*>(.*?)</(?:pre|code)>", re.S)  # code blocks and inline code (a type column)
INTERNAL = "not in the project's copy"


def test_roles_become_autorefs_resolved_where_they_are_written():
    pytest.importorskip("griffe", reason="the docs extra (mkdocstrings) resolves the roles")
    html = ('<h2 id="mechsyn.structure.rank">rank</h2><p>see :func:<code>analyze_rank</code>, '
            ':class:<code>~mechsyn.structure.report.StructureReport</code>, :func:<code>numpy.linalg.svd</code> '
            'and :mod:<code>.screws</code></p>')
    out = roles.link_roles(html)
    assert not RAW_ROLE.search(out)
    assert '<autoref identifier="mechsyn.structure.rank.analyze_rank" optional><code>analyze_rank</code>' in out
    assert ('<autoref identifier="mechsyn.structure.report.StructureReport" optional>'
            '<code>StructureReport</code></autoref>') in out
    assert "<code>numpy.linalg.svd</code>" in out and 'identifier="numpy' not in out  # not ours: plain code
    assert 'identifier="mechsyn.structure.screws"' in out


def test_no_docstring_carries_the_internal_note():
    hits = [str(p.relative_to(ROOT)) for p in (ROOT / "src").rglob("*.py") if INTERNAL in p.read_text()]
    hits += [str(p.relative_to(ROOT)) for p in (ROOT / "docs").rglob("*.md") if INTERNAL in p.read_text()]
    assert hits == []


def test_home_page_has_a_figure_the_studio_and_the_two_command_start():
    home = (ROOT / "docs" / "index.md").read_text()
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", home)
    assert images and all((ROOT / "docs" / im).is_file() for im in images)
    assert "mechsyn serve" in home and "studio" in home.lower()
    assert re.search(r"pip install mechsyn\s*\n\s*mechsyn ", home)


def test_notebook_tutorial_is_linked():
    pages = [p.read_text() for p in (ROOT / "docs").rglob("*.md")] + [(ROOT / "README.md").read_text()]
    assert any("tutorial.ipynb" in text for text in pages)


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None, reason="needs mechsyn[docs]")
def test_built_site_has_links_not_raw_roles(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d", str(tmp_path / "site")],
                          cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    pages = {p: p.read_text(encoding="utf-8") for p in (tmp_path / "site").rglob("*.html")}
    raw = {str(p.relative_to(tmp_path)): len(RAW_ROLE.findall(t)) for p, t in pages.items() if RAW_ROLE.search(t)}
    assert raw == {}
    in_code = {str(p.relative_to(tmp_path)): m.group(0) for p, t in pages.items() if "/api/" in str(p)
               for block in _PRE.findall(t) for m in [RAW_IN_CODE.search(re.sub(r"<[^>]+>", "", block))] if m}
    assert in_code == {}, in_code
    assert not [p for p, t in pages.items() if INTERNAL in t]
    links = sum(t.count('class="autorefs autorefs-internal"') for p, t in pages.items() if "/api/" in str(p))
    assert links > 300
    # the tutorials and the first steps show what their commands print and draw, run at build
    for page in ("getting-started", "tutorials/sixbar-path", "tutorials/gripper"):
        text = (tmp_path / "site" / page / "index.html").read_text(encoding="utf-8")
        assert text.count("Output of") >= 2, page
    assert 'src="../run/getting-started/crank_rocker.svg"' in (tmp_path / "site" / "getting-started"
                                                                / "index.html").read_text(encoding="utf-8")


HISTORY = re.compile(r"\b[Ii]ssues? \d+\b|\b(?:main|commit) `?[0-9a-f]{7}\b|\bstop \d+\b|was not reproduced")


def test_user_guides_carry_no_development_history():
    """The user guides describe mechsyn as it is; issue numbers, commit hashes and what an
    earlier version did are kept in docs/changelog.md (the development notes)."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    hits = [f"{p.relative_to(ROOT)}:{n}: {m.group(0)}" for p in pages if p.name != "changelog.md"
            for n, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) for m in [HISTORY.search(line)] if m]
    assert hits == []
    assert HISTORY.search((ROOT / "docs" / "changelog.md").read_text(encoding="utf-8"))  # the history is kept
