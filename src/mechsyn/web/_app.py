"""The mechsyn studio application: :func:`create_app` and :func:`run_server`.

The app is thin: every route parses its JSON, makes one call into
:mod:`mechsyn.web._service` (the only module that calls the library) and returns JSON.

Safety of a local server (issue 15):

* bound to 127.0.0.1 unless a host is given explicitly (:func:`run_server`);
* the Host header must name this server (``allowed_hosts``), against DNS rebinding;
* every ``/api/`` request carries the per-launch token (``X-Mechsyn-Token`` header, or
  ``token`` query parameter for event streams and downloads);
* files only inside the start directory (:mod:`mechsyn.web._files`);
* request bodies limited to :data:`MAX_BODY` bytes;
* a Content-Security-Policy allowing only the server's own scripts, styles and data;
* malformed requests answer 4xx with a JSON ``{"error", "field", "hint"}``; a bug answers
  500 ``internal server error`` and the trace goes to the server's log only;
* request bodies parsed strictly before any work (:func:`mechsyn.web._routing._body`: no
  NaN/Infinity, no key twice, no number of thousands of digits, no lone surrogate, nesting
  within the limit), then validated by one schema per body (:mod:`mechsyn.web._schema`:
  JSON types as they are, numbers within ±1e12, printable file names);
* heavy work (the structure check, analyze, simulate, import, export, atlas, reading a
  file, synthesis jobs) runs in worker processes, capped per connection and in all, queued
  fairly, time-limited, killed when the client disconnects or the server stops
  (:class:`mechsyn.web._jobs.HeavyRunner`, issues 27 and 42).

References
----------
The layout follows optuna-dashboard (``_app.py create_app``, ``_serializer.py``,
``json_api_view``), https://github.com/optuna/optuna-dashboard.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import secrets
import threading
from pathlib import Path
from typing import Any, Awaitable, Callable, Iterable

from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.exceptions import HTTPException
from starlette.requests import ClientDisconnect, Request
from starlette.responses import FileResponse, Response, StreamingResponse
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from mechsyn.errors import MechsynInputError
from mechsyn.results import write_atomic
from mechsyn.web import _design, _files, _service, _spatial, _studio  # _spatial: the 3-D view (view3d)
from mechsyn.web._jobs import HeavyRunner, JobTable
from mechsyn.web import _schema as S
from mechsyn.web._routing import _client, _heavy, _json_error, _parsed, api

log = logging.getLogger("mechsyn.web")
STATIC = Path(__file__).parent / "static"
MAX_BODY = 2 * 1024 * 1024
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")
CSP = ("default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data: blob:; "
       "connect-src 'self'; font-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'")
TOKEN_HEADER = "x-mechsyn-token"
#: Seconds the server waits for each part of a request body.
BODY_TIMEOUT = 30
#: Requests (past the Host and token checks) answered at once; 503 beyond.
MAX_REQUESTS = 200


# --------------------------------------------------------------------------- middleware


def _hostname(host: str) -> str:
    host = host.strip().lower()
    if host.startswith("["):  # [::1]:8000
        return host[1:host.find("]")] if "]" in host else host
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


class Guard:
    """ASGI middleware: Host check, token on /api/, body size limit, security headers, at
    most :data:`MAX_REQUESTS` requests running at once (503 beyond).

    A request refused (Host, token, size) is answered at once and its connection closed:
    it never counts against a limit; idle sockets count for nothing here.
    """

    def __init__(self, app: Callable, token: str, allowed_hosts: Iterable[str], max_body: int = MAX_BODY):
        self.app, self.token, self.max_body = app, token, max_body
        self.hosts = {h.lower().strip("[]") for h in allowed_hosts}
        self.running = 0  # requests (Host and token checked) being answered now

    async def __call__(self, scope: dict, receive: Callable, send: Callable) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope.get("headers", [])}
        problem = self._check(scope, headers)
        if problem is not None:  # refused before it counts: the connection closed after the answer
            problem.headers["connection"] = "close"
            await _with_headers(problem, scope)(scope, receive, send)
            return
        if self.running >= MAX_REQUESTS:
            await _with_headers(_json_error(503, f"{self.running} requests are running already",
                                            hint="try again in a moment"), scope)(scope, receive, send)
            return
        self.running += 1  # one event loop: no lock needed
        try:
            await self.app(scope, self._limited(receive), _secure_send(send, scope))
        finally:
            self.running -= 1

    def _check(self, scope: dict, headers: dict[str, str]) -> Response | None:
        host = _hostname(headers.get("host", ""))
        server = (scope.get("server") or ("",))[0] or ""
        # the address the connection came in on is this server's own (--host 0.0.0.0 reached
        # at 192.168.1.5); a name is accepted only when listed (DNS rebinding uses names)
        if host not in self.hosts and not (host and host == server.lower().strip("[]")):
            return _json_error(403, "this server answers only to its own address (Host header refused)",
                               hint="open the URL that `mechsyn serve` printed")
        if scope["path"].startswith("/api/"):
            from urllib.parse import parse_qs

            given = headers.get(TOKEN_HEADER) or parse_qs(scope.get("query_string", b"").decode()).get("token", [""])[0]
            if not secrets.compare_digest(given.encode(), self.token.encode()):
                return _json_error(403, "missing or wrong token", field="token",
                                   hint="open the URL with ?token=... that `mechsyn serve` printed")
        try:
            length = int(headers.get("content-length", "0") or 0)
        except ValueError:
            return _json_error(400, "bad Content-Length header")
        if length > self.max_body:
            return _json_error(413, f"request body over {self.max_body // 1024} KiB", hint="send a smaller file")
        return None

    def _limited(self, receive: Callable) -> Callable:
        seen, complete = 0, False

        async def wrapped() -> dict:
            nonlocal seen, complete
            if complete:  # waiting for a disconnect (event streams): no deadline
                return await receive()
            try:  # the body within BODY_TIMEOUT s of each part (a trickling client is dropped)
                message = await asyncio.wait_for(receive(), BODY_TIMEOUT)
            except asyncio.TimeoutError:
                raise ClientDisconnect() from None
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                complete = not message.get("more_body", False)
                if seen > self.max_body:
                    raise HTTPException(413, f"request body over {self.max_body // 1024} KiB")
            return message

        return wrapped


def _security_headers(path: str) -> list[tuple[bytes, bytes]]:
    out = [(b"content-security-policy", CSP.encode()), (b"x-content-type-options", b"nosniff"),
           (b"referrer-policy", b"no-referrer"), (b"x-frame-options", b"DENY")]
    if path.startswith("/api/") or path == "/":
        out.append((b"cache-control", b"no-store"))
    return out


def _secure_send(send: Callable, scope: dict) -> Callable:
    async def wrapped(message: dict) -> None:
        if message["type"] == "http.response.start":
            message = dict(message)
            message["headers"] = list(message.get("headers", [])) + _security_headers(scope["path"])
        await send(message)

    return wrapped


def _with_headers(response: Response, scope: dict) -> Callable:
    for k, v in _security_headers(scope["path"]):
        response.headers[k.decode()] = v.decode()
    return response


# --------------------------------------------------------------------------- routes


def _on_mechanism(service: str) -> Callable[[Request], Awaitable[Response]]:
    """A route calling ``_service.<service>(body["mechanism"])`` in a worker process."""

    @api
    async def route(request: Request) -> Any:
        return await _heavy(request, service, (await _parsed(request, S.MechanismBody)).mechanism)

    return route


#: The most rows of a simulation answered in the server's own process (the page asks for
#: 180 or 181; more go to a worker).
QUICK_STEPS = 361


# each route reads the app's state (root, start, start_name, jobs) from request.app.state
async def _index(request: Request) -> Response:
    return FileResponse(STATIC / "index.html", media_type="text/html")


@api
async def _start_route(request: Request) -> Any:
    state = request.app.state
    return {"mechanism": state.start, "name": state.start_name, "root": state.root.name,
            "synthesis_kinds": {k: v[0] for k, v in _service.SYNTHESIS_KINDS.items()}}


@api
async def _examples(request: Request) -> Any:
    return {"examples": await run_in_threadpool(_service.examples)}


@api
async def _example(request: Request) -> Any:
    path = _service.example_path(request.path_params["name"])
    return {"mechanism": await run_in_threadpool(_service.read_mechanism, path), "name": path.name}


@api
async def _simulate(request: Request) -> Any:
    body = await _parsed(request, S.SimulateBody)
    args = (body.mechanism, body.steps, None, body.rates)
    # a mechanism of drivers and dyads at the page's sweep (a drag's repaint: milliseconds
    # of NumPy) in this process, with the plans compiled here; the rest, and every
    # refusal, in a worker
    quick = await run_in_threadpool(_service.quick_simulate, *args) if body.steps <= QUICK_STEPS else None
    return quick if quick is not None else await _heavy(request, "simulate", *args)


@api
async def _file_list(request: Request) -> Any:
    return {"files": await run_in_threadpool(_files.list_mechanism_files, request.app.state.root)}


@api
async def _read_file(request: Request) -> Any:
    root = request.app.state.root
    path = _files.resolve_inside(root, request.query_params.get("path"))
    _files.mechanism_suffix(path, suffixes=_files.READABLE_SUFFIXES)
    if not path.is_file():
        raise MechsynInputError(f"{request.query_params.get('path', '')[:200]}: no such file", field="path")
    return {"mechanism": await _heavy(request, "read_mechanism", path), "name": path.relative_to(root).as_posix()}


@api
async def _save_file(request: Request) -> Any:
    body = await _parsed(request, S.SaveBody)
    root, name = request.app.state.root, body.path
    path = _files.resolve_inside(root, name)
    suffix = _files.mechanism_suffix(path)
    if (path.exists() or path.is_symlink()) and not body.overwrite:
        raise MechsynInputError(f"{name} exists", field="path", hint="confirm to overwrite it")
    mode = await run_in_threadpool(_files.may_replace, path)
    if not path.parent.is_dir():
        raise MechsynInputError(f"no folder {path.parent.relative_to(root).as_posix()}", field="path")
    text = await _heavy(request, "mechanism_text", body.mechanism, suffix)
    await run_in_threadpool(write_atomic, path, text, mode)
    return {"saved": path.relative_to(root).as_posix(), "bytes": len(text.encode())}


@api
async def _import_text(request: Request) -> Any:
    body = await _parsed(request, S.ImportBody)
    return {"mechanism": await _heavy(request, "parse_mechanism_text", body.text, body.filename),
            "name": body.filename}


@api
async def _export_text(request: Request) -> Any:
    body = await _parsed(request, S.ExportBody)
    fmt = body.format
    if fmt == "csv":
        text = await _heavy(request, "simulation_csv", body.mechanism, body.steps)
        return Response(text, media_type="text/csv")
    if fmt == "gif":
        gif = await _heavy(request, "animation_gif", body.mechanism, body.frames)
        return Response(gif, media_type="image/gif")
    text = await _heavy(request, "mechanism_text", body.mechanism, "." + fmt)
    return Response(text, media_type="application/json" if fmt == "json" else "application/yaml")


@api
async def _atlas(request: Request) -> Any:
    q = request.query_params
    n, f = _query_int(q.get("links", "6"), "links"), _query_int(q.get("mobility", "1"), "mobility")
    return {"chains": await _heavy(request, "atlas", n, f)}


def _query_int(text: str, field: str) -> int:
    if not (text.isascii() and text.lstrip("-").isdigit() and len(text) <= 6):
        raise MechsynInputError(f"expected a whole number, got {text[:20]!r}", field=field)
    return int(text)


@api
async def _atlas_mechanism(request: Request) -> Any:
    body = await _parsed(request, S.ChainBody)
    return {"mechanism": await _heavy(request, "atlas_mechanism", body.chain, body.frame, body.input)}


@api
async def _synth_start(request: Request) -> Any:
    kind = request.path_params["kind"]
    if kind not in _service.SYNTHESIS_KINDS:
        raise MechsynInputError(f"unknown synthesis kind {kind[:40]!r}", field="kind",
                                hint="one of " + ", ".join(_service.SYNTHESIS_KINDS))
    params = (await _parsed(request, S.SYNTHESIS_PARAMS.get(kind, S.AnyParams))).model_dump()
    fn = _service.SYNTHESIS_KINDS[kind][1]
    state = request.app.state
    return state.jobs.submit(kind, fn, params, state.heavy, _client(request)).snapshot()


@api
async def _job_state(request: Request) -> Any:
    return request.app.state.jobs.get(request.path_params["job"]).snapshot()


@api
async def _job_cancel(request: Request) -> Any:
    job = request.app.state.jobs.get(request.path_params["job"])
    job.cancel()
    return job.snapshot()


@api
async def _job_events(request: Request) -> Any:
    job = request.app.state.jobs.get(request.path_params["job"])

    async def stream():
        seen = -1
        while True:
            if await request.is_disconnected() or request.app.state.stopping.is_set():
                return
            if job.version != seen:
                seen = job.version
                snap = job.snapshot()
                yield f"event: {'progress' if snap['state'] == 'running' else 'end'}\ndata: {json.dumps(snap)}\n\n"
                if snap["state"] != "running":
                    return
            await asyncio.sleep(0.1)

    return StreamingResponse(stream(), media_type="text/event-stream", headers={"cache-control": "no-store"})


async def _not_found(request: Request, exc: Exception) -> Response:
    status = getattr(exc, "status_code", 404)
    return _json_error(status, str(getattr(exc, "detail", "not found")))


def _routes() -> list:
    """The studio's routes: the page, the JSON API and the static assets."""
    return [
        Route("/", _index),
        Route("/api/start", _start_route),
        Route("/api/examples", _examples),
        Route("/api/examples/{name}", _example),
        Route("/api/validate", _on_mechanism("validate"), methods=["POST"]),
        Route("/api/simulate", _simulate, methods=["POST"]),
        Route("/api/analyze", _on_mechanism("analyze"), methods=["POST"]),
        Route("/api/files", _file_list),
        Route("/api/file", _read_file),
        Route("/api/file", _save_file, methods=["POST"]),
        Route("/api/import", _import_text, methods=["POST"]),
        Route("/api/export", _export_text, methods=["POST"]),
        Route("/api/atlas", _atlas),
        Route("/api/atlas/mechanism", _atlas_mechanism, methods=["POST"]),
        Route("/api/synth/{kind}", _synth_start, methods=["POST"]),
        Route("/api/jobs/{job}", _job_state),
        Route("/api/jobs/{job}/cancel", _job_cancel, methods=["POST"]),
        Route("/api/jobs/{job}/events", _job_events),
        *_studio.routes(),
        *_spatial.routes(),  # view3d, tabs3d: POST /api/spatial/simulate
        *_design.routes(),  # issue 40: dimensions, Burmester curves, instant centres, robots
        Mount("/static", StaticFiles(directory=STATIC), name="static"),
    ]


