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
