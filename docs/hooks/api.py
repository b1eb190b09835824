"""MkDocs hook: the API reference covers every public module, found in the source tree.

One page per subpackage of ``mechsyn`` (``api/<package>.md``) and one for the top-level
modules (``api/index.md``); each page shows the package's docstring, then every public
module under it (names not starting with ``_``), in alphabetical order. The pages and the
"API reference" section of the navigation are made at build time, so a module added,
moved or renamed is documented without editing a list; a module whose docstring does not
render fails the ``--strict`` build.
"""

from __future__ import annotations

import re
from pathlib import Path


ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "src" / "mechsyn"
#: page titles of the known subpackages (others are titled by their name)
TITLES = {
    "io": "Mechanism files", "model": "Model", "structure": "Structure", "kinematics": "Kinematics",
    "synthesis": "Synthesis", "capability": "Capability", "belt": "Belt manipulator",
    "export": "Export", "plot": "Plotting", "web": "Studio and notebook widget",
    "cli": "Command line (internals)",
}


def _public(path: Path) -> bool:
    return not any(part.startswith("_") and part != "__init__.py" for part in path.relative_to(PACKAGE).parts)


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def public_modules() -> list[str]:
    """Every public module and package of mechsyn, dotted, sorted."""
    return sorted(_module_name(p) for p in PACKAGE.rglob("*.py") if _public(p))


def pages() -> dict[str, tuple[str, list[str]]]:
    """``{page path: (title, modules)}``: one page per subpackage, one for the top level."""
    subpackages = sorted(p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists() and _public(p / "__init__.py"))
    out: dict[str, tuple[str, list[str]]] = {}
    mods = public_modules()
    top = [m for m in mods if m == "mechsyn" or (m.count(".") == 1 and m.split(".")[1] not in subpackages)]
    out["api/index.md"] = ("Package and core modules", top)
    for sub in subpackages:
        prefix = f"mechsyn.{sub}"
        members = [m for m in mods if m == prefix or m.startswith(prefix + ".")]
        out[f"api/{sub}.md"] = (TITLES.get(sub, sub.replace("_", " ").capitalize()), members)
    return out


def _page(title: str, modules: list[str]) -> str:
    packages = {_module_name(p) for p in PACKAGE.rglob("__init__.py")}
    lines = [f"# {title}", ""]
    for m in modules:
        lines.append(f"::: {m}")
        if m in packages:  # the package's docstring; its modules follow on their own
            lines += ["    options:", "      members: false"]
        lines.append("")
    return "\n".join(lines)


def on_config(config):
    nav = config["nav"]
    entries = [{title: path} for path, (title, _) in pages().items()]
    for i, item in enumerate(nav):
        if isinstance(item, dict) and "API reference" in item:
            nav[i] = {"API reference": entries}
    return config


def on_files(files, config):
    for path, (title, modules) in pages().items():
        old = files.get_file_from_path(path)
        if old is not None:
            files.remove(old)
        from mkdocs.structure.files import File  # here: the tests import this hook without mkdocs

        files.append(File.generated(config, path, content=_page(title, modules)))
    return files


_CITATION = re.compile(r"(<p>|\n)\.\. \[(\d+)\] ")
_REFERENCES = re.compile(r'(<details class="references"[^>]*>.*?</details>)', re.S)


def citations_as_list(html: str) -> str:
    """numpydoc's ``.. [1] ...`` entries of a References section as numbered lines
    (``[1] ...``, one a line) instead of one run-on paragraph."""
    def fix(m: re.Match) -> str:
        return _CITATION.sub(lambda c: ("<p>" if c.group(1) == "<p>" else "<br>\n") + f"[{c.group(2)}] ",
                             m.group(1))
    return _REFERENCES.sub(fix, html)


def on_page_content(html, page, config, files):
    return citations_as_list(html) if page.file.src_uri.startswith("api/") else html
