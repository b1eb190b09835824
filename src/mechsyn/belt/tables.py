"""Tables of the belt results as text cells, rendered by the CLI (rich) and by Jupyter
(Markdown) from one source."""

from __future__ import annotations

import math
from typing import Any, NamedTuple

__all__ = ["Table", "fmt"]


class Table(NamedTuple):
    """A table of a report as text cells: the CLI and Jupyter render it their own way."""

    title: str
    columns: tuple[str, ...]
    rows: list[tuple[str, ...]]
    caption: str = ""
    #: the first column holds labels (left-aligned), not numbers
    labels: bool = False

    def markdown(self) -> str:
        """The table in Markdown (title in bold, caption in italics under it)."""
        head = "| " + " | ".join(c or " " for c in self.columns) + " |"
        rule = "|" + "|".join("---" for _ in self.columns) + "|"
        body = ["| " + " | ".join(c.replace("|", "/") for c in r) + " |" for r in self.rows]
        tail = ["", f"*{self.caption}*"] if self.caption else []
        return "\n".join([f"**{self.title}**", "", head, rule, *body, *tail])


def fmt(v: Any, nd: int = 3) -> str:
    """A number for a table: ``nan`` where undefined, ``—`` where absent."""
    if v is None:
        return "—"
    v = float(v)
    return "nan" if not math.isfinite(v) else f"{v:.{nd}f}"
