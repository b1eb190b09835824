"""Nearest-descriptor retrieval for the curve database (Faiss).

:class:`DescriptorIndex` finds the ``k`` stored descriptors nearest (Euclidean) to a
query. Up to :data:`EXACT_UP_TO` rows the search is exact (``faiss.IndexFlatL2``, a
brute-force scan: a few milliseconds at 100,000 rows of 20 numbers); above it, an
inverted-file index (``faiss.IndexIVFFlat``: ``sqrt(n)`` k-means cells, trained once on
a fixed sample, :data:`N_PROBE` cells visited per query) keeps a query at a million
curves within milliseconds (``benchmarks/curve_retrieval.py``: median 2.4 ms). Searches
run on one thread: for a few queries OpenMP's threads cost more than they give.

Faiss (J. Johnson, M. Douze and H. Jégou, "Billion-scale similarity search with GPUs",
*IEEE Transactions on Big Data* 7(3), 535-547, 2021) is chosen over hnswlib and usearch:
it installs from PyPI as a wheel on Linux, macOS and Windows (hnswlib ships only a source
archive, last released in 2023, and needs a compiler), its inverted-file index built a
million real curve descriptors in 21 s on one thread of a loaded 2-core machine where a
graph index (HNSW, both others) took 105 s for 100,000, and with one thread the built
index and every answer are
deterministic.
"""

from __future__ import annotations

import numpy as np

__all__ = ["DescriptorIndex", "EXACT_UP_TO", "N_PROBE"]

EXACT_UP_TO = 200_000   # rows searched exactly (a flat scan); more: an inverted-file index
N_PROBE = 48            # cells of the inverted file visited per query
TRAIN_PER_CELL = 64     # training sample: this many descriptors per cell (fixed rows)


class DescriptorIndex:
    """The ``k`` nearest rows of a descriptor matrix ``(n, D)`` (float32).

    >>> rng = np.random.default_rng(0)
    >>> X = rng.random((500, 20), dtype=np.float32)
    >>> idx = DescriptorIndex(X)
    >>> idx.exact, idx.search(X[[7, 42]], 1)[:, 0].tolist()
    (True, [7, 42])
    """

    def __init__(self, descriptors: np.ndarray):
        import faiss

        X = np.ascontiguousarray(descriptors, dtype=np.float32)
        self.n, d = X.shape
        self.exact = self.n <= EXACT_UP_TO
        threads = faiss.omp_get_max_threads()
        faiss.omp_set_num_threads(1)   # one thread: the k-means cells, hence the answers, repeat exactly
        try:
            if self.exact:
                self._index = faiss.IndexFlatL2(d)
            else:
                cells = int(np.sqrt(self.n))
                self._quantizer = faiss.IndexFlatL2(d)
                self._index = faiss.IndexIVFFlat(self._quantizer, d, cells)
                step = max(1, self.n // (TRAIN_PER_CELL * cells))
                self._index.train(X[::step])
                self._index.nprobe = N_PROBE
            self._index.add(X)
        finally:
            faiss.omp_set_num_threads(threads)

    def search(self, queries: np.ndarray, k: int) -> np.ndarray:
        """Row indices ``(m, k)`` of the nearest descriptors to each query, nearest first
        (fewer than ``k`` rows: all of them; an inverted file's missing ones dropped)."""
        import faiss

        q = np.ascontiguousarray(np.atleast_2d(queries), dtype=np.float32)
        threads = faiss.omp_get_max_threads()
        faiss.omp_set_num_threads(1)   # a few queries: threads cost more than they give (70 ms against 2 at load)
        try:
            _, ii = self._index.search(q, min(k, self.n))
        finally:
            faiss.omp_set_num_threads(threads)
        return ii
