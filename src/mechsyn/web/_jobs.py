"""Work of mechsyn studio that takes time: synthesis jobs and the heavy routes.

:class:`HeavyRunner` runs one call of :mod:`mechsyn.web._service` (analyze, simulate,
the structure check, import, export, atlas) or one synthesis run in a worker process forked
from a preloaded fork server, like a Jupyter kernel: nothing heavy runs in the server's own
process (issue 42). Its caps:

* ``total`` workers at once for heavy requests and synthesis jobs, of which jobs take at
  most ``job_slots`` (a heavy request finds a worker after one request finishes);
* ``quick_slots`` more workers for the quick services (:data:`QUICK`: the structure check,
  validate, reading and writing a file's text), which also take a free worker of the
  others: a check never waits behind a 360-frame GIF, only behind other quick calls;
* ``per_client`` at once per client, a client being the connection (address and port,
  its jobs apart), never a header the client chooses;
* a fair queue: when a worker frees, the waiting client served least recently goes first
  (a cheap request waits for one worker to finish, not behind every request of others);
* ``queue`` calls of one client waiting or running; one more is answered 429 at once;
* a time limit per worker (:data:`REQUEST_SECONDS`, :data:`JOB_SECONDS`): killed beyond;
* killed when its client disconnects or the server stops; a crash of native code inside it
  (bliss, BLAS) is a 500 for that request, not the end of the server.

A :class:`Job` is one synthesis run ``fn(params, progress)`` in such a worker; the worker
sends its progress (a :class:`mechsyn.progress.Progress`, at most every
:data:`PROGRESS_EVERY` s) and the server keeps the latest state's ``to_dict()``, which the
routes stream as server-sent events (:meth:`Job.snapshot`). Cancel kills
its worker.
"""

from __future__ import annotations

import asyncio
import itertools
import json
import logging
import multiprocessing
import os
import signal
import threading
import time
from typing import Any, Callable

from mechsyn.errors import MechsynInputError
from mechsyn.progress import Progress, ProgressCallback
from mechsyn.web._service import Cancelled, error_dict

log = logging.getLogger("mechsyn.web")
MAX_JOBS = 4
#: Seconds one heavy request's worker may run; killed beyond (503).
REQUEST_SECONDS = 120.0
#: Seconds one quick service's worker may run; killed beyond (503).
QUICK_SECONDS = 60.0
#: The services of the quick lane: milliseconds for a drawn mechanism, bounded by the body's size.
QUICK = frozenset({"_studio:check", "validate", "read_mechanism", "parse_mechanism_text", "mechanism_text",
                   "atlas_mechanism"})
#: Seconds one synthesis job's worker may run (its own time limit is at most 600 s, and
#: the curve database may be built first); killed beyond (the job fails).
JOB_SECONDS = 1200.0
#: Seconds between two progress messages of a job's worker.
PROGRESS_EVERY = 0.1