def create_app(root: str | Path = ".", start: dict[str, Any] | None = None, token: str | None = None,
               allowed_hosts: Iterable[str] = LOCAL_HOSTS, start_name: str = "", isolate: bool = True) -> Starlette:
    """The studio as an ASGI app.

    Parameters
    ----------
    root
        The start directory: the only place files are read from and written to.
    start
        The mechanism shown first (a file-format dict), or None for an empty canvas.
    token
        The per-launch secret every ``/api/`` request must carry (random when None;
        read it back as ``app.state.token``).
    allowed_hosts
        Host names this server answers to (the Host header check).
    start_name
        The file name the start mechanism came from (offered when saving).
    isolate
        Heavy work in worker processes (True), or in threads (False: tests that patch
        :mod:`mechsyn.web._service`), see :class:`mechsyn.web._jobs.HeavyRunner`.

    Examples
    --------
    >>> from starlette.testclient import TestClient
    >>> app = create_app(token="t")
    >>> client = TestClient(app, base_url="http://127.0.0.1")
    >>> client.get("/api/examples").status_code
    403
    >>> client.get("/api/examples", headers={"X-Mechsyn-Token": "t"}).status_code
    200
    """
    app = Starlette(routes=_routes(), exception_handlers={HTTPException: _not_found}, lifespan=_lifespan)
    app.state.token = token or secrets.token_urlsafe(24)
    app.state.root = Path(root).resolve()
    app.state.start, app.state.start_name = start, start_name
    app.state.jobs = JobTable()
    app.state.heavy = HeavyRunner(isolate=isolate)
    app.state.stopping = threading.Event()  # set by the first SIGINT/SIGTERM (run_server)
    app.add_middleware(Guard, token=app.state.token, allowed_hosts=allowed_hosts)
    return app


