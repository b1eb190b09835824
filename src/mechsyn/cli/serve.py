"""``mechsyn serve [FILE|EXAMPLE]``: the studio, a local web app (see :mod:`mechsyn.web`)."""

from __future__ import annotations

import secrets
import webbrowser
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from mechsyn.cli.app import app
from mechsyn.cli.common import console, err_console
from mechsyn.errors import MechsynInputError


@app.command("serve")
def serve(
    target: Annotated[Optional[str], typer.Argument(help="Mechanism file, or an example name (e.g. fourbar).")] = None,
    port: Annotated[int, typer.Option("--port", help="Port (0: any free port).", min=0, max=65535)] = 8765,
    host: Annotated[str, typer.Option("--host", help="Address to bind; anything but 127.0.0.1 exposes the "
                                      "studio to the network.")] = "127.0.0.1",
    no_browser: Annotated[bool, typer.Option("--no-browser", help="Do not open a browser.")] = False,
) -> None:
    """Start mechsyn studio: draw, drag, analyse, animate and synthesise mechanisms in the browser."""
    from mechsyn.web import create_app, run_server
    from mechsyn.web._app import LOCAL_HOSTS

    start, name = _start(target) if target else (None, "")
    if host not in LOCAL_HOSTS:
        err_console.print(f"[bold yellow]warning:[/] serving on {host} without TLS: anyone on the network who "
                          "sees the URL's token can use the studio and write files here (see docs/reliability.md: "
                          "a reverse proxy with TLS)", highlight=False, soft_wrap=True)
    port = port or _free_port(host)
    token = secrets.token_urlsafe(24)
    shown = "127.0.0.1" if host in ("0.0.0.0", "::") else host
    app_ = create_app(Path.cwd(), start=start, token=token, start_name=name,
                      allowed_hosts=set(LOCAL_HOSTS) | {host, shown} | _own_names(host))
    url = f"http://{'[' + shown + ']' if ':' in shown else shown}:{port}/?token={token}"
    console.print(f"mechsyn studio at [bold]{url}[/]  (Ctrl+C stops it)", highlight=False, soft_wrap=True)
    opener = None if no_browser else _open_browser(url)
    try:
        run_server(app_, host=host, port=port)
    finally:
        if opener is not None:
            opener.unlink(missing_ok=True)


def _own_names(host: str) -> set[str]:
    """This machine's names, accepted in the Host header when serving on all addresses
    (the addresses themselves are accepted as the connection's own, see ``Guard``)."""
    import socket

    if host not in ("0.0.0.0", "::"):
        return set()
    return {n.lower() for n in (socket.gethostname(), socket.getfqdn()) if n}


def _open_browser(url: str) -> Path | None:
    """Open ``url`` in the browser without the token on any command line (``ps`` shows
    those): through a redirecting page only this user can read (0600), as Jupyter does.
    Returns that page, removed when the server stops."""
    import html
    import os
    import tempfile

    fd, name = tempfile.mkstemp(prefix="mechsyn-open-", suffix=".html")  # 0600
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(f'<!doctype html><meta http-equiv="refresh" content="0;url={html.escape(url)}">'
                 f'<a href="{html.escape(url)}">mechsyn studio</a>\n')
    webbrowser.open(Path(name).as_uri())
    return Path(name)


def _start(target: str) -> tuple[Any, str]:
    """The mechanism a file or an example name opens with, and its name ("did you mean"
    for a mistyped example)."""
    from mechsyn.io.files import existing_regular
    from mechsyn.web._service import example_path, read_mechanism

    path = Path(target)
    if not path.exists() and path.suffix == "":
        try:
            path = example_path(target)
        except MechsynInputError:
            from mechsyn.examples import did_you_mean

            close = did_you_mean(target, _studio_examples())
            if not close:
                raise
            raise MechsynInputError(f"{target}: no such file or example", source="FILE",
                                    hint=f"did you mean {' or '.join(map(repr, close))}?") from None
    elif not existing_regular(path, "mechanism file"):  # a device, FIFO, directory: refused by name
        raise MechsynInputError(f"{target}: no such file or example", source="FILE",
                                hint="give a mechanism file or an example name such as fourbar")
    return read_mechanism(path), path.name


def _studio_examples() -> list[str]:
    from mechsyn.web._service import examples

    return [e["name"] for e in examples()]


def _free_port(host: str) -> int:
    import socket

    with socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET) as s:
        s.bind((host, 0))
        return int(s.getsockname()[1])