class Job:
    """One synthesis run: ``state`` is running, done, failed or cancelled (:meth:`run`)."""

    def __init__(self, ident: str, kind: str, fn: Callable[[dict, ProgressCallback], dict], params: dict):
        self.id, self.kind, self.fn, self.params = ident, kind, fn, params
        self.state = "running"
        self.progress: dict[str, Any] = Progress().to_dict()  # the latest state, as the events send it
        self.result: dict[str, Any] | None = None
        self.error: dict[str, Any] | None = None
        self.started = time.monotonic()
        self.ended: float | None = None
        self.version = 0
        self.thread: threading.Thread | None = None  # waits for the worker (JobTable.submit)
        self._cancel = threading.Event()
        self._lock = threading.Lock()

    def cancel(self) -> None:
        self._cancel.set()

    def _report(self, state: Progress) -> None:
        """The run's progress (:class:`mechsyn.progress.Progress`, kept as its ``to_dict()``);
        raises :class:`Cancelled` once cancel was asked (its worker is then killed, or a run
        in a thread stops at this report)."""
        if self._cancel.is_set():
            raise Cancelled()
        with self._lock:
            self.progress = state.to_dict()
            self.version += 1

    def _finish(self, state: str, result: dict | None = None, error: dict | None = None) -> None:
        with self._lock:
            self.state, self.result, self.error = state, result, error
            self.ended = time.monotonic()  # a finished job's seconds stay as they were
            self.version += 1

    async def run(self, runner: "HeavyRunner", client: str) -> None:
        """``fn(params, progress)`` in a worker of ``runner`` (lane ``job``, at most
        :data:`JOB_SECONDS`), the outcome kept as the job's state."""

        async def cancelled() -> bool:
            return self._cancel.is_set()

        try:
            result = await runner.call(client, cancelled, self.fn, self.params, lane="job", limit=JOB_SECONDS,
                                       progress=self._report)
        except (Cancelled, ClientGone, ServerStopping):
            self._finish("cancelled")
        except MechsynInputError as err:
            self._finish("failed", error=error_dict(err))
        except (Busy, TooLong) as exc:
            self._finish("failed", error={"message": str(exc), "field": None, "hint": None, "element": None})
        except WorkerCrashed as exc:  # its trace, if any, is logged already
            log.warning("synthesis job %s: %s", self.id, exc)
            self._finish("failed", error={"message": "internal error in the synthesis run (see the server log)"})
        except Exception:  # a bug: logged for the terminal, a plain message for the page
            if runner.stopping:  # the server stopped under it: nothing to report
                self._finish("cancelled")
                return
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
    """The jobs of one server (at most :data:`MAX_JOBS` running or waiting at once)."""

    def __init__(self) -> None:
        self._jobs: dict[str, Job] = {}
        self._ids = itertools.count(1)
        self._lock = threading.Lock()

    def submit(self, kind: str, fn, params: dict, runner: "HeavyRunner", client: str) -> Job:
        """A job of ``fn(params, progress)`` started on ``runner`` for ``client`` (a
        connection; its jobs are capped apart from its requests)."""
        with self._lock:
            running = sum(j.state == "running" for j in self._jobs.values())
            if running >= MAX_JOBS:
                raise MechsynInputError(f"{running} synthesis runs are going on already", field="kind",
                                        hint="cancel one or wait for it to finish")
            job = Job(str(next(self._ids)), kind, fn, params)
            self._jobs[job.id] = job
        # its own thread and event loop: a job outlives the request (and, in the notebook
        # widget, the request's event loop) that started it; the thread only waits on a pipe
        job.thread = threading.Thread(target=asyncio.run, args=(job.run(runner, f"job {client}"),), daemon=True,
                                      name=f"mechsyn-job-{job.id}")
        job.thread.start()
        return job

    def get(self, ident: str) -> Job:
        try:
            return self._jobs[ident]
        except KeyError:
            raise MechsynInputError(f"no job {ident!r}", field="job") from None

    def cancel_all(self) -> None:
        for j in self._jobs.values():
            j.cancel()


# --------------------------------------------------------------------------- heavy routes
#: Modules the fork server imports once, so that each worker starts in milliseconds (a
#: synthesis worker at nice 10 on a loaded machine took tens of seconds to import SciPy's
#: optimisers and the curve database).
PRELOAD = ["mechsyn.web._service", "mechsyn.web._studio", "mechsyn.web._spatial", "mechsyn.io",
           "mechsyn.kinematics.analysis", "mechsyn.structure.report", "mechsyn.structure.assur",
           "mechsyn.synthesis.chains", "mechsyn.synthesis.mechanisms", "mechsyn.synthesis.optimize",
           "mechsyn.synthesis.path", "mechsyn.synthesis.export", "mechsyn.synthesis.curves.database",
           "mechsyn.synthesis.curves.synthesis", "mechsyn.web._warm"]


class Busy(Exception):
    """A client asked for more heavy work at once than it may (answered 429)."""


class ClientGone(Exception):
    """The client disconnected: its work was stopped (nobody reads the answer)."""


class WorkerCrashed(Exception):
    """The worker process ended without an answer (killed, or native code aborted)."""


class TooLong(Exception):
    """A worker ran past its time limit and was killed (answered 503)."""


class ServerStopping(Exception):
    """The server is stopping: work waiting or running was stopped (answered 503)."""


#: The web modules whose functions heavy calls may name as ``"module:function"``.
SERVICE_MODULES = ("_service", "_studio", "_spatial", "_design")


