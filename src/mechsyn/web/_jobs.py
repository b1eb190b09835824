"""Work of mechsyn studio that takes time: synthesis jobs and the heavy routes.

A :class:`Job` runs ``fn(params, progress)`` in a thread; ``progress`` stores the latest
state and raises :class:`~mechsyn.web._service.Cancelled` once cancel was asked, so the
run stops at its next report. The routes stream :meth:`Job.snapshot` as server-sent events.

:class:`HeavyRunner` runs one call of :mod:`mechsyn.web._service` (analyze, simulate,
import, export, atlas) in a worker process forked from a preloaded fork server, like a
Jupyter kernel: at most ``per_client`` at once per client and ``total`` at once in all,
killed when its client disconnects, and a crash of native code inside it (bliss, BLAS)
is a 500 for that request, not the end of the server. A request over its client's queue
is answered at once with 429.
"""

from __future__ import annotations

import asyncio
import itertools
import logging
import multiprocessing
import os
import signal
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
        self.started = time.monotonic()
        self.ended: float | None = None
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
            self.ended = time.monotonic()  # a finished job's seconds stay as they were
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
                   "seconds": round((self.ended or time.monotonic()) - self.started, 2)}
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


# --------------------------------------------------------------------------- heavy routes
#: Modules the fork server imports once, so that each worker starts in milliseconds.
PRELOAD = ["mechsyn.web._service", "mechsyn.io", "mechsyn.kinematics.analysis", "mechsyn.structure.report",
           "mechsyn.structure.assur", "mechsyn.synthesis.chains", "mechsyn.synthesis.mechanisms"]


class Busy(Exception):
    """A client asked for more heavy work at once than it may (answered 429)."""


class ClientGone(Exception):
    """The client disconnected: its work was stopped (nobody reads the answer)."""


class WorkerCrashed(Exception):
    """The worker process ended without an answer (killed, or native code aborted)."""


#: The web modules whose functions heavy calls may name as ``"module:function"``.
SERVICE_MODULES = ("_service", "_studio", "_spatial", "_design")


def service_function(name: str) -> Callable[..., Any]:
    """The function a heavy call names: ``"simulate"`` is ``_service.simulate``,
    ``"_studio:forces"`` is :func:`mechsyn.web._studio.forces` (only the modules of
    :data:`SERVICE_MODULES`)."""
    import importlib

    module, _, function = name.rpartition(":")
    if (module or "_service") not in SERVICE_MODULES:
        raise ValueError(f"no heavy service {name!r}")
    return getattr(importlib.import_module(f"mechsyn.web.{module or '_service'}"), function)


