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

    def markdown(self, max_rows: int | None = None, where: str = "") -> str:
        """The table in Markdown (title in bold, caption in italics under it).

        With ``max_rows``, a longer table shows its first and last rows, a row saying how
        many are left out between them, and its size under the title (``where`` says where
        the full table is).

        Examples
        --------
        >>> t = Table("squares", ("n", "n²"), [(str(k), str(k * k)) for k in range(100)])
        >>> print(t.markdown(max_rows=4, where="in to_dict()"))
        **squares** (100 rows: the first 2 and the last 2 shown; all in to_dict())
        <BLANKLINE>
        | n | n² |
        |---|---|
        | 0 | 0 |
        | 1 | 1 |
        | … 96 rows … |  |
        | 98 | 9604 |
        | 99 | 9801 |
        """
        head = "| " + " | ".join(c or " " for c in self.columns) + " |"
        rule = "|" + "|".join("---" for _ in self.columns) + "|"
        rows, title = list(self.rows), f"**{self.title}**"
        if max_rows is not None and len(rows) > max_rows:
            first = (max_rows + 1) // 2
            last = max_rows - first
            title += (f" ({len(rows)} rows: the first {first} and the last {last} shown"
                      + (f"; all {where}" if where else "") + ")")
            gap = (f"… {len(rows) - max_rows} rows …",) + ("",) * (len(self.columns) - 1)
            rows = rows[:first] + [gap] + rows[len(rows) - last:]
        body = ["| " + " | ".join(c.replace("|", "/") for c in r) + " |" for r in rows]
        tail = ["", f"*{self.caption}*"] if self.caption else []
        return "\n".join([title, "", head, rule, *body, *tail])


def fmt(v: Any, nd: int = 3) -> str:
    """A number for a table: ``nan`` where undefined, ``—`` where absent."""
    if v is None:
        return "—"
    v = float(v)
    return "nan" if not math.isfinite(v) else f"{v:.{nd}f}"