def service_function(name: str | Callable[..., Any]) -> Callable[..., Any]:
    """The function a heavy call names: ``"simulate"`` is ``_service.simulate``,
    ``"_studio:forces"`` is :func:`mechsyn.web._studio.forces` (only the modules of
    :data:`SERVICE_MODULES`); a function (a synthesis kind's) is itself."""
    import importlib

    if callable(name):
        return name
    module, _, function = name.rpartition(":")
    if (module or "_service") not in SERVICE_MODULES:
        raise ValueError(f"no heavy service {name!r}")
    return getattr(importlib.import_module(f"mechsyn.web.{module or '_service'}"), function)


class RawJSON:
    """A request's answer encoded as JSON (UTF-8) by its worker: the server sends the bytes
    as they are, with no unpickling of a large structure and no encoding in its own process.

    >>> RawJSON.of({"a": [1.5, None], "b": "é"}).data
    b'{"a":[1.5,null],"b":"\xc3\xa9"}'
    """

    __slots__ = ("data",)

    def __init__(self, data: bytes) -> None:
        self.data = data

    @classmethod
    def of(cls, obj: Any) -> "RawJSON":
        try:
            return cls(json.dumps(obj, ensure_ascii=False, allow_nan=False, separators=(",", ":")).encode())
        except UnicodeEncodeError:  # a lone surrogate echoed back: escaped as \uXXXX
            return cls(json.dumps(obj, ensure_ascii=True, allow_nan=False, separators=(",", ":")).encode())


def _label(name: str | Callable[..., Any]) -> str:
    return name if isinstance(name, str) else getattr(name, "__name__", "job")


#: The niceness of a worker by lane: the server's own process (answering other clients)
#: goes first for the CPU; a quick call and a job less far behind than a heavy request (at
#: nice 10 on a machine busy with other programs, a worker got a fraction of a percent of a
#: core: a 2 s search took minutes, a four-bar's check 0.3 s instead of 0.08 s).
NICE = {"quick": 5, "job": 5, "request": 10}


