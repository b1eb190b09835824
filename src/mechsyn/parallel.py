"""One way to run a long job's independent pieces: here, in local processes, or on Dask.

Every long job of mechsyn (``atlas``, ``capability`` maps, ``synth path``, ``synth
mechanism``, and for ``synth curve`` and the curve-database build) is cut into
independent *tasks* -- calls ``fn(*args)`` of a top-level (picklable) function -- and run
by :func:`run_tasks`:

* ``workers=1, scheduler=None``: in this process, one after the other;
* ``workers=N``: in N local worker processes (``concurrent.futures``; no Dask needed);
* ``scheduler="tcp://host:8786"`` (or a ``dask.distributed.Client``): on a Dask cluster
  (the optional extra ``mechsyn[dask]``; ``dask`` is imported only then).

The contract, the same on every back end:

* **Identical results.** The results come back in task order, whatever order the
  workers finish in; a task must depend only on its arguments (seeds travel in them),
  so the answer equals the single-process run.
* **Progress.** Each time a task finishes, wherever it ran, ``on_result(index, result)``
  (``index``: the task's position; a caller may use finished results at once) and then
  ``progress(state)`` (:class:`mechsyn.progress.Progress`: tasks ``done`` of ``total``,
  stage ``"tasks"``) are called in the calling process.
* **Deadline.** ``deadline`` (a ``time.time()`` value): tasks not started by then are not
  started (their result is ``None``); running tasks finish, so a task that can run long
  takes the deadline among its arguments and honours it itself.
* **Early stop.** ``stop(index, result)`` returning true (e.g. the target error is
  reached) means no task after ``index`` is started any more; the tasks before it all
  run. So ``results[:index + 1]`` are exactly the single-process ones (where the run
  ends at that task). A later task that had already started (with several workers it
  may even have finished first) runs to its end and its result is kept: finished work
  is worth keeping, and it is that task's true result, never a different value. Tasks
  not started are ``None``. A caller that needs the single-process answer bit for bit
  uses ``results[:index + 1]``.
* **Ctrl-C.** ``KeyboardInterrupt`` cancels what has not run (local processes are shut
  down, cluster futures cancelled) and is raised again.

Examples
--------
>>> from operator import mul
>>> run_tasks(mul, [(2, 3), (4, 5), (6, 7)])
[6, 20, 42]
>>> run_tasks(mul, [(2, 3), (4, 5), (6, 7)], stop=lambda i, r: r >= 20)
[6, 20, None]
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

from mechsyn.errors import MechsynInputError
from mechsyn.progress import ProgressCallback, report

ResultFn = Callable[[int, Any], None]
StopFn = Callable[[int, Any], bool]

__all__ = ["run_tasks", "dask_client", "check_parallel_options"]


def check_parallel_options(workers: int, scheduler: Any) -> None:
    """The CLI's check of ``--workers`` / ``--scheduler`` (one clear line on bad input)."""
    if workers < 1:
        raise MechsynInputError("must be at least 1", field="workers")
    if scheduler is not None and workers > 1:
        raise MechsynInputError("give workers or a scheduler, not both", field="workers",
                                hint="the cluster's own workers run the tasks with a scheduler")


def connect_timeout() -> float:
    """Seconds to wait for a Dask scheduler: ``MECHSYN_SCHEDULER_TIMEOUT``, default 10."""
    import os

    try:
        value = float(os.environ.get("MECHSYN_SCHEDULER_TIMEOUT", "10"))
    except ValueError:
        raise MechsynInputError("MECHSYN_SCHEDULER_TIMEOUT is not a number of seconds",
                                source="MECHSYN_SCHEDULER_TIMEOUT", hint="e.g. 10") from None
    return value if value > 0 else 10.0


def dask_client(scheduler: Any):
    """A ``dask.distributed.Client`` for ``scheduler`` (an address or a Client), and
    whether the caller owns it (must close it). Clear errors without Dask or cluster."""
    try:
        from dask.distributed import Client
    except ImportError:
        raise MechsynInputError("dask.distributed is not installed", field="scheduler",
                                hint="pip install 'mechsyn[dask]' or run without a scheduler") from None
    if isinstance(scheduler, Client):
        return scheduler, False
    try:
        return Client(scheduler, timeout=connect_timeout()), True
    except (OSError, TimeoutError, ValueError) as exc:
        raise MechsynInputError(f"cannot reach the Dask scheduler: {exc}", field="scheduler",
                                hint="give the address printed by dask-scheduler, "
                                     "e.g. tcp://127.0.0.1:8786") from None


