"""Drives against mobility: which declared drives are one too many (over-actuation).

A mechanism of mobility ``W`` is moved by ``W`` independent drives. A drive beyond them
is not free: its motion is fixed by the others (the drives fight each other), so a
simulation that holds it at its drawn value while the others move finds no configuration.
:func:`excess_drives` finds such drives from the drives' rates on the mechanism's motions
(the rows of the drives in a basis of the joint rates that close every loop): a drive is
independent when its rows raise the rank of the rows kept before it. The rank method
(:mod:`mechsyn.structure.rank`) and the kinematic simulation
(:mod:`mechsyn.kinematics.analysis`) both ask it, each with its own motions; the sentence a
user reads is :meth:`DriveCheck.text`.

Examples
--------
>>> import numpy as np
>>> motions = np.array([[1.0], [0.5], [-2.0]])       # one motion: three joint rates
>>> excess_drives(motions, {"A": [0], "D": [2]}, ["A", "D"], 1e-9)
['D']
>>> DriveCheck(["A", "D"], 1, ["D"], "rank method").text()
'2 drives (A, D) for mobility 1: drop `actuated: true` on D'
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

__all__ = ["DriveCheck", "excess_drives", "drive_check_of_formulas"]


def _rank(a: np.ndarray, tol: float) -> int:
    if a.size == 0:
        return 0
    return int(np.sum(np.linalg.svd(a, compute_uv=False) > tol))


def excess_drives(motions: np.ndarray, rows: dict[str, Sequence[int]], order: Sequence[str],
                  tol: float) -> list[str]:
    """The drives of ``order`` whose rates are fixed by drives before them in ``order``.

    ``motions`` (rows: joint coordinates, columns: a basis of the mechanism's motions);
    ``rows[d]``: the rows of drive ``d`` (several for a multi-freedom pair); ``tol``: the
    rank tolerance on the rows' singular values. A drive whose rows vanish on every motion
    (the mechanism locks it) is in excess too.
    """
    kept: list[int] = []
    rank = 0
    out = []
    for d in order:
        trial = kept + list(rows[d])
        r = _rank(motions[trial], tol) if motions.shape[1] else 0
        if r > rank:
            kept, rank = trial, r
        else:
            out.append(d)
    return out


@dataclass(frozen=True)
class DriveCheck:
    """The declared drives against the mobility.

    ``drives``: the driven joints (file order); ``mobility``: the useful mobility they
    are compared with; ``excess``: drives beyond it (their motion is fixed by the others);
    ``source``: where the mobility comes from (``"rank method"``, ``"formulas"`` or
    ``"kinematics"``).
    """

    drives: list[str]
    mobility: int
    excess: list[str]
    source: str

    @property
    def over_actuated(self) -> bool:
        return bool(self.excess)

    def text(self, fix: str | None = None) -> str:
        """One line: ``"2 drives (A, D) for mobility 1: drop `actuated: true` on D"``
        (``fix`` replaces the part after the colon); empty when no drive is in excess."""
        if not self.excess:
            return ""
        n = len(self.drives)
        what = f"{n} drive{'s' if n != 1 else ''} ({', '.join(self.drives)}) for mobility {self.mobility}"
        return f"{what}: {fix or 'drop `actuated: true` on ' + ', '.join(self.excess)}"

    def to_dict(self) -> dict[str, Any]:
        return {"drives": self.drives, "mobility": self.mobility, "excess": self.excess,
                "over_actuated": self.over_actuated, "source": self.source, "text": self.text() or None}


def drive_check_of_formulas(drives: list[str], mobility: Any) -> DriveCheck:
    """Without the geometry: the drives after the first ``mobility`` ones are in excess
    (the formulas cannot say which drives are independent, so the file's order decides)."""
    w = int(mobility) if isinstance(mobility, (int, float)) and mobility == mobility else len(drives)
    return DriveCheck(list(drives), w, list(drives[max(w, 0):]) if w >= 1 else [], "formulas")
