"""One runner for long jobs: local processes and a Dask LocalCluster give the
single-process results (atlas, capability map), with progress, deadlines and early stop."""

from __future__ import annotations

import operator
import time
from pathlib import Path

import numpy as np
import pytest

from mechsyn.capability.arm_file import load_arm
from mechsyn.capability.maps import capability_map
from mechsyn.errors import MechsynInputError
from mechsyn.parallel import check_parallel_options, run_tasks
from mechsyn.synthesis.chains import n_units, synthesize_chains, synthesize_chains_to_file

ROOT = Path(__file__).resolve().parents[2]
UR5 = ROOT / "examples" / "capability" / "ur5_dh.yaml"
TASKS = [(i, i + 1) for i in range(7)]


def test_order_progress_and_early_stop_in_one_process():
    seen, states = [], []
    out = run_tasks(operator.mul, TASKS, on_result=lambda i, r: seen.append((i, r)), progress=states.append)
    assert out == [i * (i + 1) for i in range(7)]
    assert seen == [(i, i * (i + 1)) for i in range(7)]
    assert [(p.done, p.total, p.stage) for p in states] == [(i + 1, 7, "tasks") for i in range(7)]
    assert run_tasks(operator.mul, TASKS, stop=lambda i, r: r >= 6) == [0, 2, 6, None, None, None, None]


def test_deadline_runs_the_first_task_only():
    assert run_tasks(operator.mul, TASKS, deadline=time.time() - 1) == [0] + [None] * 6


def assert_early_stop_contract(stopped, stop_index=2):
    """Up to the stopping task: the one-process results; after it: a task that was
    started keeps its own true result, a task not started is None (never another value)."""
    full = [i * (i + 1) for i in range(7)]
    assert stopped[:stop_index + 1] == full[:stop_index + 1]
    assert all(r is None or r == full[i] for i, r in enumerate(stopped) if i > stop_index)


def test_local_processes_equal_one_process():
    out = run_tasks(operator.mul, TASKS, workers=2)
    assert out == [i * (i + 1) for i in range(7)]
    seen = []
    stopped = run_tasks(operator.mul, TASKS, workers=2, stop=lambda i, r: r >= 6,
                        on_result=lambda i, r: seen.append(i))
    assert_early_stop_contract(stopped)
    assert sorted(seen) == [i for i, r in enumerate(stopped) if r is not None]  # each once


def test_early_stop_keeps_later_results_that_finished_first():
    from mechsyn.parallel import _Book

    results, found, states = [None] * 7, [], []
    book = _Book(7, states.append, lambda i, r: r >= 6, lambda i, r: found.append(i))
    for i in (0, 1, 3, 2):  # task 3 finishes before the stopping task 2
        book.finished(i, i * (i + 1), results)
    assert results == [0, 2, 6, 12, None, None, None] and book.limit == 3
    assert found == [0, 1, 3, 2] and [(p.done, p.total) for p in states] == [(1, 7), (2, 7), (3, 7), (4, 7)]


def test_options_checked():
    with pytest.raises(MechsynInputError):
        check_parallel_options(0, None)
    with pytest.raises(MechsynInputError):
        check_parallel_options(2, "tcp://127.0.0.1:8786")


def test_atlas_with_local_processes_is_the_same_atlas(tmp_path):
    one = synthesize_chains(10, 1)
    ticks = []
    two = synthesize_chains(10, 1, workers=2, progress=ticks.append)
    assert [c.edges for c in one] == [c.edges for c in two] and len(two) == 230
    assert [c.certificate for c in one] == [c.certificate for c in two]
    # shares of the assortments, from the workers, counted up to all of them
    assert ticks[-1].done == pytest.approx(n_units(10, 1)) and ticks[-1].total == n_units(10, 1)
    assert len(ticks) >= n_units(10, 1) and all(0 < b.done - a.done <= 1 for a, b in zip(ticks, ticks[1:]))
    streamed = synthesize_chains_to_file(tmp_path / "c.jsonl", 10, 1, workers=2)
    assert [c.edges for c in streamed] == [c.edges for c in one]


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as c:
            yield c


def test_dask_local_cluster_equals_one_process(client):
    seen = []
    out = run_tasks(operator.mul, TASKS, scheduler=client,
                    on_result=lambda i, r: seen.append(i))
    assert out == [i * (i + 1) for i in range(7)] and sorted(seen) == list(range(7))
    stopped = run_tasks(operator.mul, TASKS, scheduler=client, stop=lambda i, r: r >= 6)
    assert_early_stop_contract(stopped)
    atlas = synthesize_chains(8, 1, scheduler=client)
    assert [c.edges for c in atlas] == [c.edges for c in synthesize_chains(8, 1)]
    arm = load_arm(UR5)
    grid = (np.array([300.0, 500]), np.array([-100.0, 100]))
    a = capability_map(arm, *grid, [1, 0, 0], z=300, chunk=1, scheduler=client)
    b = capability_map(arm, *grid, [1, 0, 0], z=300)
    np.testing.assert_array_equal(a.value, b.value)
    np.testing.assert_array_equal(a.q, b.q)


def test_unreachable_scheduler_is_one_clear_error(monkeypatch):
    pytest.importorskip("dask.distributed")
    monkeypatch.setenv("MECHSYN_SCHEDULER_TIMEOUT", "1")
    with pytest.raises(MechsynInputError) as exc:
        run_tasks(operator.mul, TASKS, scheduler="tcp://127.0.0.1:9")
    assert exc.value.field == "scheduler"  # the library names its parameter; the CLI shows --scheduler
    from mechsyn.cli.common import option_error

    assert option_error(exc.value).format().startswith("--scheduler: cannot reach the Dask scheduler")


@pytest.mark.slow
def test_synth_mechanism_restarts_in_processes_equal_one_process():
    from mechsyn.synthesis.general import load_mechanism_case, synthesize_mechanism

    case = load_mechanism_case(ROOT / "examples" / "synthesis" / "slider_crank_path_case.yaml")
    fast = {"maxiter": 15, "popsize": 5}  # generation budgets: no timing decides the result
    one = synthesize_mechanism(case, seed=2, restarts=2, time_limit=300, options=fast, n_polish=1)
    two = synthesize_mechanism(case, seed=2, restarts=2, time_limit=300, options=fast, n_polish=1,
                               workers=2)
    assert one.design == two.design and one.restart_errors == two.restart_errors
    assert one.restarts == two.restarts == 2
