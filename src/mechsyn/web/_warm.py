"""Warm-up of the studio's workers: imported once by their fork server (the last module of
:data:`mechsyn.web._jobs.PRELOAD`), it runs a structure check and a short simulation of a
four-bar, so that every worker forked afterwards starts with pydantic's validators built
and the lazy imports of these services done (a four-bar's check in a fresh worker took
67 ms, in a warm one 34 ms, on a loaded machine). Nothing here may stop the fork server:
a failure is ignored (the workers then warm up on their own).
"""

from __future__ import annotations

FOURBAR = {"name": "Four-bar linkage", "kind": "planar", "ground": "frame",
           "links": ["frame", "crank", "coupler", "rocker"],
           "joints": [{"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0.0, 0.0], "actuated": True},
                      {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": [1.0, 2.0]},
                      {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": [4.0, 3.0]},
                      {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": [5.0, 0.0]}]}


def warm() -> None:
    """One check and one simulation of :data:`FOURBAR` (errors ignored)."""
    try:
        from mechsyn.web._service import simulate
        from mechsyn.web._studio import check

        check(FOURBAR)
        simulate(FOURBAR, 12)
    except Exception:  # noqa: BLE001  a warm-up only
        pass


warm()
