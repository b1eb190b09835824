"""Benchmark: nearest-descriptor retrieval of synth curve at a million curves.

Run from the repository root::

    python benchmarks/curve_retrieval.py --database DIR [--build] [--curves 1000000] [--queries 50]

With ``--build`` a database of real coupler curves is built first in ``DIR`` (the four-
and six-bar topologies, ``curves / 15`` each, through ``build_database``; resumable).
Measured: loading the descriptors, building the index (:class:`DescriptorIndex`: an
inverted file above 200,000 rows), the time of one retrieval as synth curve makes it
(the ``k = 300`` nearest of a descriptor and of its reversed-sense twin, one call), as
median and worst over the queries, and its recall against the exact answer (a flat
scan). Queries: the descriptors of closed coupler curves of random four-, six- and
eight-bars drawn by ``benchmarks/curve_synthesis.py``'s generator (not in the database)
and of the 26 capitals of DejaVu Sans. Times are wall-clock on the shared machine.
"""

from __future__ import annotations

import argparse
import string
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from mechsyn.synthesis.curves.database import build_database, load_database  # noqa: E402
from mechsyn.synthesis.curves.descriptors import fourier_descriptor, resample, swap_direction  # noqa: E402
from mechsyn.synthesis.curves.index import DescriptorIndex  # noqa: E402


def queries(n: int) -> np.ndarray:
    """Descriptors ``(2 m, D)``: each query curve and its reversed sense."""
    from curve_alphabet import letter_outline
    from curve_synthesis import random_linkage_curve

    curves = [letter_outline(ch) for ch in string.ascii_uppercase]
    rng = np.random.default_rng(41_000)
    while len(curves) < n:
        curves.append(random_linkage_curve(int(rng.choice([4, 6, 8])), rng))
    out = []
    for P in curves[:n]:
        d = fourier_descriptor(resample(np.asarray(P), 64, closed=True))
        out.append(np.stack([d, swap_direction(d)]))
    return np.array(out, np.float32)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--database", required=True)
    ap.add_argument("--build", action="store_true")
    ap.add_argument("--curves", type=int, default=1_000_000)
    ap.add_argument("--queries", type=int, default=50)
    ap.add_argument("-k", type=int, default=300)
    args = ap.parse_args()
    if args.build:
        t = time.perf_counter()
        build_database(args.database, max_links=6, per_topology=-(-args.curves // 15))
        print(f"built in {time.perf_counter() - t:.0f} s")
    t = time.perf_counter()
    db = load_database(args.database, max_links=6, build_if_missing=False)
    X = db.descriptors
    print(f"{len(X):,} curves ({X.shape[1]} numbers each) loaded in {time.perf_counter() - t:.1f} s")
    t = time.perf_counter()
    index = DescriptorIndex(X)
    print(f"index ({'exact' if index.exact else 'inverted file'}) built in {time.perf_counter() - t:.1f} s")
    import faiss

    flat = faiss.IndexFlatL2(X.shape[1])
    flat.add(np.ascontiguousarray(X))
    Q = queries(args.queries)
    times, recall = [], []
    for q in Q:
        t = time.perf_counter()
        ii = index.search(q, args.k)
        times.append(time.perf_counter() - t)
        _, jj = flat.search(q, args.k)
        recall.append(np.mean([len(set(a) & set(b)) / args.k for a, b in zip(ii, jj)]))
    times = np.array(times) * 1e3
    print(f"retrieval (k = {args.k}, both senses, one call) over {len(Q)} queries: median {np.median(times):.1f} ms, "
          f"worst {times.max():.1f} ms; recall@{args.k} against the exact scan: median {np.median(recall):.3f}, "
          f"worst {min(recall):.3f}")


if __name__ == "__main__":
    main()