@contextlib.asynccontextmanager
async def _lifespan(app: Starlette):
    await asyncio.get_running_loop().run_in_executor(None, app.state.heavy.warm)
    # the kernel's compiled pass (Numba) loaded (or compiled, once per machine) beside
    # the server's start rather than on the first drag
    threading.Thread(target=_warm_kernel, name="mechsyn-kernel-warm", daemon=True).start()
    yield
    app.state.jobs.cancel_all()


def _warm_kernel() -> None:
    from mechsyn.kinematics import kernel

    kernel.warm()


#: Seconds a client may take to send its request head (and to keep an idle connection).
HEADER_TIMEOUT = 10
#: Connections whose request head has not arrived yet; a new one beyond closes the oldest
#: (a client sends its head at once: only silent sockets wait, and they hold no slot).
MAX_PENDING_HEADS = 256


def _header_timeout_protocol():
    """uvicorn's h11 protocol closing a connection whose request head has not arrived
    within :data:`HEADER_TIMEOUT` s (uvicorn's own keep-alive timer starts only after a
    first response: about 1,100 silent connections locked a studio out), and the oldest
    such connection when more than :data:`MAX_PENDING_HEADS` wait (their descriptors stay
    bounded). Nothing counts open sockets: :class:`Guard` counts the requests that run
    (issue 42: 250 sockets sending a request line only made uvicorn's ``limit_concurrency``
    answer 503 to the real user)."""
    from collections import OrderedDict

    from uvicorn.protocols.http.h11_impl import H11Protocol

    pending: "OrderedDict[Any, None]" = OrderedDict()  # this server's connections without a head

    class Protocol(H11Protocol):
        def connection_made(self, transport: Any) -> None:
            super().connection_made(transport)
            self._head_timer = self.loop.call_later(HEADER_TIMEOUT, self._head_late)
            pending[self] = None
            while len(pending) > MAX_PENDING_HEADS:
                oldest, _ = pending.popitem(last=False)
                oldest._head_late()

        def _head_late(self) -> None:
            pending.pop(self, None)
            if self.cycle is None and not self.transport.is_closing():
                self.transport.close()

        def handle_events(self) -> None:
            super().handle_events()
            if self.cycle is not None:
                self._head_timer.cancel()
                pending.pop(self, None)

        def connection_lost(self, exc: Exception | None) -> None:
            self._head_timer.cancel()
            pending.pop(self, None)
            super().connection_lost(exc)

    return Protocol


