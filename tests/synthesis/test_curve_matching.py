"""The curve error's compiled correspondence in order (dynamic time warping from any start
of a closed curve) and matched segments, against plain definitions written out here."""

from __future__ import annotations

import numpy as np
import pytest

from mechsyn.synthesis.curves import _numba as compiled
from mechsyn.synthesis.curves.fitting import correspondence


def _dtw_by_definition(C: np.ndarray) -> tuple[float, np.ndarray]:
    """Least weighted sum over monotone paths (diagonal steps 2, others 1) over n + m, and
    the table of sums, cell by cell."""
    n, m = C.shape
    D = np.full((n, m), np.inf)
    for i in range(n):
        for j in range(m):
            if i == 0 and j == 0:
                D[i, j] = 2 * C[0, 0]
                continue
            D[i, j] = min(D[i - 1, j] + C[i, j] if i else np.inf, D[i, j - 1] + C[i, j] if j else np.inf,
                          D[i - 1, j - 1] + 2 * C[i, j] if i and j else np.inf)
    return D[-1, -1] / (n + m), D


@pytest.mark.parametrize("rows", [True, False])
def test_the_compiled_warping_costs_each_start_as_the_definition(rows):
    rng = np.random.default_rng(3)
    c = rng.random((9, 13))
    shifts = np.arange(c.shape[0] if rows else c.shape[1])
    got = compiled.costs(c, shifts, rows)
    for s in shifts:
        C = np.roll(c, -s, axis=0) if rows else np.roll(c, -s, axis=1)
        assert got[s] == pytest.approx(_dtw_by_definition(C)[0], rel=1e-12)


def test_the_compiled_path_is_monotone_and_sums_to_the_least_cost():
    rng = np.random.default_rng(4)
    c = rng.random((11, 7))
    i, j = compiled.pairs(c, 3, True)
    C = np.roll(c, -3, axis=0)
    assert (i[0], j[0], i[-1], j[-1]) == (0, 0, 10, 6)
    di, dj = np.diff(i), np.diff(j)
    assert np.all((di >= 0) & (dj >= 0) & (di + dj >= 1) & (di <= 1) & (dj <= 1))
    w = np.where((di == 1) & (dj == 1), 2.0, 1.0)          # each step weighs the cell it enters
    total = 2 * C[0, 0] + np.sum(w * C[i[1:], j[1:]])
    assert total / sum(C.shape) == pytest.approx(_dtw_by_definition(C)[0], rel=1e-12)


def test_a_turned_start_and_reversed_sense_are_found():
    t = np.linspace(0, 2 * np.pi, 24, endpoint=False)
    a = np.c_[np.cos(t), 0.5 * np.sin(t)]
    b = np.roll(a[::-1], 5, axis=0)
    c = np.linalg.norm(a[:, None] - b[None], axis=-1)
    W, (rev, _) = correspondence(c, True, True)
    assert rev and int(W.sum()) == 24 and np.all(c[W] < 1e-12)


@pytest.mark.parametrize("closed,k", [(True, 1), (True, 4), (False, 1), (False, 4)])
def test_the_nearest_matched_segment_is_the_nearest_beside_the_matched_samples(closed, k):
    rng = np.random.default_rng(5)
    n, m = 12, 10
    W = rng.random((n, m)) < 0.2
    W[np.arange(n), rng.integers(0, m, n)] = True
    D = rng.random((n, k * m if closed else k * (m - 1)))
    got = compiled.nearest_beside(D, W, closed, k)
    for r in range(n):
        beside = [s for s in range(D.shape[1])
                  if W[r, s // k] or W[r, (s // k + 1) % m if closed else s // k + 1]]
        assert got[r] == beside[int(np.argmin(D[r, beside]))]
