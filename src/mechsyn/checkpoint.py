"""Checkpoints of multi-start searches: stop a long search, continue it later.

A multi-start search (``synth path``, ``synth mechanism``) runs independent restarts, each
from its own child seed (:func:`mechsyn.synthesis.optimize.restart_seeds`). A
:class:`RestartCheckpoint` keeps, in one JSON file written whole (temporary file, then
rename) each time a restart finishes and at most every ``interval`` seconds meanwhile:

* every finished restart (its index, seed, best vector, fitness, evaluations, seconds);
* the best vector evaluated so far by the restart that is running (``partial``);
* a *key*: what the result depends on (a digest of the case, the seed, the number of
  restarts, the optimiser and its options). A checkpoint is resumed only with the same key.

Resuming runs only the restarts not finished, each from its own seed, so the resumed
search finds what the uninterrupted one would have (unless a time limit cut a restart
short: a restart is kept as its time limit left it). The partial best of an interrupted
restart is kept only as a fallback: it competes if the resumed run is interrupted again
before that restart finishes.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> ck = RestartCheckpoint.open(folder / "run.ckpt.json", "demo", {"seed": 0, "restarts": 3})
>>> ck.finish(0, seed=11, x=[1.0, 2.0], fitness=0.5, nfev=100, seconds=1.0)
>>> ck = RestartCheckpoint.open(folder / "run.ckpt.json", "demo", {"seed": 0, "restarts": 3}, resume=True)
>>> sorted(ck.finished), ck.pending(3)
([0], [1, 2])
>>> RestartCheckpoint.open(folder / "run.ckpt.json", "demo", {"seed": 1, "restarts": 3}, resume=True)
Traceback (most recent call last):
...
mechsyn.errors.MechsynInputError: ...run.ckpt.json: key.seed: the checkpoint was written with 0, this run has 1 (fix: resume with the options of the interrupted run (seed 0), or start afresh with --checkpoint)
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.results import dumps, write_atomic

__all__ = ["RestartCheckpoint", "FORMAT", "digest", "open_search_checkpoint", "read_checkpoint"]

#: The ``format`` field of a checkpoint file (how a checkpoint is recognised).
FORMAT = "mechsyn-checkpoint"
VERSION = 1


def digest(obj: Any) -> str:
    """A short SHA-256 digest of ``obj``'s JSON (dataclasses and arrays allowed)."""
    return hashlib.sha256(dumps(obj, indent=None).encode()).hexdigest()[:16]


_AFRESH = "start afresh with --checkpoint (the file is not usable)"


def _record(data: Any, source: str, where: str, dim: int | None) -> dict[str, Any]:
    try:
        rec = {"seed": int(data["seed"]), "x": np.asarray(data["x"], float),
               "fitness": float("inf") if data["fitness"] is None else float(data["fitness"]),
               "nfev": int(data.get("nfev", 0)), "seconds": float(data.get("seconds", 0.0))}
    except (TypeError, KeyError, ValueError, AttributeError, OverflowError):
        raise MechsynInputError("damaged restart record", source=source, field=where, hint=_AFRESH) from None
    x = rec["x"]
    if x.ndim != 1 or not np.isfinite(x).all() or (dim is not None and x.size != dim) or rec["fitness"] != rec["fitness"]:
        raise MechsynInputError("damaged restart record (design vector or fitness)", source=source,
                                field=f"{where}.x", hint=_AFRESH)
    return rec


