"""Fuzzing (issue 18, item 4): random and broken mechanism, case and arm files and command
lines. Each input must give exit 0 with finite output, or exit 2 with one line naming the
problem; never a traceback, a hang (an alarm per example) or a half-written file. Through
the Python API the same inputs raise MechsynInputError, never a bare TypeError,
LinAlgError or RecursionError.

The default run is short (a few seconds of examples); ``-m slow`` runs a deeper one.
``MECHSYN_FUZZ_SCALE=20`` multiplies every example count by 20 and draws new random
examples (the default run is derandomised, so CI is reproducible), for a long local hunt.
"""

from __future__ import annotations

import copy
import json
import math
import os
import signal
import tempfile
from contextlib import contextmanager
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mechsyn.cli.main import main
from mechsyn.errors import MechsynInputError

ROOT = Path(__file__).resolve().parents[2]
EX = ROOT / "examples"
SEEDS = {
    "fourbar": EX / "kinematics" / "crank_rocker.yaml",
    "slider": EX / "textbook" / "slider_crank.yaml",
    "cam": EX / "kinematics" / "cam_polar.yaml",
    "sixbar": EX / "textbook" / "watt_sixbar.yaml",
}
ARM = EX / "capability" / "paper004_3r.yaml"
CASE = EX / "synthesis" / "slider_crank_path_case.yaml"
HANG_SECONDS = 60   # an example running longer than this is a hang, not slowness
SCALE = max(1, int(os.environ.get("MECHSYN_FUZZ_SCALE", "1")))
FIXED = SCALE == 1  # derandomised in CI; a scaled local run draws new examples


@contextmanager
def hang_guard(seconds: int = HANG_SECONDS):
    """Fail an example that runs longer than ``seconds`` (SIGALRM; main thread only)."""
    def alarm(signum, frame):
        raise TimeoutError(f"no answer within {seconds} s: a hang")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


# ----------------------------------------------------------------------- strategies
NASTY_TEXT = st.sampled_from(["", "x" * 300, "\x1b[31mred\x1b[0m", "[link=https://e.example]l[/link]",
                              "A", "frame", "R", "P", "0", "nan", "-", "é", "[/]", "[bold]", "[crank]"])
SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(-10**6, 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e-300, 1e300, 1e308, -1e308]),
    NASTY_TEXT,
)
VALUES = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(NASTY_TEXT, inner, max_size=3)),
                      max_leaves=8)


def _paths(data, prefix=()):
    """Every (path, value) of nested dicts/lists."""
    yield prefix, data
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _paths(v, prefix + (k,))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _paths(v, prefix + (i,))


def _set(data, path, value):
    node = data
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value


def _delete(data, path):
    node = data
    for k in path[:-1]:
        node = node[k]
    del node[path[-1]]


@st.composite
def broken(draw, seed: dict):
    """``seed`` with a few random edits: values replaced, entries deleted, keys added."""
    data = copy.deepcopy(seed)
    for _ in range(draw(st.integers(1, 3))):
        paths = [p for p, _ in _paths(data) if p]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        action = draw(st.sampled_from(["replace", "replace", "delete", "add"]))
        try:
            if action == "replace":
                _set(data, path, draw(VALUES))
            elif action == "delete":
                _delete(data, path)
            else:
                node = data
                for k in path[:-1]:
                    node = node[k]
                if isinstance(node, dict):
                    node[draw(NASTY_TEXT)] = draw(VALUES)
        except (KeyError, IndexError, TypeError):
            pass
    return data


def _load(path: Path) -> dict:
    return yaml.safe_load(path.read_text())


def _dump(data) -> str:
    return yaml.safe_dump(data, sort_keys=False, allow_unicode=True)


def _check_cli(capsys, argv: list[str]) -> tuple[int, str]:
    """Run ``argv`` in-process and check the contract; return (status, stdout)."""
    capsys.readouterr()
    with hang_guard():
        try:
            code = main(argv)
        except (Exception, RecursionError) as exc:  # noqa: BLE001 - anything escaping is a failure
            pytest.fail(f"{' '.join(argv)}: {type(exc).__name__}: {exc}")
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    assert "\x1b]8;" not in out + err        # no hyperlinks (terminal injection)
    if code == 0:
        if "--json" in argv:
            _assert_finite(json.loads(out))
    else:
        assert code == 2, f"{argv}: exit {code}: {err}"
        lines = [ln for ln in err.strip().splitlines() if ln.strip()]
        assert lines and lines[0].startswith("error:"), err
        assert len(lines) <= 3, err     # one message (rich may wrap it)
    return code, out


def _assert_finite(obj) -> None:
    if isinstance(obj, float):
        assert math.isfinite(obj)
    elif isinstance(obj, dict):
        for v in obj.values():
            _assert_finite(v)
    elif isinstance(obj, list):
        for v in obj:
            _assert_finite(v)


def _api_contract(call, *args, **kwargs):
    """Run a library loader: it returns, or raises MechsynInputError; nothing else."""
    with hang_guard():
        try:
            return call(*args, **kwargs)
        except MechsynInputError:
            return None