def server_config(app: Starlette, host: str = "127.0.0.1", port: int = 8765):
    """uvicorn's settings for the studio: the request head within :data:`HEADER_TIMEOUT` s
    (the body: :data:`BODY_TIMEOUT`, in :class:`Guard`), idle connections closed after as
    long, no limit on open sockets (requests are counted by :class:`Guard`), one second
    to finish on exit."""
    import uvicorn

    return uvicorn.Config(app, host=host, port=port, log_level="warning", http=_header_timeout_protocol(),
                          timeout_keep_alive=HEADER_TIMEOUT, limit_concurrency=None,
                          timeout_graceful_shutdown=1, h11_max_incomplete_event_size=64 * 1024)


def run_server(app: Starlette, host: str = "127.0.0.1", port: int = 8765) -> None:
    """Serve ``app`` with uvicorn until SIGINT or SIGTERM.

    The first signal stops the server at once, whatever is open (event streams, long
    requests, worker processes: cancelled), and is raised again once uvicorn has
    restored the previous handlers: Ctrl-C becomes ``KeyboardInterrupt`` (exit 130 on
    the command line), SIGTERM the command line's 143.
    """
    import uvicorn

    class _Server(uvicorn.Server):
        def handle_exit(self, sig: int, frame: Any) -> None:
            super().handle_exit(sig, frame)
            app.state.stopping.set()  # event streams end now; other requests get 1 s, then are cancelled
            app.state.jobs.cancel_all()
            app.state.heavy.stop_all()  # workers killed: their requests answer 503 within the second

    try:
        _Server(server_config(app, host, port)).run()
    finally:
        app.state.heavy.stop()
