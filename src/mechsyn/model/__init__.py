"""The mechanism model: the bottom layer every analysis reads (it imports no other part
of mechsyn but :mod:`mechsyn.errors`).

* :mod:`~mechsyn.model.mechanism`: the one frozen :class:`Mechanism` (links, joints,
  named points, contours, states, external constraints) and its facades
  ``analyze``/``simulate``/``forces`` (they import the analyses when called);
* :mod:`~mechsyn.model.pairs`: the catalogue of kinematic pairs (Artobolevsky's classes);
* :mod:`~mechsyn.model.contour`: the contours (closed loops) of the link graph.

Files become mechanisms in :mod:`mechsyn.io`; the layers above are listed in
``tests/test_layout.py`` (``LAYERS``).
"""

from mechsyn.model.mechanism import (
    ExternalSpec,
    Joint,
    Link,
    Mechanism,
    PointSpec,
    StateSpec,
)
from mechsyn.model.pairs import PAIR_KINDS, PairKind, canonical_pair_type

__all__ = [
    "ExternalSpec", "Joint", "Link", "Mechanism", "PointSpec", "StateSpec",
    "PAIR_KINDS", "PairKind", "canonical_pair_type",
]
