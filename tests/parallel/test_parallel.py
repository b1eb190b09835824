"""One runner for long jobs: local processes and a Dask LocalCluster give the
single-process results (atlas, capability map), with progress, deadlines and early stop."""

from __future__ import annotations

import operator
import time
from pathlib import Path

import numpy as np
import pytest

from mechsyn.capability.arm import load_arm
from mechsyn.capability.maps import capability_map
from mechsyn.errors import MechsynInputError
from mechsyn.parallel import check_parallel_options, run_tasks
from mechsyn.synthesis.chains import n_units, synthesize_chains, synthesize_chains_to_file

ROOT = Path(__file__).resolve().parents[2]
UR5 = ROOT / "examples" / "capability" / "ur5_dh.yaml"
TASKS = [(i, i + 1) for i in range(7)]


def test_order_progress_and_early_stop_in_one_process():
    seen = []
    out = run_tasks(operator.mul, TASKS, progress=lambda d, t, i, r: seen.append((d, t, i, r)))
    assert out == [i * (i + 1) for i in range(7)]
    assert seen == [(i + 1, 7, i, i * (i + 1)) for i in range(7)]
    assert run_tasks(operator.mul, TASKS, stop=lambda i, r: r >= 6) == [0, 2, 6, None, None, None, None]


def test_deadline_runs_the_first_task_only():
    assert run_tasks(operator.mul, TASKS, deadline=time.time() - 1) == [0] + [None] * 6


def test_local_processes_equal_one_process():
    out = run_tasks(operator.mul, TASKS, workers=2)
    assert out == [i * (i + 1) for i in range(7)]
    stopped = run_tasks(operator.mul, TASKS, workers=2, stop=lambda i, r: r >= 6)
    assert stopped[:3] == [0, 2, 6] and stopped[3:] == [None] * 4


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
    assert len(ticks) == n_units(10, 1)  # one per assortment
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
                    progress=lambda d, t, i, r: seen.append(i))
    assert out == [i * (i + 1) for i in range(7)] and sorted(seen) == list(range(7))
    stopped = run_tasks(operator.mul, TASKS, scheduler=client, stop=lambda i, r: r >= 6)
    assert stopped[:3] == [0, 2, 6] and stopped[3:] == [None] * 4
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


def test_synth_mechanism_restarts_in_processes_equal_one_process():
    from mechsyn.synthesis.general import load_case, synthesize_mechanism

    case = load_case(ROOT / "examples" / "synthesis" / "slider_crank_path_case.yaml")
    fast = {"maxiter": 15, "popsize": 5}  # generation budgets: no timing decides the result
    one = synthesize_mechanism(case, seed=2, restarts=2, time_limit=300, options=fast, n_polish=1)
    two = synthesize_mechanism(case, seed=2, restarts=2, time_limit=300, options=fast, n_polish=1,
                               workers=2)
    assert one.design == two.design and one.restart_errors == two.restart_errors
    assert one.restarts == two.restarts == 2