def run_tasks(fn: Callable[..., Any], tasks: Sequence[tuple], *, workers: int = 1,
              scheduler: Any = None, progress: ProgressCallback | None = None,
              deadline: float | None = None, stop: StopFn | None = None,
              on_result: ResultFn | None = None) -> list[Any]:
    """Run ``fn(*args)`` for every ``args`` of ``tasks``; results in task order.

    See the module docstring for the back ends (``workers``, ``scheduler``) and the
    contract (identical results, ``on_result``, ``progress``, ``deadline``, ``stop``,
    Ctrl-C). Tasks that were not run (deadline, early stop) give ``None``.
    """
    tasks = list(tasks)
    results: list[Any] = [None] * len(tasks)
    if not tasks:
        return results
    book = _Book(len(tasks), progress, stop, on_result)
    if scheduler is not None:
        return _run_dask(fn, tasks, results, scheduler, book, deadline)
    if workers <= 1 or len(tasks) == 1:
        for i, args in enumerate(tasks):
            if deadline is not None and time.time() >= deadline and i > 0:
                break
            book.finished(i, fn(*args), results)
            if i + 1 >= book.limit:  # stopped early (or the last task)
                break
        return results
    return _run_pool(fn, tasks, results, workers, book, deadline)


class _Book:
    """Bookkeeping shared by the pool and Dask loops: which tasks still count."""

    def __init__(self, n: int, progress: ProgressCallback | None, stop: StopFn | None, on_result: ResultFn | None):
        self.n, self.progress, self.stop, self.on_result = n, progress, stop, on_result
        self.limit = n  # tasks at index >= limit are not started any more (early stop)
        self.done = 0

    def finished(self, i: int, result: Any, results: list[Any]) -> None:
        """Keep a finished task's result (whatever its index), report it, apply ``stop``."""
        results[i] = result
        self.done += 1
        if self.on_result is not None:
            self.on_result(i, result)
        report(self.progress, self.done, self.n, "tasks")
        if i < self.limit and self.stop is not None and self.stop(i, result):
            self.limit = i + 1


def _run_pool(fn, tasks, results, workers, book: _Book, deadline) -> list[Any]:
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

    pool = ProcessPoolExecutor(max_workers=workers)
    try:
        queue = list(range(len(tasks)))
        running: dict[Any, int] = {}
        # with a deadline or a stop: the pool just full, so later tasks stay unstarted;
        # otherwise a task more per worker waits queued, so that no worker waits while
        # this process takes in a result
        depth = workers if deadline is not None or book.stop is not None else 2 * workers
        while queue or running:
            while queue and len(running) < depth:
                i = queue.pop(0)
                if i >= book.limit or (deadline is not None and time.time() >= deadline
                                       and i > 0):
                    continue
                running[pool.submit(fn, *tasks[i])] = i
            if not running:
                break
            finished, _ = wait(list(running), return_when=FIRST_COMPLETED)
            for fut in sorted(finished, key=running.get):
                book.finished(running.pop(fut), fut.result(), results)
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return results


_SKIPPED = "mechsyn.parallel: not started before the deadline"


def _guarded(fn, deadline, first, *args):
    """Run ``fn(*args)`` unless the deadline has passed (the first task always runs)."""
    if deadline is not None and not first and time.time() >= deadline:
        return _SKIPPED
    return fn(*args)


def _run_dask(fn, tasks, results, scheduler, book: _Book, deadline) -> list[Any]:
    client, owned = dask_client(scheduler)
    from dask.distributed import as_completed

    futures: list[Any] = []
    try:
        futures = [client.submit(_guarded, fn, deadline, i == 0, *args, pure=False,
                                 priority=-i) for i, args in enumerate(tasks)]
        index = {f.key: i for i, f in enumerate(futures)}
        for fut in as_completed(futures):
            i = index[fut.key]
            if fut.cancelled():
                continue
            result = fut.result()
            if isinstance(result, str) and result == _SKIPPED:
                continue
            book.finished(i, result, results)
            if book.limit < len(tasks):
                client.cancel([f for f in futures[book.limit:] if not f.done()])
    except BaseException:
        if futures:
            client.cancel(futures)
        raise
    finally:
        if owned:
            client.close()
    return results
