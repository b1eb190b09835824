"""Issue 42, item 1: every command-line path that is read, given /dev/zero, a FIFO or a
directory, answers with one line naming the path and exit status 2, at once.

Each command runs in-process; an interval timer is a safety net only (a reader blocking
on the FIFO would otherwise hang the suite): it turns a hang into a failure, and nothing
is asserted about time.
"""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

from test_corpus import one_error_line

ROOT = Path(__file__).resolve().parents[2]
EX = ROOT / "examples"
PATH_CASE = EX / "synthesis" / "path_cases_public.json"

#: (name, arguments); ``{}`` is the special file
COMMANDS = [
    ("analyze", ["analyze", "{}"]),
    ("structure", ["structure", "{}"]),
    ("simulate", ["simulate", "{}", "-i", "A=0:90:10"]),
    ("forces", ["forces", "{}", "-i", "A=0:90:10"]),
    ("capability", ["capability", "{}", "--direction", "1,0", "--point", "1,1"]),
    ("atlas --stream", ["atlas", "-n", "6", "--stream", "{}"]),
    ("belt analyze --file", ["belt", "analyze", "--file", "{}"]),
    ("belt analyze --table", ["belt", "analyze", "--file", str(EX / "belt" / "paper001.yaml"), "--law", "table",
                              "--table", "{}"]),
    ("belt inverse --file", ["belt", "inverse", "--file", "{}", "--speed", "1"]),
    ("synth finger", ["synth", "finger", "{}"]),
    ("synth finger-design", ["synth", "finger-design", "{}"]),
    ("synth finger-design --resume", ["synth", "finger-design", str(EX / "fingers" / "finger_design_case.yaml"),
                                      "--resume", "{}"]),
    ("synth path", ["synth", "path", "{}"]),
    ("synth path --resume", ["synth", "path", str(PATH_CASE), "--case", "P1", "--resume", "{}"]),
    ("synth motion", ["synth", "motion", "{}"]),
    ("synth mechanism", ["synth", "mechanism", "{}"]),
    ("synth mechanism --resume", ["synth", "mechanism", str(EX / "synthesis" / "sixbar_path_case.yaml"),
                                  "--resume", "{}"]),
    ("synth curve", ["synth", "curve", "{}"]),
    ("synth curve --database", ["synth", "curve", "{csv}", "--database", "{}"]),
    ("curves build --database", ["curves", "build", "--links", "4", "--database", "{}"]),
    ("convert", ["convert", "{}", "-o", "{out}"]),
    ("export", ["export", "{}", "--svg", "{out}.svg"]),
    ("serve", ["serve", "{}", "--no-browser", "--port", "0"]),
]


@pytest.fixture
def special(tmp_path, request):
    """The special file named by the test's parameter, under a name with a usual suffix."""
    kind = request.param
    path = tmp_path / "input.yaml"
    if kind == "/dev/zero":
        path.symlink_to("/dev/zero")
    elif kind == "fifo":
        os.mkfifo(path)  # nobody ever writes: reading it would block forever
    else:
        path.mkdir()
    return kind, path


@pytest.fixture
def safety_net():
    """Fail (instead of hanging the suite) when a command blocks; not a timing verdict."""

    def blocked(signum, frame):
        raise AssertionError("the command blocked on a special file")

    old = signal.signal(signal.SIGALRM, blocked)
    signal.setitimer(signal.ITIMER_REAL, 120.0)
    yield
    signal.setitimer(signal.ITIMER_REAL, 0.0)
    signal.signal(signal.SIGALRM, old)


@pytest.mark.parametrize("special", ["/dev/zero", "fifo", "directory"], indirect=True)
@pytest.mark.parametrize("name, args", COMMANDS, ids=[c[0] for c in COMMANDS])
def test_every_path_read_refuses_special_files(run_cli, special, safety_net, tmp_path, name, args):
    kind, path = special
    if "database" in name and kind == "directory":
        pytest.skip("a directory is what --database takes")
    if name.startswith(("synth curve", "convert", "export")):  # suffixes these commands read by
        target = path.with_name("input" + {"synth curve": ".csv", "convert": ".pyslvs"}.get(name, ".yaml"))
        if target != path:
            path.rename(target)
            path = target
    csv = tmp_path / "square.csv"
    csv.write_text("0,0\n1,0\n1,1\n0,1\n")
    argv = [a.replace("{}", str(path)).replace("{out}", str(tmp_path / "out.yaml")).replace("{csv}", str(csv))
            for a in args]
    code, out, err = run_cli(*argv)
    assert code == 2, (code, out[-400:], err[-400:])
    msg = one_error_line(err)
    assert str(path) in msg or path.name in msg, msg
    assert any(w in msg for w in ("not a regular file", "a directory")), msg
    assert not list(tmp_path.glob("out*")), "an output was written"
