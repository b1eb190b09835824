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
    """The states ``run(progress)`` reports, checked against the protocol: each a
    :class:`Progress`, ``0 <= done <= total`` (when the total is known), ``done`` never
    going back within a stage (a new stage may count its own steps, with its own total)."""
    seen: list[Progress] = []
    run(seen.append)
    assert seen and all(isinstance(s, Progress) for s in seen), seen[:3]
    _well_formed(seen)
    return seen


def _well_formed(seen: list[Progress]) -> None:
    last: dict[str, float] = {}
    for s in seen:
        assert s.done >= 0 and (s.total is None or s.done <= s.total), s
        assert s.done >= last.get(s.stage, 0), (s, last)  # monotone within its stage
        last[s.stage] = s.done


def test_the_checks_of_the_protocol_can_fail():
    with pytest.raises(AssertionError):
        _well_formed([Progress(3, 2, "rows")])
    with pytest.raises(AssertionError):
        _well_formed([Progress(2, 4, "rows"), Progress(1, 4, "rows")])
    _well_formed([Progress(2, 4, "build"), Progress(1, 1, "refine")])  # a new stage counts anew


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


def _long_computations():
    """Every public long computation of mechsyn (issue 37, item 7)."""
    from mechsyn.capability.maps import capability_grid, capability_map
    from mechsyn.kinematics.analysis import KinematicPlan, simulate
    from mechsyn.kinetostatics import forces
    from mechsyn.kinematics.report import simulation_report
    from mechsyn.kinematics.solve import sweep
    from mechsyn.kinematics.spatial import SpatialEngine, simulate_spatial
    from mechsyn.parallel import run_tasks
    from mechsyn.structure.rank import analyze_rank
    from mechsyn.structure.report import analyze
    from mechsyn.synthesis.atlas import chain_atlas
    from mechsyn.synthesis.chains import synthesize_chains, synthesize_chains_to_file
    from mechsyn.synthesis.curves.database import build_database, load_database
    from mechsyn.synthesis.curves.synthesis import synthesize_curve
    from mechsyn.synthesis.finger.design import design_finger
    from mechsyn.synthesis.general import synthesize_mechanism
    from mechsyn.synthesis.optimize import synthesize_path
    from mechsyn.synthesis.reports import curve_database, mechanism_synthesis, path_synthesis

    return [simulate, KinematicPlan.simulate, forces, simulation_report, sweep, simulate_spatial,
            SpatialEngine.simulate, analyze_rank, analyze, chain_atlas, synthesize_chains, synthesize_chains_to_file,
            build_database, load_database, synthesize_curve, curve_database, synthesize_path, path_synthesis,
            synthesize_mechanism, mechanism_synthesis, design_finger, capability_map, capability_grid, run_tasks]


@pytest.mark.parametrize("fn", _long_computations(), ids=lambda f: f.__qualname__)
def test_every_long_computation_takes_progress_by_one_name(fn):
    import inspect

    params = inspect.signature(fn).parameters
    assert "progress" in params, f"{fn.__qualname__} takes no progress="
    assert params["progress"].annotation == "ProgressCallback | None" and params["progress"].default is None
    assert not {"callback", "advance", "on_progress"} & set(params)  # one name, no second face


def test_the_newton_sweep_counts_its_rows_over_both_ways_from_the_drawn_pose():
    from mechsyn.kinematics.analysis import compile_plan
    from mechsyn.kinematics.engines import drawn_row

    mech = ms.examples.load("crank_rocker")
    drive = next(j.id for j in mech.joints if j.actuated)
    S = compile_plan(mech, inputs=(drive,)).system
    u0 = float(np.degrees(S.drivers[0].assembled))
    u = ms.input_grid(u0 - 40.0, u0 + 40.0, 5.0)  # the drawn pose inside: swept forwards, then backwards
    assert drawn_row(S, np.radians(u)[:, None]) not in (None, 0)
    seen = _states(lambda p: ms.simulate(mech, {drive: u}, method="newton", progress=p))
    assert [(s.done, s.total, s.stage) for s in seen] == [(k, len(u), "sweep") for k in range(1, len(u) + 1)]


def test_the_newton_solver_reports_progress_records_itself():
    from mechsyn.kinematics.analysis import compile_plan
    from mechsyn.kinematics.solve import sweep

    mech = ms.examples.load("slider_crank")
    drive = next(j.id for j in mech.joints if j.actuated)
    S = compile_plan(mech, inputs=(drive,)).system
    U = np.linspace(0.0, 1.0, 7)[:, None] + S.drivers[0].assembled
    seen = _states(lambda p: sweep(S, U, progress=p))
    assert [(s.done, s.total, s.stage) for s in seen] == [(k, 7, "sweep") for k in range(1, 8)]


