"""The plumbing every studio route shares: JSON in and out (:func:`api`), the request body
parsed strictly before any work (:func:`_body`) and validated by its schema (:func:`_parsed`,
:mod:`mechsyn.web._schema`) and heavy calls as capped, cancellable worker processes (:func:`_heavy`).

Kept apart from :mod:`mechsyn.web._app` (the app factory and its route table) so that the
route modules (:mod:`mechsyn.web._studio`, :mod:`mechsyn.web._spatial`) use it without
importing the app that registers them.
"""

from __future__ import annotations

import functools
import json
import logging
from typing import Any, Awaitable, Callable

from starlette.concurrency import run_in_threadpool
from starlette.exceptions import HTTPException
from starlette.requests import ClientDisconnect, Request
from starlette.responses import JSONResponse, Response

from mechsyn.errors import MechsynInputError
from mechsyn.io.files import check_data_size, loads_json
from mechsyn.web._jobs import Busy, ClientGone, RawJSON, ServerStopping, TooLong, WorkerCrashed

log = logging.getLogger("mechsyn.web")


def _json_error(status: int, message: str, **extra: Any) -> JSONResponse:
    return JSONResponse({"error": message, **extra}, status_code=status)


def api(fn: Callable[[Request], Awaitable[Any]]) -> Callable[[Request], Awaitable[Response]]:
    """JSON in and out; input errors → 400 naming the field, bugs → 500 without a trace."""

    @functools.wraps(fn)
    async def wrapped(request: Request) -> Response:
        try:
            out = await fn(request)
            return out if isinstance(out, Response) else _json_response(out)
        except MechsynInputError as err:
            return JSONResponse({"error": err.message, "field": err.field, "hint": err.hint,
                                 "element": getattr(err, "element", None)}, status_code=400)
        except HTTPException as exc:
            return _json_error(exc.status_code, str(exc.detail))
        except Busy as exc:
            return _json_error(429, f"busy: {exc}", hint="wait for the running computation to finish")
        except (ClientDisconnect, ClientGone):  # nobody reads the answer: one line, no trace
            log.info("%s %s: the client left; its work was stopped", request.method, request.url.path)
            return _json_error(499, "client disconnected")
        except TooLong as exc:  # a worker past its time limit (killed)
            log.warning("%s %s: %s", request.method, request.url.path, exc)
            return _json_error(503, str(exc), hint="try a smaller mechanism, or fewer steps or frames")
        except ServerStopping:
            return _json_error(503, "the server is stopping", hint="start `mechsyn serve` again")
        except WorkerCrashed as exc:
            log.warning("%s %s: %s", request.method, request.url.path, exc)
            return _json_error(500, "internal server error (the server's log has the details)")
        except Exception:
            log.exception("%s %s failed", request.method, request.url.path)
            return _json_error(500, "internal server error (the server's log has the details)")

    return wrapped


def _json_response(out: Any) -> Response:
    """``out`` as JSON: a worker's :class:`~mechsyn.web._jobs.RawJSON` (alone, or as values
    of a dict) sent as it is; text that is not valid UTF-8 (a lone surrogate echoed from a
    URL) escaped as ``\\uXXXX`` instead of failing outside the route's error handling."""
    if isinstance(out, RawJSON) or (isinstance(out, dict) and any(isinstance(v, RawJSON) for v in out.values())):
        return Response(_encoded(out), media_type="application/json")
    try:
        return JSONResponse(out)
    except UnicodeEncodeError:
        return Response(json.dumps(out, ensure_ascii=True, allow_nan=False), media_type="application/json")


def _encoded(out: Any) -> bytes:
    if isinstance(out, RawJSON):
        return out.data
    if isinstance(out, dict):
        return b"{" + b",".join(RawJSON.of(str(k)).data + b":" + _encoded(v) for k, v in out.items()) + b"}"
    return RawJSON.of(out).data


#: Bodies larger than this many bytes are parsed in a thread, not on the event loop.
PARSE_INLINE = 64 * 1024


def _decoded(raw: bytes) -> Any:
    return check_data_size(loads_json(raw or b"null", "request body", finite=True), "request body", hidden=False)


async def _body(request: Request) -> dict[str, Any]:
    """The request's JSON object, parsed strictly (:func:`mechsyn.io.files.loads_json` with
    finite numbers, :func:`mechsyn.io.files.check_data_size`), before any work; a large body
    in a thread, so that the event loop keeps answering."""
    raw = await request.body()
    try:
        data = _decoded(raw) if len(raw) <= PARSE_INLINE else await run_in_threadpool(_decoded, raw)
    except MechsynInputError as err:
        raise MechsynInputError(f"the request body is not acceptable JSON: {err.message}", field=err.field or "body",
                                hint=err.hint or "send a JSON object") from None
    if not isinstance(data, dict):
        raise MechsynInputError("the request body must be a JSON object", field="body")
    return data


async def _parsed(request: Request, model: type) -> Any:
    """The request's body (:func:`_body`) validated by its schema (:mod:`mechsyn.web._schema`):
    a wrong type, a number too large, a name that is not printable are a 400 naming the field."""
    from mechsyn.web._schema import parse

    return parse(model, await _body(request))


def _client(request: Request) -> str:
    """Who asks, for the per-client caps: the connection (address and port), never a header
    the client chooses (issue 42: a header let one client take every slot)."""
    peer = request.client
    return f"{peer.host}:{peer.port}" if peer else "?"


async def _heavy(request: Request, name: str, *args: Any) -> Any:
    """``_service.<name>(*args)`` as capped, cancellable work (:class:`HeavyRunner`)."""
    return await request.app.state.heavy.call(_client(request), request.is_disconnected, name, *args)