def read_checkpoint(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The content of a checkpoint file, or :class:`MechsynInputError` naming the problem."""
    from mechsyn.io.files import read_data

    data, _ = read_data(Path(path), "checkpoint", fmt="json")
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise MechsynInputError("not a mechsyn checkpoint", source=str(path), field="format",
                                hint="give the file written by --checkpoint")
    if data.get("version") != VERSION:
        raise MechsynInputError(f"checkpoint version {data.get('version')!r}, this mechsyn reads {VERSION}",
                                source=str(path), field="version", hint="start afresh with --checkpoint")
    return data


class RestartCheckpoint:
    """The finished restarts of a multi-start search, kept in a file (see the module doc).

    Parameters
    ----------
    path : path-like
        The checkpoint file.
    kind : str
        The search (``"synth path"``...), checked on resume.
    key : dict
        What the result depends on, checked field by field on resume.
    interval : float
        Seconds between two saves of the running restart's best.
    """

    def __init__(self, path: str | os.PathLike[str], kind: str, key: dict[str, Any],
                 interval: float = 5.0) -> None:
        self.path, self.kind, self.key, self.interval = Path(path), kind, dict(key), interval
        self.finished: dict[int, dict[str, Any]] = {}
        self.partial: dict[str, Any] | None = None
        #: finished stages kept as data (name -> JSON value), for searches whose units are
        #: not restarts (``synth finger-design``: one record per VLL variant)
        self.done: dict[str, Any] = {}
        self._saved = time.monotonic()

    @classmethod
    def open(cls, path: str | os.PathLike[str], kind: str, key: dict[str, Any], *,
             resume: bool = False, interval: float = 5.0, dim: int | None = None) -> "RestartCheckpoint":
        """A new checkpoint at ``path`` or, with ``resume``, the one it holds (same kind
        and key, else :class:`MechsynInputError` naming the field that differs). ``dim``:
        the length of the design vectors, checked.

        A new checkpoint never replaces a file that is not a checkpoint.
        """
        ck = cls(path, kind, key, interval)
        if not resume:
            if ck.path.exists():
                try:
                    read_checkpoint(ck.path)
                except MechsynInputError:
                    raise MechsynInputError("exists and is not a mechsyn checkpoint; not overwritten",
                                            source=str(path), hint="give another --checkpoint file") from None
            return ck
        if not ck.path.exists():
            raise MechsynInputError("no such checkpoint", source=str(path),
                                    hint="give the file written by --checkpoint (or start with --checkpoint)")
        data = read_checkpoint(ck.path)
        if data.get("kind") != kind:
            raise MechsynInputError(f"a checkpoint of {data.get('kind')!r}, not of {kind!r}", source=str(path),
                                    field="kind", hint=f"resume it with mechsyn {data.get('kind')}")
        ck._check_key(data.get("key"))
        try:
            ck.finished = {ck._index(i, f"finished[{str(i)[:20]}]"): _record(r, str(path), f"finished[{i}]", dim)
                           for i, r in (data.get("finished") or {}).items()}
            if data.get("partial"):
                ck.partial = {**_record(data["partial"], str(path), "partial", dim),
                              "index": ck._index(data["partial"]["index"], "partial.index")}
            done = data.get("done") or {}
            ck.done = {str(k): v for k, v in done.items()}
        except MechsynInputError:
            raise
        except (TypeError, KeyError, ValueError, AttributeError, OverflowError) as exc:
            raise MechsynInputError(f"damaged checkpoint ({type(exc).__name__})", source=str(path),
                                    field="finished", hint=_AFRESH) from None
        return ck

    def _index(self, text: Any, where: str) -> int:
        """A restart index read from the file: an integer in ``0 ... restarts - 1`` when the
        key holds the number of restarts (a forged ``-7`` or ``99999`` never counts as done)."""
        if isinstance(text, bool) or not isinstance(text, (int, str)) or not (str(text).isascii() and str(text).isdigit()):
            raise MechsynInputError(f"restart index {str(text)[:20]!r} is not a whole number", source=str(self.path),
                                    field=where, hint=_AFRESH)
        index, restarts = int(text), self.key.get("restarts")
        if isinstance(restarts, int) and not 0 <= index < restarts:
            raise MechsynInputError(f"restart index {index} is outside 0 ... {restarts - 1}", source=str(self.path),
                                    field=where, hint=_AFRESH)
        return index

    def _check_key(self, saved: Any) -> None:
        if not isinstance(saved, dict):
            raise MechsynInputError("damaged checkpoint: no key", source=str(self.path), field="key",
                                    hint=_AFRESH)
        mine = json.loads(dumps(self.key, indent=None))
        for name in sorted(set(mine) | set(saved)):
            if mine.get(name) == saved.get(name):
                continue
            if name == "case":
                raise MechsynInputError(
                    "the checkpoint was written for another case (or the case file changed)",
                    source=str(self.path), field="key.case",
                    hint="resume with the case of the interrupted run, or start afresh with --checkpoint")
            raise MechsynInputError(
                f"the checkpoint was written with {saved.get(name)!r}, this run has {mine.get(name)!r}",
                source=str(self.path), field=f"key.{name}",
                hint=f"resume with the options of the interrupted run ({name} {saved.get(name)!r}), "
                     "or start afresh with --checkpoint")

    def pending(self, restarts: int) -> list[int]:
        """Indices of the restarts still to run, in order."""
        return [i for i in range(restarts) if i not in self.finished]

    def finish(self, index: int, *, seed: int, x: Any, fitness: float, nfev: int = 0,
               seconds: float = 0.0) -> None:
        """Record restart ``index`` as finished and save."""
        self.finished[int(index)] = {"seed": int(seed), "x": np.asarray(x, float), "fitness": float(fitness),
                                     "nfev": int(nfev), "seconds": float(seconds)}
        if self.partial is not None and self.partial["index"] == index:
            self.partial = None
        self.save()

    def finish_stage(self, name: str, data: Any) -> None:
        """Record the finished stage ``name`` with its result ``data`` (JSON-able) and save."""
        self.done[str(name)] = json.loads(dumps(data, indent=None))
        self.save()

    def offer(self, index: int, seed: int, x: Any, fitness: float, *, force: bool = False) -> None:
        """The running restart's best so far; saved if ``interval`` seconds passed (or ``force``)."""
        if x is None or index in self.finished:
            return
        if self.partial is None or self.partial["index"] != index or fitness < self.partial["fitness"]:
            self.partial = {"index": int(index), "seed": int(seed), "x": np.asarray(x, float),
                            "fitness": float(fitness), "nfev": 0, "seconds": 0.0}
        if force or time.monotonic() - self._saved >= self.interval:
            self.save()

    def save(self) -> None:
        """Write the checkpoint whole (temporary file, then rename)."""
        write_atomic(self.path, dumps({
            "format": FORMAT, "version": VERSION, "kind": self.kind, "key": self.key,
            "written": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
            "finished": {str(i): r for i, r in sorted(self.finished.items())},
            "partial": self.partial, "done": self.done}, indent=None) + "\n")
        self._saved = time.monotonic()

    def due(self) -> bool:
        """Whether ``interval`` seconds have passed since the last save."""
        return time.monotonic() - self._saved >= self.interval


def open_search_checkpoint(path: str | os.PathLike[str] | None, kind: str, case: Any, *, resume: bool = False,
                           dim: int | None = None, **key: Any) -> RestartCheckpoint | None:
    """The checkpoint of a search of ``case`` (``None`` without ``path``): its key is a
    digest of the case and the ``key`` settings (see :meth:`RestartCheckpoint.open`)."""
    if path is None:
        if resume:
            raise MechsynInputError("resume needs the checkpoint file", field="checkpoint",
                                    hint="give checkpoint=<the file written by the interrupted run>")
        return None
    return RestartCheckpoint.open(path, kind, {"case": digest(case), **key}, resume=resume, dim=dim)