def test_forces_and_reports_of_a_sweep_pass_its_progress_on():
    from mechsyn.kinetostatics import forces
    from mechsyn.kinematics.report import simulation_report

    mech = ms.examples.load("crank_rocker")
    drive = next(j.id for j in mech.joints if j.actuated)
    u = {drive: ms.input_grid(0.0, 60.0, 5.0)}
    for run in (lambda p: forces(mech, u, progress=p), lambda p: simulation_report(mech, u, progress=p)):
        seen = _states(run)
        assert seen[-1].done == seen[-1].total == len(u[drive]) and seen[-1].stage == "sweep"


def test_path_and_mechanism_synthesis_report_restarts_with_the_best():
    from mechsyn.synthesis.general import load_mechanism_case, synthesize_mechanism
    from mechsyn.synthesis.optimize import synthesize_path
    from mechsyn.synthesis.path import PathCase
    from mechsyn.synthesis.fourbar import fourbar_position

    th = [0.0, 0.4, 0.8, 1.2, 1.6]
    C = fourbar_position(3.0, 1.0, 3.0, 2.5, np.array(th), branch=-1, rcx=1.0, rcy=1.0).C
    case = PathCase.from_dict({
        "id": "known", "targets": C.tolist(), "timing": {"type": "prescribed", "theta2": th},
        "fixed": {"x0": 0.0, "y0": 0.0, "theta0": 0.0},
        "variables": [{"name": n, "lower": lo, "upper": 6.0} for n, lo in
                      (("r1", 0.1), ("r2", 0.1), ("r3", 0.1), ("r4", 0.1), ("rcx", -6.0), ("rcy", -6.0))]})
    fast = {"maxiter": 6, "popsize": 6}
    path = _states(lambda p: synthesize_path(case, seed=1, time_limit=60, restarts=2, options=fast, n_polish=1,
                                             progress=p))
    assert path[-1].done == path[-1].total == 2 and {s.stage for s in path} == {"restarts"}
    assert path[-1].best is not None
    mcase = load_mechanism_case(ms.examples.path("slider_crank_path_case"))
    mech = _states(lambda p: synthesize_mechanism(mcase, seed=0, time_limit=60, restarts=1, options=fast,
                                                  n_polish=1, progress=p))
    assert mech[-1].done == mech[-1].total == 1 and {s.stage for s in mech} == {"restarts"}


def test_curve_synthesis_reports_its_build_and_its_stages(tmp_path):
    from mechsyn.synthesis.curves.database import build_database, load_database
    from mechsyn.synthesis.curves.synthesis import synthesize_curve
    from mechsyn.synthesis.curves.target import target_from_points

    build_database(tmp_path, max_links=4, per_topology=40)
    t = np.linspace(0.0, 2 * np.pi, 60, endpoint=False)
    target = target_from_points(np.c_[3 * np.cos(t), 2 * np.sin(t)], closed=True)
    seen = _states(lambda p: synthesize_curve(target, max_links=4, top=1, refinements=2,
                                              database=load_database(tmp_path), progress=p))
    stages = [s.stage for s in seen]
    assert stages[0] == "retrieve" and stages[-1] == "done" and "refine" in stages
    assert [s.done for s in seen if s.stage == "refine"][-1] <= 2


def test_atlas_finger_design_and_capability_grid_report_progress():
    from dataclasses import replace

    from mechsyn.capability.arm_file import load_arm
    from mechsyn.capability.maps import capability_grid
    from mechsyn.synthesis.atlas import chain_atlas
    from mechsyn.synthesis.chains import n_units
    from mechsyn.synthesis.finger.cases import load_case
    from mechsyn.synthesis.finger.design import design_finger

    atlas = _states(lambda p: chain_atlas(6, 1, progress=p))
    assert atlas[-1].done == atlas[-1].total == n_units(6, 1)
    arm = load_arm(ms.examples.path("paper004_3r"))
    grid = _states(lambda p: capability_grid(arm, np.linspace(1300, 2100, 3), np.linspace(100, 900, 2), [1, 0],
                                             progress=p))
    assert grid[-1].done == grid[-1].total == 6
    case = replace(load_case(ms.examples.path("finger_design_three_phalanx")),
                   maxiter=4, popsize=5, force_maxiter=1, vll_steps=3, candidates=1)
    finger = _states(lambda p: design_finger(case, seed=0, progress=p))
    generations = [s for s in finger if s.total is not None]
    assert generations and all(s.stage.startswith("VLL ") for s in generations)
    assert max(s.done for s in generations if s.stage.endswith(": stage 1")) <= case.maxiter
