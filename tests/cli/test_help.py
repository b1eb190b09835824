"""Help texts: literal brackets survive, flags are shown as flags."""

from __future__ import annotations

import pytest


@pytest.mark.parametrize("command", [["synth", "motion"], ["simulate"], ["convert"], ["export"], ["analyze"]])
def test_help_keeps_brackets_and_flags(command, run_cli):
    code, out, err = run_cli(*command, "--help")
    assert code == 0, err
    assert "<bool>" not in out  # a flag takes no value
    assert "╭" not in out  # plain text: no markup parsing, so no [...] is eaten


def test_literal_brackets_in_help(run_cli):
    code, out, _ = run_cli("synth", "motion", "--help")
    assert '{"poses": [[x, y, angle_deg], ...]}' in " ".join(out.split())
    code, out, _ = run_cli("export", "--help")
    assert "--frame / --no-frame" in out and "--dimensions" in out


def test_repeatable_options_show_their_form(run_cli, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    code, out, _ = run_cli("simulate", "--help")
    assert "-i, --input J=A:B:S" in out and "--straight P=A:B" in out
    code, out, _ = run_cli("export", "--help")
    assert "--pose J=V" in out


def _all_commands() -> list[list[str]]:
    from mechsyn.cli.main import COMMANDS, _load

    out = []
    for name in COMMANDS:
        out.append([name])
        sub = getattr(_load(name), "commands", {})
        out += [[name, s] for s in sub]
    return out


@pytest.mark.parametrize("command", _all_commands(), ids=" ".join)
def test_every_help_reads_at_80_columns(command, run_cli, monkeypatch):
    """At COLUMNS=80: no line wider than 80, flags take no value, every option says what it does."""
    monkeypatch.setenv("COLUMNS", "80")
    code, out, err = run_cli(*command, "--help")
    assert code == 0, err
    assert "<bool>" not in out
    assert "<list[" not in out  # repeatable options read as the field writes them (metavar=)
    wide = [ln for ln in out.splitlines() if len(ln) > 80]
    assert not wide, wide
    lines = out.splitlines()
    start = lines.index("Options:") + 1
    bare = [ln for ln in lines[start:] if ln.startswith("  -") and len(ln.split("  ")) < 3
            and not (lines[lines.index(ln) + 1:] or [""])[0].startswith("        ")]
    assert not bare, f"options without help: {bare}"
