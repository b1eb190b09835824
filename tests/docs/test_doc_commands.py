"""Every ``mechsyn ...`` command shown in the README and docs runs as written.

Commands are taken from fenced blocks (no language, ``bash``, ``sh``, ``shell`` or
``console``); usage synopses with placeholders live in ``text`` blocks. A page's commands
run in-process, in page order, as one test in a temporary directory of its own (a command
may read what an earlier one on the page wrote, on any number of workers) without the
repository's ``examples/``: the docs name the bundled examples (``mechsyn analyze fourbar``),
which work after ``pip install mechsyn`` (:func:`test_docs_name_bundled_examples`); ``> FILE``
redirects its output there.

Commands that take more than a few seconds (synthesis runs, fine grids, the 12-link
atlas) and those reading their output run only with ``MECHSYN_DOC_COMMANDS=all``: CI
runs them in ``.ci/steps/doc-commands.sh``, keeping the default suite short.
"""

from __future__ import annotations

import os
import re
import shlex
from pathlib import Path

import pytest

from mechsyn.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
_FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.M | re.S)
LONG = ("--links 12", "--links 10", "atlas8.svg", "finger-design", "finger_best", "synth path",
        "synth mechanism", "six.yaml", "synth motion examples/", "cam_roller.yaml --input O=0:360:5 --animate",
        "ur5_dh.yaml --grid", "--grid 1000:2600", "three_phalanx_base_000.yaml --max-links 4",
        "belt analyze --file", "triple_rocker.yaml --input A=0:360:2 --plot")
RUN_ALL = os.environ.get("MECHSYN_DOC_COMMANDS") == "all"
#: commands that start a server and run until stopped: tests/web/test_serve_cli.py starts
#: them (bound to a free port) instead
SERVERS = ("mechsyn serve",)


def doc_commands() -> list[tuple[str, str]]:
    """(page, command) for every mechsyn command in the runnable fenced blocks."""
    out = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for lang, body in _FENCE.findall(text):
            if lang not in ("", "bash", "sh", "shell", "console"):
                continue
            body = re.sub(r"\\\n\s*", " ", body)
            for line in body.splitlines():
                line = line.strip()
                if line.startswith("$ "):
                    line = line[2:]
                for part in line.split("&&"):  # e.g. pip install -e . && mechsyn analyze ...
                    part = part.strip()
                    if part.startswith("mechsyn ") and not part.startswith(SERVERS):
                        out.append((str(page.relative_to(ROOT)), part))
    return out


def _params():
    """One test per page: its commands run in page order in one directory (a later one may
    read an earlier one's output), whatever the workers' distribution (``--dist load``,
    ``worksteal`` or none). The long commands run only with ``MECHSYN_DOC_COMMANDS=all``
    (then the page's test is marked slow)."""
    pages: dict[str, list[str]] = {}
    for page, cmd in doc_commands():
        pages.setdefault(page, []).append(cmd)
    for page, cmds in pages.items():
        long = [c for c in cmds if any(k in c for k in LONG)]
        run = cmds if RUN_ALL else [c for c in cmds if c not in long]
        if run:
            marks = [pytest.mark.slow] if long and RUN_ALL else []
            yield pytest.param(page, run, id=page, marks=marks)


def _run(command: str, tmp_path: Path, capsys) -> None:
    words = shlex.split(command, comments=True)
    redirect = None
    if ">" in words:
        k = words.index(">")
        words, redirect = words[:k], words[k + 1]
    if "|" in words:
        words = words[:words.index("|")]
    assert words[0] == "mechsyn"
    code = main(words[1:])
    out = capsys.readouterr()
    assert code == 0, f"{command}\n{out.err}"
    assert out.out.strip() or out.err.strip(), f"{command} said nothing"  # a command that did nothing
    if redirect:
        (tmp_path / redirect).write_text(out.out)


@pytest.mark.parametrize("page, commands", list(_params()))
def test_documented_commands_run(page, commands, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # no examples/ folder here: bundled names, as after pip install
    for command in commands:
        _run(command, tmp_path, capsys)
