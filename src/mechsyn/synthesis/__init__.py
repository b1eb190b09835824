"""Synthesis of mechanisms: which links and joints (structural), which dimensions
(dimensional), which linkage traces a drawn curve, which finger grips; and the workflows
of the command line built on them.

The package's entry points are listed in ``__all__`` and imported on first use, so
``import mechsyn.synthesis`` loads no solver; each comes from the module named below.

Structural (number and type) synthesis
    :mod:`~mechsyn.synthesis.chains`
        link assortments and the non-isomorphic planar chains of ``n`` links
        (:func:`synthesize_chains`, :class:`KinematicChain`), streamed to a file with resume;
    :mod:`~mechsyn.synthesis.contracted`
        the contracted multigraphs the enumeration starts from;
    :mod:`~mechsyn.synthesis.canonical`
        canonical certificates and automorphisms of coloured graphs (bliss or nauty);
    :mod:`~mechsyn.synthesis.mechanisms`
        from a chain to mechanisms: frame and input choices up to symmetry
        (:func:`distinct_mechanisms`), a drawing, a mechanism file;
    :mod:`~mechsyn.synthesis.atlas`
        the atlas report of all of it (:func:`chain_atlas`).

Dimensional synthesis
    :mod:`~mechsyn.synthesis.problem`
        what every synthesis shares: :class:`SynthesisResult`, the seed convention,
        :class:`Progress` for ``progress(state)``;
    :mod:`~mechsyn.synthesis.cases`
        the case files of path generation (:func:`load_cases`) and of any mechanism
        file (:func:`load_mechanism_case`); no solver runs there;
    :mod:`~mechsyn.synthesis.fourbar`
        closed-form four-bar and slider-crank positions, vectorised;
    :mod:`~mechsyn.synthesis.path`, :mod:`~mechsyn.synthesis.optimize`
        four-bar path generation: the objective and its constraints, then the
        multi-start global search and polish (:func:`synthesize_path`);
    :mod:`~mechsyn.synthesis.exact`
        precision positions in closed form: Freudenstein function generation and
        Burmester motion generation (:func:`motion_synthesis`);
    :mod:`~mechsyn.synthesis.designs`, :mod:`~mechsyn.synthesis.general`,
    :mod:`~mechsyn.synthesis.general_batch`
        path and motion generation for any planar mechanism file
        (:func:`synthesize_mechanism`): design vectors, engine evaluation, population
        evaluation through the batch kinematics;
    :mod:`~mechsyn.synthesis.export`
        synthesised four-bars as mechanism files.

Curve to mechanism: :mod:`mechsyn.synthesis.curves`
    type and dimensional synthesis of 4-, 6- and 8-bar linkages tracing a drawn curve
    (:func:`synthesize_curve`): topologies from the atlas, Fourier descriptors, a local
    curve database, least-squares refinement.

Adaptive fingers (paper 000): :mod:`mechsyn.synthesis.finger`
    fingers made fully actuated by an attached group (:func:`synthesize_fingers`) and
    the parametric design of a finger with variable-length links (:func:`design_finger`).

Workflows: :mod:`~mechsyn.synthesis.reports`
    the synthesis commands of the CLI as library calls (:func:`path_synthesis`,
    :func:`mechanism_synthesis`, :func:`motion_report`): budgets checked, margins and
    stopping errors chosen, mechanism files for the designs found.

Examples
--------
>>> import mechsyn.synthesis as syn
>>> [c.assortment_label() for c in syn.synthesize_chains(6)]   # Watt and Stephenson chains
['4B 2T', '4B 2T']
>>> syn.synthesize_path.__module__
'mechsyn.synthesis.optimize'

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import importlib
from typing import Any

#: public name -> module that defines it (imported on first use)
_LAZY: dict[str, str] = {
    # structural
    "synthesize_chains": "mechsyn.synthesis.chains", "KinematicChain": "mechsyn.synthesis.chains",
    "distinct_mechanisms": "mechsyn.synthesis.mechanisms", "chain_atlas": "mechsyn.synthesis.atlas",
    # dimensional
    "SynthesisResult": "mechsyn.synthesis.problem", "Progress": "mechsyn.synthesis.problem",
    "load_cases": "mechsyn.synthesis.cases", "load_mechanism_case": "mechsyn.synthesis.cases",
    "synthesize_path": "mechsyn.synthesis.optimize", "motion_synthesis": "mechsyn.synthesis.exact",
    "synthesize_mechanism": "mechsyn.synthesis.general",
    # curves, fingers
    "synthesize_curve": "mechsyn.synthesis.curves.synthesis",
    "synthesize_fingers": "mechsyn.synthesis.finger.candidates", "design_finger": "mechsyn.synthesis.finger.design",
    # workflows
    "path_synthesis": "mechsyn.synthesis.reports", "mechanism_synthesis": "mechsyn.synthesis.reports",
    "motion_report": "mechsyn.synthesis.reports",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_LAZY[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
