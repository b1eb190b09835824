"""Every ``mechsyn ...`` command shown in the README and docs runs as written.

Commands are taken from fenced blocks (no language, ``bash``, ``sh``, ``shell`` or
``console``); usage synopses with placeholders live in ``text`` blocks. Each command
runs in-process in a temporary directory (one per page, so a command may read what an
earlier one on the page wrote) that sees the repository's ``examples/``; ``> FILE``
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
    for page, cmd in doc_commands():
        long = any(k in cmd for k in LONG)
        if long and not RUN_ALL:
            continue
        # one page's commands run in order on one worker (a later one may read an earlier one's output)
        marks = [pytest.mark.xdist_group(page)] + ([pytest.mark.slow] if long else [])
        yield pytest.param(page, cmd, id=f"{page}:{cmd[:60]}", marks=marks)


@pytest.fixture(scope="session")  # not module: a worker may run another module's tests between
def page_dirs(tmp_path_factory):  # two commands of a page, which would tear a module fixture down
    dirs: dict[str, Path] = {}

    def get(page: str) -> Path:
        if page not in dirs:
            dirs[page] = tmp_path_factory.mktemp(Path(page).stem)
            (dirs[page] / "examples").symlink_to(ROOT / "examples")
        return dirs[page]

    return get


def test_the_docs_show_commands():
    cmds = doc_commands()
    assert len(cmds) >= 40
    assert sum(not any(k in c for k in LONG) for _, c in cmds) >= 30  # most run by default


@pytest.mark.parametrize("page, command", list(_params()))
def test_documented_command_runs(page, command, page_dirs, monkeypatch, capsys):
    tmp_path = page_dirs(page)
    monkeypatch.chdir(tmp_path)
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
