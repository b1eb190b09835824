"""One progress protocol (issue 37, item 7): every long computation calls ``progress(state)``
with a :class:`mechsyn.progress.Progress`, counted from the start of the run; the command
line draws it with one rich bar (``mechsyn.cli.common.progress_bar``), the studio's jobs
send its ``to_dict()``."""

from __future__ import annotations

import dataclasses
import io
import json

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.progress import Progress, counter, report


def test_progress_is_one_small_immutable_record():
    p = Progress(done=2, total=8, stage="restarts", best=0.5, message="branch +1")
    assert p.fraction == 0.25 and Progress(done=2).fraction is None and Progress(1, 0).fraction is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.done = 3  # type: ignore[misc]
    assert Progress(best=float("inf")).best is None and Progress(best=float("nan")).best is None
    d = p.to_dict()
    assert d == {"done": 2, "total": 8, "stage": "restarts", "best": 0.5, "message": "branch +1"}
    assert json.loads(json.dumps(d, allow_nan=False)) == d  # the studio's event stream
    seen: list[Progress] = []
    advance = counter(seen.append, 10, "rows")
    advance()
    advance(4)
    report(seen.append, 7, 10, "rows", best=np.float64(0.25))
    report(None, 1)  # nobody listens: nothing happens
    assert [(s.done, s.total, s.stage) for s in seen] == [(1, 10, "rows"), (5, 10, "rows"), (7, 10, "rows")]
    assert isinstance(seen[-1].to_dict()["best"], float)


def _states(run) -> list[Progress]:
    seen: list[Progress] = []
    run(seen.append)
    assert seen and all(isinstance(s, Progress) for s in seen), seen[:3]
    return seen


@pytest.mark.parametrize("name, method", [("crank_rocker", "auto"), ("crank_rocker", "newton"),
                                          ("slider_crank", "tracked groups"), ("bennett", "auto")])
def test_a_sweep_reports_its_rows(name, method):
    mech = ms.examples.load(name)
    drive = next(j.id for j in mech.joints if j.actuated)
    u = ms.input_grid(0.0, 90.0, 5.0)
    seen = _states(lambda p: ms.simulate(mech, {drive: u}, method=method, progress=p))
    assert seen[-1].done == seen[-1].total == len(u) and {s.stage for s in seen} == {"sweep"}
    assert all(b.done >= a.done for a, b in zip(seen, seen[1:]))  # counted from the start


def test_tasks_chains_and_the_rank_method_report_progress():
    from mechsyn.parallel import run_tasks
    from mechsyn.structure.rank import analyze_rank
    from mechsyn.synthesis.chains import n_units, synthesize_chains

    tasks = _states(lambda p: run_tasks(pow, [(2, k) for k in range(5)], progress=p))
    assert [(s.done, s.total, s.stage) for s in tasks] == [(k, 5, "tasks") for k in range(1, 6)]
    chains = _states(lambda p: synthesize_chains(8, 1, progress=p))
    assert chains[-1].done == chains[-1].total == n_units(8, 1)
    rank = _states(lambda p: analyze_rank(ms.examples.load("watt_sixbar"), progress=p))
    assert [s.stage for s in rank][:3] == ["contours", "rank", "idle"] and rank[0].total == 4


def test_searches_report_the_best_so_far(tmp_path):
    from mechsyn.capability.arm_file import load_arm
    from mechsyn.capability.maps import capability_map
    from mechsyn.synthesis.curves.database import build_database

    arm = load_arm(ms.examples.path("paper004_3r"))
    cap = _states(lambda p: capability_map(arm, np.linspace(1300, 2100, 3), np.linspace(100, 900, 3), [1, 0],
                                           chunk=4, progress=p))
    assert [(s.done, s.total, s.stage) for s in cap] == [(4, 9, "points"), (8, 9, "points"), (9, 9, "points")]
    db = _states(lambda p: build_database(tmp_path, max_links=4, per_topology=20, progress=p))
    assert (db[-1].done, db[-1].total, db[-1].stage, db[-1].message) == (1, 1, "build", "20 curves")
    # path and mechanism synthesis: tests/synthesis/test_problem.py (restarts done of all, the best)


def test_the_command_line_draws_a_progress_with_its_best(monkeypatch):
    from rich.console import Console

    from mechsyn.cli import common

    buf = io.StringIO()
    monkeypatch.setattr(common, "err_console", Console(file=buf, force_terminal=True, width=80))
    with common.progress_bar("synth path", 4) as progress:
        progress(Progress(done=3, total=4, stage="restarts", best=0.0123))
    text = buf.getvalue()
    assert "synth path: restarts" in text and "3/4" in text and "best 0.0123" in text
    with common.progress_bar("quiet", 4, enabled=False) as progress:
        assert progress is None  # the library call then reports to nobody


def test_a_studio_job_keeps_the_progress_as_its_dict():
    from mechsyn.web._jobs import Job

    job = Job("j1", "curve", lambda params, progress: {}, {})
    assert job.snapshot()["progress"] == Progress().to_dict()
    job._report(Progress(done=2, total=5, stage="refine", best=0.03))
    assert job.snapshot()["progress"] == {"done": 2, "total": 5, "stage": "refine", "best": 0.03, "message": ""}
