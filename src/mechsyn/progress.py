"""One progress protocol for every long computation of mechsyn.

A long computation (a sweep that reports, the rank method's stages, path, curve,
mechanism and finger synthesis, the atlas, the curve-database build, capability maps,
:func:`mechsyn.parallel.run_tasks`, the studio's jobs) takes ``progress``, a callable
``progress(state)`` that it calls with a :class:`Progress` as the work goes:

* ``done`` of ``total`` (``total`` None when unknown: rows, restarts, tasks, units of
  work), both counted from the start of the run, or of its stage when a stage counts its
  own steps (curve synthesis: build, retrieve, refine; finger design: the generations of
  each variant's stage); ``0 <= done <= total``, and ``done`` never goes back within a
  stage, so a reader shows the latest one (a part of a run: :func:`shifted`);
* ``stage``: what runs now (``"sweep"``, ``"restarts"``, ``"contours"``, ``"build"``...);
* ``best``: the best error (or fitness) so far, None before the first;
* ``message``: a line for a person (``""`` when the rest says it all).

Raising :class:`KeyboardInterrupt` in ``progress`` stops a search like Ctrl-C (the best so
far is returned, ``interrupted=True``). The command line shows it with one rich progress
bar (:func:`mechsyn.cli.common.progress_bar`), the studio sends :meth:`Progress.to_dict`
in its job events. Nothing here imports more than the standard library.

Examples
--------
>>> from mechsyn.progress import Progress, counter
>>> seen = []
>>> Progress(done=1, total=4, stage="restarts", best=0.02).fraction
0.25
>>> advance = counter(seen.append, total=3, stage="rows")
>>> advance(); advance(2)
>>> [(p.done, p.total, p.stage) for p in seen]
[(1, 3, 'rows'), (3, 3, 'rows')]
>>> Progress(done=2, total=None, best=float("inf")).to_dict()
{'done': 2, 'total': None, 'stage': '', 'best': None, 'message': ''}
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable

__all__ = ["Progress", "ProgressCallback", "counter", "report", "shifted"]


@dataclass(frozen=True)
class Progress:
    """The state of a running computation, given to ``progress(state)`` (see the module doc).

    A ``best`` that is not a finite number (``inf`` before the first feasible design, NaN)
    is kept as None.

    Examples
    --------
    >>> Progress(done=3, total=10, stage="restarts", best=0.5)
    Progress(done=3, total=10, stage='restarts', best=0.5, message='')
    """

    done: float = 0
    total: float | None = None
    stage: str = ""
    best: float | None = None
    message: str = ""

    def __post_init__(self) -> None:
        if self.best is not None and not math.isfinite(self.best):
            object.__setattr__(self, "best", None)

    @property
    def fraction(self) -> float | None:
        """``done / total``, None when the total is unknown (or 0)."""
        return None if not self.total else self.done / self.total

    def to_dict(self) -> dict[str, Any]:
        """The fields as JSON values (the studio's job events)."""
        return {"done": self.done, "total": self.total, "stage": self.stage,
                "best": None if self.best is None else float(self.best), "message": self.message}


#: ``progress(state)`` of a long computation.
ProgressCallback = Callable[[Progress], None]


def report(progress: ProgressCallback | None, done: float, total: float | None = None, stage: str = "",
           best: float | None = None, message: str = "") -> None:
    """``progress(Progress(...))`` when there is a ``progress`` (None: nothing).

    Examples
    --------
    >>> report(None, 1, 2)          # nobody listens
    >>> report(print, 1, 2, "rank")
    Progress(done=1, total=2, stage='rank', best=None, message='')
    """
    if progress is not None:
        progress(Progress(done, total, stage, best, message))


def counter(progress: ProgressCallback | None, total: float | None = None,
            stage: str = "") -> Callable[..., None]:
    """An ``advance(n=1)`` that counts steps and reports the count so far to ``progress``
    (for work that ticks: a row solved, a task finished, a share of a unit of work).

    Examples
    --------
    >>> seen = []
    >>> tick = counter(seen.append, 2, "sweep")
    >>> tick(); tick()
    >>> seen[-1].done, seen[-1].fraction
    (2, 1.0)
    """
    done = [0]

    def advance(n: float = 1) -> None:
        done[0] += n
        report(progress, done[0], total, stage)

    return advance


def shifted(progress: ProgressCallback | None, before: float, total: float | None) -> ProgressCallback | None:
    """The ``progress`` of one part of a run (a sweep computed in two parts outwards from
    its drawn row): each state of the part is passed on with the ``before`` steps of the
    parts before it added to its ``done``, of the run's ``total`` (None: nothing listens).

    Examples
    --------
    >>> seen = []
    >>> second = shifted(seen.append, 3, 5)
    >>> second(Progress(done=1, total=2, stage="sweep"))
    >>> seen
    [Progress(done=4, total=5, stage='sweep', best=None, message='')]
    >>> shifted(None, 3, 5) is None
    True
    """
    if progress is None:
        return None

    def part(state: Progress) -> None:
        progress(replace(state, done=before + state.done, total=total))

    return part