def _worker(conn, name: str | Callable[..., Any], args: tuple, with_progress: bool, nice: int = 10) -> None:
    """Worker process: ``_service.<name>(*args)`` (and a progress callback when asked) sent
    back as ("ok", result), ("input", error fields) or ("bug", traceback text), after any
    number of ("progress", state); a request's dict or list result as :class:`RawJSON`."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the server's to handle
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(os, "nice"):
        os.nice(nice)  # :data:`NICE`
    last = [0.0]

    def progress(state: Progress) -> None:
        now = time.monotonic()
        if now - last[0] >= PROGRESS_EVERY:
            last[0] = now
            conn.send(("progress", state))

    try:
        out = ("ok", service_function(name)(*args, *((progress,) if with_progress else ())))
        if not with_progress and isinstance(out[1], (dict, list)):  # a request's JSON answer
            out = ("ok", RawJSON.of(out[1]))
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


class _Ticket:
    """A call waiting for a worker; :meth:`grant` wakes it on its own event loop."""

    def __init__(self, client: str, lane: str, seq: int) -> None:
        self.client, self.lane, self.seq, self.granted = client, lane, seq, False
        self.pool = ""  # the workers it was granted from: "quick" or "general"
        self._loop, self._event = asyncio.get_running_loop(), asyncio.Event()

    def grant(self) -> None:
        self.granted = True
        self._loop.call_soon_threadsafe(self._event.set)

    async def wait(self, seconds: float) -> None:
        try:
            await asyncio.wait_for(self._event.wait(), seconds)
        except asyncio.TimeoutError:
            pass
class HeavyRunner:
    """Heavy calls of :mod:`mechsyn.web._service` and synthesis runs in worker processes,
    capped, queued fairly, time-limited and cancellable (see the module's notes).

    Parameters
    ----------
    total
        Workers running at once for heavy requests and jobs (default: the machine's CPUs, at
        least 2).
    per_client
        Workers running at once for one client; its further calls wait.
    queue
        Calls of one client waiting or running; one more is answered 429 at once.
    isolate
        False runs the calls in threads of this process instead (no kill on disconnect, no
        time limit: for tests that patch :mod:`mechsyn.web._service`).
    job_slots
        Workers synthesis jobs may hold at once (default: all but one).
    quick_slots
        Workers kept for the quick services (:data:`QUICK`) besides ``total``.

    Examples
    --------
    >>> import asyncio
    >>> runner = HeavyRunner(isolate=False)
    >>> async def never():
    ...     return False
    >>> asyncio.run(runner.call("127.0.0.1:5000", never, "atlas", 4, 1))[0]["label"]
    '4B, four-bar chain'
    """

    def __init__(self, total: int | None = None, per_client: int = 1, queue: int = 4, isolate: bool = True,
                 job_slots: int | None = None, quick_slots: int = 1):
        self.total = total or max(2, os.cpu_count() or 2)
        self.per_client, self.queue, self.isolate = per_client, queue, isolate
        self.job_slots = job_slots or max(1, self.total - 1)
        self.quick_slots = quick_slots
        self.running: dict[str, int] = {}  # workers running now, by client
        self.waiting: dict[str, int] = {}  # calls waiting for a worker, by client
        self.lanes = {"quick": 0, "request": 0, "job": 0}  # workers running now, by lane
        self.pools = {"quick": 0, "general": 0}  # workers running now, by the slots they hold
        self.started = 0  # workers started since launch
        self.procs: set = set()  # the worker processes running now
        self.stopping = False
        self._tickets: list[_Ticket] = []
        self._served: dict[str, int] = {}  # when each client last got a worker (a counter)
        self._seq = itertools.count()
        self._lock = threading.Lock()
        self._ctx = _context() if isolate else None

    def warm(self) -> None:
        """Start the fork server now (it imports mechsyn once, about a second)."""
        if self._ctx is not None and self._ctx.get_start_method() == "forkserver":
            from multiprocessing import forkserver

            forkserver.ensure_running()

    def stop(self) -> None:
        """Stop the fork server now (SIGKILL: it holds no state, and its own exit, with the
        preloaded modules, took seconds on a loaded machine while it kept the terminal's
        pipes open). The next :meth:`warm` or call starts a new one."""
        if self._ctx is None or self._ctx.get_start_method() != "forkserver":
            return
        from multiprocessing import forkserver

        server = forkserver._forkserver  # CPython's private state
        with server._lock:
            pid = getattr(server, "_forkserver_pid", None)
            if not pid:
                return
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            if hasattr(server, "_stop_unlocked"):  # reaped and forgotten: the next call starts a new one
                server._stop_unlocked()  # (killed but remembered, it was believed alive: "unexpected EOF")

    def stop_all(self) -> None:
        """The server stops: every worker killed now, waiting calls end (:class:`ServerStopping`),
        so that each request answers within the server's second of grace."""
        self.stopping = True
        for proc in list(self.procs):
            try:
                proc.kill()
            except (OSError, ValueError, AttributeError):  # ended already
                pass

    # ------------------------------------------------------------------ the fair queue
    def _room(self, t: _Ticket) -> str:
        """The slots a waiting call may take now ("quick", "general"), or "" (under the lock)."""
        if self.running.get(t.client, 0) >= self.per_client:
            return ""
        if t.lane == "quick" and self.pools["quick"] < self.quick_slots:
            return "quick"
        if t.lane == "job" and self.lanes["job"] >= self.job_slots:
            return ""
        return "general" if self.pools["general"] < self.total else ""

    def _dispatch(self) -> None:
        """Free workers to waiting calls (under the lock): among the calls that have room,
        the client served least recently first, then the oldest call."""
        while self._tickets:
            ready = [(t, pool) for t in self._tickets if (pool := self._room(t))]
            if not ready:
                return
            t, pool = min(ready, key=lambda tp: (self._served.get(tp[0].client, -1), tp[0].seq))
            self._tickets.remove(t)
            self.waiting[t.client] -= 1
            self.running[t.client] = self.running.get(t.client, 0) + 1
            self.lanes[t.lane] += 1
            self.pools[pool] += 1
            t.pool = pool
            self._served[t.client] = next(self._seq)
            t.grant()

    def _release(self, ticket: _Ticket) -> None:
        with self._lock:
            if ticket.granted:
                self.running[ticket.client] -= 1
                self.lanes[ticket.lane] -= 1
                self.pools[ticket.pool] -= 1
                if not self.running[ticket.client]:
                    del self.running[ticket.client]
            elif ticket in self._tickets:
                self._tickets.remove(ticket)
                self.waiting[ticket.client] -= 1
            if not self.waiting.get(ticket.client, 1):
                del self.waiting[ticket.client]
            self._dispatch()

    async def call(self, client: str, gone: Callable[[], Any], name: str | Callable[..., Any], *args: Any,
                   lane: str | None = None, limit: float | None = None,
                   progress: ProgressCallback | None = None) -> Any:
        """``_service.<name>(*args)`` for ``client`` (``name(*args, progress)`` when
        ``progress`` is given); ``gone()`` (awaitable) tells a disconnect or a cancel.
        ``lane`` is "quick" for the services of :data:`QUICK`, else "request" (or "job");
        ``limit`` the seconds its worker may run (:data:`QUICK_SECONDS`, :data:`REQUEST_SECONDS`)."""
        lane = lane or ("quick" if name in QUICK else "request")
        limit = limit or (QUICK_SECONDS if lane == "quick" else REQUEST_SECONDS)
        if self.stopping:
            raise ServerStopping("the server is stopping")
        with self._lock:
            if self.waiting.get(client, 0) + self.running.get(client, 0) >= self.queue:
                raise Busy(f"{self.queue} computations of this client are waiting or running already")
            ticket = _Ticket(client, lane, next(self._seq))
            self._tickets.append(ticket)
            self.waiting[client] = self.waiting.get(client, 0) + 1
            self._dispatch()
        try:
            while not ticket.granted:
                if self.stopping:
                    raise ServerStopping("the server is stopping")
                if await gone():
                    raise ClientGone(_label(name))
                await ticket.wait(0.25)
            if not self.isolate:
                return await self._in_thread(name, args, progress)
            return await self._in_process(gone, name, args, limit, progress, lane)
        finally:
            self._release(ticket)

    async def _in_thread(self, name, args: tuple, progress: ProgressCallback | None) -> Any:
        from starlette.concurrency import run_in_threadpool

        return await run_in_threadpool(service_function(name), *args, *((progress,) if progress else ()))

    # ------------------------------------------------------------------ one worker
    async def _in_process(self, gone: Callable[[], Any], name, args: tuple, limit: float | None,
                          progress: ProgressCallback | None, lane: str = "request") -> Any:
        loop = asyncio.get_running_loop()
        parent, child = self._ctx.Pipe(duplex=False)
        proc = self._ctx.Process(target=_worker, args=(child, name, args, progress is not None, NICE[lane]),
                                 daemon=True, name=f"mechsyn-{_label(name)}")
        try:
            await loop.run_in_executor(None, proc.start)
        except (EOFError, OSError) as exc:  # the fork server was stopped (the server stops) or died
            if self.stopping:
                raise ServerStopping("the server is stopping") from None
            raise WorkerCrashed(f"the {_label(name)} worker did not start ({exc})") from None
        self.started += 1
        self.procs.add(proc)
        child.close()
        deadline = None if limit is None else loop.time() + limit
        try:
            while True:
                kind, payload = await self._next_message(loop, parent, proc, gone, name, deadline, limit)
                if kind != "progress":
                    break
                progress(payload)
        finally:
            parent.close()
            if proc.is_alive():
                proc.kill()
            await loop.run_in_executor(None, proc.join, 5)
            self.procs.discard(proc)
        return _unpack(kind, payload, _label(name))

    async def _next_message(self, loop, parent, proc, gone, name, deadline: float | None,
                            limit: float | None) -> tuple[str, Any]:
        """The worker's next message, watching its client, the server and the clock."""
        ready = asyncio.Event()
        loop.add_reader(parent.fileno(), ready.set)
        try:
            while not ready.is_set():
                if self.stopping:
                    raise ServerStopping("the server is stopping")
                if await gone():
                    raise ClientGone(_label(name))
                if deadline is not None and loop.time() > deadline:
                    raise TooLong(f"{_label(name)} was stopped after {limit:.0f} s (the studio's limit for one "
                                  "computation)")
                try:
                    await asyncio.wait_for(ready.wait(), 0.1)
                except asyncio.TimeoutError:
                    pass
        finally:
            loop.remove_reader(parent.fileno())
        try:
            return await loop.run_in_executor(None, parent.recv)
        except (EOFError, OSError):
            if self.stopping:
                raise ServerStopping("the server is stopping") from None
            raise WorkerCrashed(f"the {_label(name)} worker ended without an answer "
                                f"(exit code {proc.exitcode})") from None


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
