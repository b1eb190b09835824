"""Long runs (synthesis) of mechsyn studio in background threads, with progress and cancel.

A :class:`Job` runs ``fn(params, progress)`` in a thread; ``progress`` stores the latest
state and raises :class:`~mechsyn.web._service.Cancelled` once cancel was asked, so the
run stops at its next report. The routes stream :meth:`Job.snapshot` as server-sent events.
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from typing import Any, Callable

from mechsyn.errors import MechsynInputError
from mechsyn.web._service import Cancelled, error_dict

log = logging.getLogger("mechsyn.web")
MAX_JOBS = 4


class Job:
    """One background run: ``state`` is running, done, failed or cancelled."""

    def __init__(self, ident: str, kind: str, fn: Callable[[dict, Callable[[dict], None]], dict], params: dict):
        self.id, self.kind = ident, kind
        self.state = "running"
        self.progress: dict[str, Any] = {"done": 0, "total": 1, "best": None}
        self.result: dict[str, Any] | None = None
        self.error: dict[str, Any] | None = None
        self.started = time.time()
        self.version = 0
        self._cancel = threading.Event()
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, args=(fn, params), daemon=True, name=f"mechsyn-job-{ident}")

    def start(self) -> "Job":
        self._thread.start()
        return self

    def cancel(self) -> None:
        self._cancel.set()

    def _report(self, state: dict) -> None:
        if self._cancel.is_set():
            raise Cancelled()
        with self._lock:
            self.progress = dict(state)
            self.version += 1

    def _finish(self, state: str, result: dict | None = None, error: dict | None = None) -> None:
        with self._lock:
            self.state, self.result, self.error = state, result, error
            self.version += 1

    def _run(self, fn, params) -> None:
        try:
            result = fn(params, self._report)
        except Cancelled:
            self._finish("cancelled")
        except MechsynInputError as err:
            self._finish("failed", error=error_dict(err))
        except Exception:  # a bug: logged for the terminal, a plain message for the page
            log.exception("synthesis job %s failed", self.id)
            self._finish("failed", error={"message": "internal error in the synthesis run (see the server log)"})
        else:
            self._finish("cancelled" if self._cancel.is_set() else "done", result=result)

    def snapshot(self) -> dict[str, Any]:
        with self._lock:
            out = {"id": self.id, "kind": self.kind, "state": self.state, "progress": dict(self.progress),
                   "seconds": round(time.time() - self.started, 2)}
            if self.result is not None:
                out["result"] = self.result
            if self.error is not None:
                out["error"] = self.error
            return out


class JobTable:
    """The jobs of one server (at most :data:`MAX_JOBS` running at once)."""

    def __init__(self) -> None:
        self._jobs: dict[str, Job] = {}
        self._ids = itertools.count(1)
        self._lock = threading.Lock()

    def submit(self, kind: str, fn, params: dict) -> Job:
        with self._lock:
            running = sum(j.state == "running" for j in self._jobs.values())
            if running >= MAX_JOBS:
                raise MechsynInputError(f"{running} synthesis runs are going on already", field="kind",
                                        hint="cancel one or wait for it to finish")
            job = Job(str(next(self._ids)), kind, fn, params)
            self._jobs[job.id] = job
        return job.start()

    def get(self, ident: str) -> Job:
        try:
            return self._jobs[ident]
        except KeyError:
            raise MechsynInputError(f"no job {ident!r}", field="job") from None

    def cancel_all(self) -> None:
        for j in self._jobs.values():
            j.cancel()
