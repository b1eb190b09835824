"""Structural analysis: mobility formulas, per-contour analysis, remedies, external constraints."""

from mechsyn.structure.analysis import StructuralAnalysis, analyze_structure
from mechsyn.structure.contours import independent_contours

__all__ = ["StructuralAnalysis", "analyze_structure", "independent_contours"]