def _worker(conn, name: str, args: tuple) -> None:
    """Worker process: ``_service.<name>(*args)`` sent back as ("ok", result),
    ("input", error fields) or ("bug", traceback text)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the server's to handle
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(os, "nice"):
        os.nice(10)  # the server's own process (answering other clients) goes first for the CPU
    try:
        out = ("ok", service_function(name)(*args))
    except MechsynInputError as err:
        out = ("input", {"message": err.message, "field": err.field, "hint": err.hint,
                         "source": err.source, "line": err.line, "element": getattr(err, "element", None)})
    except BaseException:  # noqa: BLE001  a bug: its trace goes to the server's log
        import traceback

        out = ("bug", traceback.format_exc())
    try:
        conn.send(out)
    except (BrokenPipeError, OSError):
        pass  # the server stopped waiting (client gone)
    finally:
        conn.close()


def _context():
    """The fork server (POSIX), else spawn: a clean process that inherits no server thread."""
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    if ctx.get_start_method() == "forkserver":
        ctx.set_forkserver_preload(PRELOAD)
    return ctx


class HeavyRunner:
    """Heavy calls of :mod:`mechsyn.web._service` in worker processes, capped and cancellable.

    Parameters
    ----------
    total
        Workers running at once in all (default: the machine's CPUs, at least 2).
    per_client
        Workers running at once for one client; its further requests wait.
    queue
        Requests of one client waiting or running; one more is answered 429 at once.
    isolate
        False runs the calls in threads of this process instead (no kill on disconnect:
        for tests that patch :mod:`mechsyn.web._service`).
    """

    def __init__(self, total: int | None = None, per_client: int = 1, queue: int = 4, isolate: bool = True):
        self.total = total or max(2, os.cpu_count() or 2)
        self.per_client, self.queue, self.isolate = per_client, queue, isolate
        self.running: dict[str, int] = {}
        self.waiting: dict[str, int] = {}
        self.started = 0  # workers started since launch
        self.procs: set = set()  # the worker processes running now
        self._lock = threading.Lock()
        self._ctx = _context() if isolate else None

    def warm(self) -> None:
        """Start the fork server now (it imports mechsyn once, about a second)."""
        if self._ctx is not None and self._ctx.get_start_method() == "forkserver":
            from multiprocessing import forkserver

            forkserver.ensure_running()

    def _take(self, client: str) -> bool:
        with self._lock:
            if self.running.get(client, 0) >= self.per_client or sum(self.running.values()) >= self.total:
                return False
            self.running[client] = self.running.get(client, 0) + 1
            return True

    def stop(self) -> None:
        """Stop the fork server now (SIGKILL: it holds no state, and its own exit, with the
        preloaded modules, took seconds on a loaded machine while it kept the terminal's
        pipes open). The next :meth:`warm` or call starts a new one."""
        if self._ctx is None or self._ctx.get_start_method() != "forkserver":
            return
        from multiprocessing import forkserver

        pid = getattr(forkserver._forkserver, "_forkserver_pid", None)  # CPython's private state
        if pid:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass

    async def call(self, client: str, gone: Callable[[], Any], name: str, *args: Any) -> Any:
        """``_service.<name>(*args)`` for ``client``; ``gone()`` (awaitable) tells a disconnect."""
        with self._lock:
            if self.waiting.get(client, 0) + self.running.get(client, 0) >= self.queue:
                raise Busy(f"{self.queue} computations of this client are waiting or running already")
            self.waiting[client] = self.waiting.get(client, 0) + 1
        try:
            while not self._take(client):  # a free slot is polled: no event-loop-bound primitive
                if await gone():
                    raise ClientGone(name)
                await asyncio.sleep(0.05)
        finally:
            with self._lock:
                self.waiting[client] -= 1
        try:
            return await (self._in_process(gone, name, args) if self.isolate else self._in_thread(name, args))
        finally:
            with self._lock:
                self.running[client] -= 1

    async def _in_thread(self, name: str, args: tuple) -> Any:
        from starlette.concurrency import run_in_threadpool

        return await run_in_threadpool(service_function(name), *args)

    async def _in_process(self, gone: Callable[[], Any], name: str, args: tuple) -> Any:
        loop = asyncio.get_running_loop()
        parent, child = self._ctx.Pipe(duplex=False)
        proc = self._ctx.Process(target=_worker, args=(child, name, args), daemon=True, name=f"mechsyn-{name}")
        await loop.run_in_executor(None, proc.start)
        self.started += 1
        self.procs.add(proc)
        child.close()
        ready = asyncio.Event()
        loop.add_reader(parent.fileno(), ready.set)
        try:
            while not ready.is_set():
                if await gone():
                    raise ClientGone(name)
                try:
                    await asyncio.wait_for(ready.wait(), 0.1)
                except asyncio.TimeoutError:
                    pass
            try:
                kind, payload = await loop.run_in_executor(None, parent.recv)
            except (EOFError, OSError):
                raise WorkerCrashed(f"the {name} worker ended without an answer "
                                    f"(exit code {proc.exitcode})") from None
        finally:
            loop.remove_reader(parent.fileno())
            parent.close()
            if proc.is_alive():
                proc.kill()
            await loop.run_in_executor(None, proc.join, 5)
            self.procs.discard(proc)
        return _unpack(kind, payload, name)


def _unpack(kind: str, payload: Any, name: str) -> Any:
    if kind == "ok":
        return payload
    if kind == "input":
        err = MechsynInputError(payload["message"], field=payload["field"], hint=payload["hint"],
                                source=payload["source"], line=payload["line"])
        err.element = payload["element"]  # type: ignore[attr-defined]
        raise err
    log.error("%s failed in its worker:\n%s", name, payload)
    raise WorkerCrashed(f"{name} failed (the server's log has the details)")
