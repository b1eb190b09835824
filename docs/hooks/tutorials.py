"""MkDocs hook: the tutorials show what their commands print and draw, run at build time.

Every ``mechsyn`` command in a ``bash`` block of ``getting-started.md`` and
``tutorials/*.md`` runs in-process, in
order, in one temporary directory per page that sees the repository's ``examples/`` (so a
command reads what an earlier one wrote), with the terminal 80 columns wide. Under each
block the page then shows, for each command, what it printed (its first lines and how
many more there are, when long) and the figures it wrote (PNG, GIF and SVG files, added to
the site under ``run/<page>/``). A command that fails fails the build: a
tutorial cannot drift from what mechsyn does.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIGURES = (".png", ".gif", ".svg")
#: lines of a command's output shown (the rest is counted)
MAX_LINES = 40

_BLOCK = re.compile(r"^```(?:bash|sh|shell|console)?[ \t]*\n(.*?)^```[ \t]*$", re.M | re.S)
#: page -> [(block source, [(command, printed text, [figure uris])])]
_RUNS: dict[str, list[tuple[str, list[tuple[str, str, list[str]]]]]] = {}


def _commands(block: str) -> list[str]:
    body = re.sub(r"\\\n\s*", " ", block)
    return [ln.strip() for ln in body.splitlines() if ln.strip().startswith("mechsyn ")]


def run_command(cmd: str, where: Path) -> tuple[str, list[Path]]:
    """Run one documented command in ``where``; return what it printed and the figures it
    wrote (new or changed files). ``> FILE`` writes stdout to FILE, as a shell would."""
    from mechsyn.cli.main import main

    words = shlex.split(cmd, comments=True)
    redirect = None
    if ">" in words:
        k = words.index(">")
        words, redirect = words[:k], words[k + 1]
    before = {p: p.stat().st_mtime_ns for p in where.rglob("*") if p.is_file() and "examples" not in p.parts}
    old = Path.cwd()
    os.chdir(where)
    try:
        with contextlib.redirect_stdout(io.StringIO()) as out, contextlib.redirect_stderr(io.StringIO()) as err:
            code = main(words[1:])
    finally:
        os.chdir(old)
    if code != 0:
        raise RuntimeError(f"tutorial command failed ({code}): {cmd}\n{err.getvalue()}")
    if redirect:
        (where / redirect).write_text(out.getvalue())
        lines = out.getvalue().count("\n")
        printed = err.getvalue() + f"({lines} lines written to {redirect}; its first ones:)\n" + out.getvalue()
    else:
        printed = out.getvalue() + err.getvalue()
    after = [p for p in where.rglob("*") if p.is_file() and "examples" not in p.parts]
    figures = sorted(p for p in after if p.suffix in FIGURES and before.get(p) != p.stat().st_mtime_ns)
    return printed, figures


def shown(text: str, max_lines: int = MAX_LINES) -> str:
    """The first ``max_lines`` lines of ``text`` and how many more there are.

    Examples
    --------
    >>> print(shown("a\\nb\\nc\\nd", 2))
    a
    b
    … (2 more lines)
    """
    lines = text.rstrip().splitlines()
    if len(lines) <= max_lines:
        return "\n".join(lines)
    return "\n".join(lines[:max_lines] + [f"… ({len(lines) - max_lines} more lines)"])


def on_files(files, config):
    import sys

    from mkdocs.structure.files import File

    sys.path.insert(0, str(ROOT / "src"))
    import matplotlib

    matplotlib.use("Agg")
    docs = Path(config["docs_dir"])
    for page in [docs / "getting-started.md", *sorted((docs / "tutorials").glob("*.md"))]:
        where = Path(tempfile.mkdtemp(prefix=f"mechsyn-tutorial-{page.stem}-"))
        (where / "examples").symlink_to(ROOT / "examples")
        runs = []
        for m in _BLOCK.finditer(page.read_text(encoding="utf-8")):
            done = []
            for cmd in _commands(m.group(1)):
                printed, figures = run_command(cmd, where)
                uris = []
                for fig in figures:
                    uri = f"run/{page.stem}/{fig.relative_to(where).as_posix()}"
                    if files.get_file_from_path(uri) is not None:
                        files.remove(files.get_file_from_path(uri))
                    files.append(File.generated(config, uri, content=fig.read_bytes()))
                    uris.append(uri)
                done.append((cmd, printed, uris))
            runs.append((m.group(0), done))
        _RUNS[page.relative_to(docs).as_posix()] = runs
    return files


def with_output(markdown: str, runs: list, prefix: int = 0) -> str:
    """``markdown`` with each block's commands followed by what they printed and drew
    (``prefix``: how many folders deep the page is, for the figures' relative links)."""
    for block, done in runs:
        if not done:
            continue
        parts = [block, ""]
        for cmd, printed, uris in done:
            parts.append(f"Output of `{cmd if len(cmd) <= 70 else cmd[:67] + '...'}`:")
            parts += ["", "```text", shown(printed) or "(nothing printed)", "```", ""]
            parts += [f"![{Path(u).name}]({'../' * prefix}{u})" for u in uris] + [""]
        markdown = markdown.replace(block, "\n".join(parts), 1)
    return markdown


def on_page_markdown(markdown, page, config, files):
    runs = _RUNS.get(page.file.src_uri)
    return with_output(markdown, runs, page.file.src_uri.count("/")) if runs else markdown
