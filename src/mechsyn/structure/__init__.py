"""Structural analysis: mobility formulas, the rank method, Assur groups, remedies.

* :mod:`~mechsyn.structure.formulas`: the classic structural formulas (Chebyshev,
  Malyshev, Somov-Malyshev, ...) with the numbers substituted;
* :mod:`~mechsyn.structure.analysis`: the papers' per-contour analysis
  (:func:`analyze_structure`), with :mod:`~mechsyn.structure.contours` (independent
  contours) and :mod:`~mechsyn.structure.external` (external constraints of variable-structure mechanisms);
* :mod:`~mechsyn.structure.rank`: exact mobility from the joints' geometry (screw-theory
  rank), on :mod:`~mechsyn.structure.screws` (pair twists, linear algebra) and
  :mod:`~mechsyn.structure.idle` (idle mobilities);
* :mod:`~mechsyn.structure.compare`: the formulas beside the rank method, remedies
  re-checked;
* :mod:`~mechsyn.structure.remedies`: pair-class changes that remove redundant
  constraints and idle mobilities;
* :mod:`~mechsyn.structure.assur`: Assur group decomposition;
* :mod:`~mechsyn.structure.report`: :func:`mechsyn.analyze`, the one call behind
  ``mechsyn analyze`` (:class:`~mechsyn.structure.report.StructureReport`).

It reads :mod:`mechsyn.model` and never the kinematics (the layers: ``tests/test_layout.py``).
"""

from mechsyn.structure.analysis import StructuralAnalysis, analyze_structure
from mechsyn.structure.contours import independent_contours

__all__ = ["StructuralAnalysis", "analyze_structure", "independent_contours"]
