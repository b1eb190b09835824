"""mechsyn studio: a local web app to draw, drag, analyse, animate and synthesise mechanisms.

``mechsyn serve [FILE|EXAMPLE]`` starts it; :func:`create_app` builds the ASGI app (tests
call it in-process) and :func:`run_server` serves it on 127.0.0.1. The front end
(``static/``) is plain ES modules drawing SVG, shipped as package data: nothing is
fetched from outside the server.
"""

from mechsyn.web._app import create_app, run_server

__all__ = ["create_app", "run_server"]
