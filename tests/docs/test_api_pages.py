"""The API reference covers every public module: the pages docs/hooks/api.py makes list
each module that Python's own package walk finds, exactly once."""

from __future__ import annotations

import importlib.util
import pkgutil
from pathlib import Path

import mechsyn

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("api_hook", ROOT / "docs" / "hooks" / "api.py")
api_hook = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(api_hook)


def _walk() -> set[str]:
    names = {"mechsyn"}
    for info in pkgutil.walk_packages(mechsyn.__path__, "mechsyn.", onerror=lambda name: None):
        if not any(part.startswith("_") for part in info.name.split(".")):
            names.add(info.name)
    return names


def test_every_public_module_is_on_one_page():
    listed = [m for _, modules in api_hook.pages().values() for m in modules]
    assert len(listed) == len(set(listed))
    assert set(listed) == _walk()


def test_pages_render_each_module_and_packages_without_members():
    for path, (title, modules) in api_hook.pages().items():
        text = api_hook._page(title, modules)
        assert text.startswith(f"# {title}\n")
        assert [ln[4:] for ln in text.splitlines() if ln.startswith("::: ")] == modules
    assert "members: false" in api_hook._page("Structure", ["mechsyn.structure"])
    assert "members: false" not in api_hook._page("Structure", ["mechsyn.structure.rank"])


def test_navigation_lists_every_page():
    config = {"nav": [{"Home": "index.md"}, {"API reference": []}]}
    nav = api_hook.on_config(config)["nav"]
    assert [next(iter(e.values())) for e in nav[1]["API reference"]] == list(api_hook.pages())


def test_references_read_as_numbered_lines():
    html = ('<details class="references" open>\n  <summary>References</summary>\n'
            '  <p>.. [1] First, "A title"\n   more.\n.. [2] Second.</p>\n</details>')
    out = api_hook.citations_as_list(html)
    assert ".. [" not in out
    assert "<p>[1] First" in out and "<br>\n[2] Second." in out
    assert api_hook.citations_as_list("<p>.. [1] outside a References section</p>").startswith("<p>.. [1]")
