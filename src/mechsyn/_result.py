"""The behaviour every result of mechsyn shares: a dict for JSON, a short text, a table for
Jupyter, and a picture where one says more.

A result is a dataclass that inherits :class:`Result`. Its ``to_dict()`` is derived from
its fields (a field declared with ``metadata={"json": False}`` is left out, e.g. the solver
state a result keeps for plotting); a result overrides it only where it adds something on
purpose (a mask turning unassembled samples into ``null``, a block of units). ``plot(ax=None)``
delegates to the function named in ``_plot`` inside :mod:`mechsyn.plot`, imported only when
called, so computing never loads Matplotlib.
"""

from __future__ import annotations

import dataclasses
import importlib
from typing import Any, ClassVar

import numpy as np

__all__ = ["Result", "summary_rows"]


def _short(value: Any) -> str | None:
    """A value in a few characters, or None when it is too big to show in a summary."""
    if isinstance(value, (bool, int, str)) or value is None:
        text = repr(value) if isinstance(value, str) else str(value)
        return text if len(text) <= 60 else text[:57] + "..."
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    if isinstance(value, np.ndarray):
        return f"array{value.shape}"
    if isinstance(value, (list, tuple, dict)):
        return f"{type(value).__name__} of {len(value)}"
    return None


def summary_rows(obj: Any) -> list[tuple[str, str]]:
    """``(field, short value)`` for the fields of dataclass ``obj`` that read in a line."""
    rows = []
    for f in dataclasses.fields(obj):
        if not f.repr or f.metadata.get("json") is False:
            continue
        text = _short(getattr(obj, f.name))
        if text is not None:
            rows.append((f.name, text))
    return rows


class Result:
    """Mixin of mechsyn's result dataclasses (see the module doc).

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> from mechsyn._result import Result
    >>> @dataclass(repr=False)
    ... class Answer(Result):
    ...     mobility: int
    ...     note: str = "planar"
    >>> a = Answer(1)
    >>> a.to_dict()
    {'mobility': 1, 'note': 'planar'}
    >>> print(a)
    Answer
      mobility  1
      note      'planar'
    """

    #: ``"module:function"`` in :mod:`mechsyn.plot` that draws this result, or None.
    _plot: ClassVar[str | None] = None

    def to_dict(self) -> dict[str, Any]:
        """The result as plain values (arrays stay arrays; ``mechsyn.results.to_jsonable``
        makes JSON of them)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)  # type: ignore[arg-type]
                if f.metadata.get("json", True)}

    def _summary(self) -> list[tuple[str, str]]:
        return summary_rows(self)

    def __str__(self) -> str:
        rows = self._summary()
        width = max((len(k) for k, _ in rows), default=0)
        return "\n".join([type(self).__name__] + [f"  {k:<{width}}  {v}" for k, v in rows])

    def __repr__(self) -> str:
        inner = ", ".join(f"{k}={v}" for k, v in self._summary())
        text = f"{type(self).__name__}({inner})"
        return text if len(text) <= 300 else text[:296] + "...)"

    def _repr_markdown_(self) -> str:
        rows = self._summary()
        lines = [f"**{type(self).__name__}**", "", "| field | value |", "|---|---|"]
        lines += [f"| {k} | {v.replace('|', '/')} |" for k, v in rows]
        return "\n".join(lines)

    def _repr_pretty_(self, p: Any, cycle: bool) -> None:
        p.text(repr(self) if cycle else str(self))

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Draw the result (see :mod:`mechsyn.plot`) on ``ax`` or a new figure and return
        the Axes (the Figure for pictures of several panels, which take ``fig=`` instead).
        Never writes a file, never chooses a backend."""
        import inspect

        if self._plot is None:
            raise TypeError(f"{type(self).__name__} has no picture")
        module, name = self._plot.split(":")
        draw = getattr(importlib.import_module(f"mechsyn.plot.{module}"), name)
        if "ax" in inspect.signature(draw).parameters:
            return draw(self, ax=ax, **kwargs)
        if ax is not None:
            raise TypeError(f"{type(self).__name__}.plot draws several panels: give fig=, not ax=")
        return draw(self, **kwargs)
