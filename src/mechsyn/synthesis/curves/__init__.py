"""Curve to mechanism: type and dimensional synthesis of 4-, 6- and 8-bar linkages
that trace a drawn curve (retrieval from a local curve database, then least-squares
refinement). Modules: ``topologies`` (candidates from the atlas), ``descriptors``
(invariant Fourier descriptors, closed-form alignment), ``database`` (build / load),
``index`` (nearest descriptors, Faiss), ``target`` (CSV, JSON, SVG targets), ``fitting``
(the error measure, bounds, the least-squares problem), ``frame`` (the working frame),
``candidates`` (the answer and its ranking), ``synthesis`` (:func:`synthesize_curve`, the
anytime search); figures in :mod:`mechsyn.plot.curves`.
"""

from typing import Any

__all__ = ["synthesize_curve", "CurveSynthesisResult", "read_target", "build_database", "load_database"]


def __getattr__(name: str) -> Any:  # lazy: importing the package stays cheap
    if name in ("synthesize_curve", "CurveSynthesisResult"):
        from mechsyn.synthesis.curves import synthesis

        return getattr(synthesis, name)
    if name == "read_target":
        from mechsyn.synthesis.curves.target import read_target

        return read_target
    if name in ("build_database", "load_database"):
        from mechsyn.synthesis.curves import database

        return getattr(database, name)
    raise AttributeError(name)
