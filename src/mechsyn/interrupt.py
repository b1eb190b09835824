"""Keeping the best result of a search when the user interrupts it (Ctrl-C).

A search wraps its fitness in :class:`BestSoFar`; when :class:`KeyboardInterrupt` arrives
(from the terminal's SIGINT, or raised by a progress callback) the search returns the
best candidate evaluated so far, marked ``interrupted=True``, instead of losing it. The
command line writes that result as usual, prints ``interrupted`` and exits with 130.

Examples
--------
>>> import numpy as np
>>> best = BestSoFar()
>>> f = best.wrap(lambda X: np.sum(X ** 2, axis=1))
>>> _ = f(np.array([[1.0, 1.0], [0.5, 0.0], [2.0, 0.0]]))
>>> best.x.tolist(), best.f
([0.5, 0.0], 0.25)
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

__all__ = ["BestSoFar", "INTERRUPT_EXIT_CODE"]

#: Exit status of a command stopped by Ctrl-C (128 + SIGINT, the shell convention).
INTERRUPT_EXIT_CODE = 130


class BestSoFar:
    """The lowest-scored candidate a vectorised fitness has evaluated.

    Attributes
    ----------
    x : numpy.ndarray or None
        The best candidate (a copy), ``None`` before the first evaluation.
    f : float
        Its score (``inf`` before the first evaluation).
    """

    def __init__(self) -> None:
        self.x: np.ndarray | None = None
        self.f: float = float("inf")

    def offer(self, X: np.ndarray, F: np.ndarray) -> None:
        """Consider the rows of ``X`` scored ``F`` (NaN scores are ignored)."""
        F = np.asarray(F, float).reshape(-1)
        if F.size == 0 or not np.any(np.isfinite(F)):
            return
        i = int(np.nanargmin(np.where(np.isfinite(F), F, np.inf)))
        if F[i] < self.f:
            self.f = float(F[i])
            self.x = np.array(np.atleast_2d(X)[i], dtype=float, copy=True)

    def wrap(self, fitness: Callable[[np.ndarray], np.ndarray]) -> Callable[[np.ndarray], np.ndarray]:
        """``fitness`` (rows of candidates to scores) that also records the best row."""

        def recorded(X: np.ndarray) -> np.ndarray:
            F = fitness(X)
            self.offer(X, F)
            return F

        return recorded
