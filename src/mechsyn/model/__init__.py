"""The mechanism model: links, kinematic pairs and their catalogue, the link graph."""

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