# ----------------------------------------------------------------------- mechanism files
FAST = settings(max_examples=5 * SCALE, deadline=None, derandomize=FIXED,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
DEEP = settings(max_examples=25 * SCALE, deadline=None, derandomize=FIXED,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


def _mechanism_files_through_cli(capsys, data):
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "m.yaml"
        f.write_text(_dump(data), encoding="utf-8")
        for cmd in (["analyze"], ["structure"], ["simulate", "--input", "A=0:360:45"]):
            argv = [cmd[0], str(f), *cmd[1:], "--json"]
            _check_cli(capsys, argv)
        for cmd in ("analyze", "structure"):  # the terminal tables too (names with markup)
            _check_cli(capsys, [cmd, str(f)])


def _mechanism_data_through_api(data):
    from mechsyn.io import mechanism_from_dict

    _api_contract(mechanism_from_dict, data, "m.yaml")


@pytest.mark.parametrize("seed", ["fourbar", "slider", "cam"])
@FAST
@given(data=st.data())
def test_broken_mechanism_files_cli(capsys, seed, data):
    _mechanism_files_through_cli(capsys, data.draw(broken(_load(SEEDS[seed]))))


@settings(max_examples=60 * SCALE, deadline=None, derandomize=FIXED)
@given(data=st.data())
def test_broken_mechanism_data_api(data):
    seed = data.draw(st.sampled_from(sorted(SEEDS)))
    _mechanism_data_through_api(data.draw(broken(_load(SEEDS[seed]))))


@settings(max_examples=60 * SCALE, deadline=None, derandomize=FIXED)
@given(value=VALUES)
def test_any_data_as_mechanism_api(value):
    _mechanism_data_through_api(value)


# ----------------------------------------------------------------------- case and arm files
@settings(max_examples=60 * SCALE, deadline=None, derandomize=FIXED)
@given(data=st.data())
def test_broken_synthesis_cases_api(data):
    from mechsyn.synthesis.general import mechanism_case_from_dict

    _api_contract(mechanism_case_from_dict, data.draw(broken(_load(CASE))), str(CASE), base_dir=CASE.parent)


@settings(max_examples=60 * SCALE, deadline=None, derandomize=FIXED)
@given(data=st.data())
def test_broken_path_cases_api(data):
    from mechsyn.synthesis.path import PathCase

    cases = json.loads((ROOT / "tests" / "synthesis" / "data" / "synthesis_cases_public.json").read_text())
    _api_contract(PathCase.from_dict, data.draw(broken(cases["cases"][0])), "case.json")


@settings(max_examples=60 * SCALE, deadline=None, derandomize=FIXED)
@given(data=st.data())
def test_broken_arm_files_api(data):
    from mechsyn.capability.arm_file import arm_from_dict

    _api_contract(arm_from_dict, data.draw(broken(_load(ARM))), str(ARM), base_dir=ARM.parent)


@FAST
@given(data=st.data())
def test_broken_arm_files_cli(capsys, data):
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "arm.yaml"
        f.write_text(_dump(data.draw(broken(_load(ARM)))), encoding="utf-8")
        _check_cli(capsys, ["capability", str(f), "--point", "1300,900", "--direction", "1,0"])
        _check_cli(capsys, ["capability", str(f), "--grid", "1300:1500:100,500:700:100", "--direction",
                            "1,0", "--json"])


@settings(max_examples=40 * SCALE, deadline=None, derandomize=FIXED)
@given(data=st.data())
def test_broken_checkpoints_api(data):
    from mechsyn.checkpoint import RestartCheckpoint

    seed = {"format": "mechsyn-checkpoint", "version": 1, "kind": "k", "key": {"seed": 0},
            "finished": {"0": {"seed": 1, "x": [1.0, 2.0], "fitness": 0.5, "nfev": 3, "seconds": 1.0}},
            "partial": {"index": 1, "seed": 2, "x": [0.0, 1.0], "fitness": 2.0}}
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "ck.json"
        f.write_text(json.dumps(data.draw(broken(seed))), encoding="utf-8")
        _api_contract(RestartCheckpoint.open, f, "k", {"seed": 0}, resume=True)


# ----------------------------------------------------------------------- command lines
WORDS = st.sampled_from([
    "analyze", "structure", "simulate", "forces", "atlas", "capability", "synth", "path", "mechanism",
    str(SEEDS["fourbar"]), str(ARM), "--json", "--input", "A=0:360:30", "A=0:1e9:0.001", "A=0:0:0",
    "--links", "6", "100", "-1", "--mobility", "0", "--out", "/proc/nope/x.yaml", "--direction", "1,0",
    "nan", "1e308", "--step", "0", "--point", "1,1", "--", "-h", "\x1b[31m",
])


@settings(max_examples=20 * SCALE, deadline=None, derandomize=FIXED,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(argv=st.lists(WORDS, min_size=1, max_size=6))
def test_random_command_lines(capsys, argv):
    capsys.readouterr()
    with hang_guard():
        try:
            code = main(argv)
        except (Exception, RecursionError) as exc:  # noqa: BLE001
            pytest.fail(f"{argv}: {type(exc).__name__}: {exc}")
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    assert code in (0, 2), (argv, code, err)
    if code == 2 and err.strip():  # (a bare group prints its help instead)
        assert err.lstrip().startswith(("error:", "Usage:")), err
        if err.lstrip().startswith("error:"):
            assert len([ln for ln in err.splitlines() if ln.strip()]) <= 3, err


# ----------------------------------------------------------------------- deeper (slow) runs
@pytest.mark.slow
@pytest.mark.parametrize("seed", sorted(SEEDS))
@DEEP
@given(data=st.data())
def test_broken_mechanism_files_cli_deep(capsys, seed, data):
    _mechanism_files_through_cli(capsys, data.draw(broken(_load(SEEDS[seed]))))


@pytest.mark.slow
@settings(max_examples=300 * SCALE, deadline=None, derandomize=FIXED)
@given(data=st.data())
def test_broken_mechanism_data_api_deep(data):
    seed = data.draw(st.sampled_from(sorted(SEEDS)))
    _mechanism_data_through_api(data.draw(broken(_load(SEEDS[seed]))))
