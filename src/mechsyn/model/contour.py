"""Contours (closed loops) of the link graph."""

from __future__ import annotations

from collections.abc import Sequence

from mechsyn.model.mechanism import Joint


def contour_links(joints: Sequence[Joint]) -> list[str] | None:
    """Links met walking the joints of a contour in order, or None if not a closed loop.

    A contour ``j1 ... jk`` is closed when there are links ``L0 ... L(k-1)`` with
    ``jt`` joining ``L(t-1)`` and ``Lt`` and ``jk`` joining ``L(k-1)`` and ``L0``.
    Returns ``[L0, ..., L(k-1)]``.
    """
    if len(joints) < 2:
        return None
    first = joints[0]
    for start in (first.links[0], first.links[1]):
        current = first.other(start)
        walk = [start, current]
        ok = True
        for j in joints[1:]:
            if current not in j.links or j.links[0] == j.links[1]:
                ok = False
                break
            current = j.other(current)
            walk.append(current)
        if ok and walk[-1] == walk[0]:
            links = walk[:-1]
            if len(set(links)) == len(links):
                return links
    return None
