"""External constraints of a variable-structure mechanism (paper 002).

A gripper before clamping has internal constraints only; after clamping, the object
(an external body) is constrained by the jaws. Quantities:

- ``W_f``: mobility of the mechanism isolated from the object,
- ``W_rob``: working mobility with the external constraints on (0 when held),
- ``W_a``: mobilities the external body loses (6 for a free body),
- ``S_a``: external constraints, ``S_ai``: those that take the main mobility and at once
  fix the body.

External redundant constraints: ``σ_a = S_a - [(W_f - W_rob) + W_a - S_ai]``.
Whole system: ``σ = S - {[6(N - 1) - W_rob] + W_a - S_ai}``, ``S = S_i + S_a``,
``S_i`` the sum of the internal pairs' classes, ``N`` the links with the frame.

References
----------
.. [1] "Rational structural synthesis of schemes of crank-slider mechanisms of gripping
   devices" (in Ukrainian, with an English abstract) ("paper 002"; see docs/references.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from mechsyn.structure.formulas import Formula


@dataclass(frozen=True)
class ExternalAnalysis:
    """Paper 002's external-constraint balance of one state."""

    S_a: int
    W_f: int
    W_rob: int
    W_a: int
    S_ai: int
    S_i: int
    S: int
    N: int
    external_redundant: Formula
    system_redundant: Formula


def external_analysis(*, S_a: int, W_f: int, W_rob: int, W_a: int, S_ai: int, S_i: int, N: int,
                      lam: int = 6) -> ExternalAnalysis:
    """Evaluate paper 002's external and whole-system redundant constraints."""
    sigma_a = S_a - ((W_f - W_rob) + W_a - S_ai)
    ea = Formula(sigma_a, f"σ_a = {S_a} - [({W_f} - {W_rob}) + {W_a} - {S_ai}] = {sigma_a}")
    S = S_i + S_a
    sigma = S - ((lam * (N - 1) - W_rob) + W_a - S_ai)
    sa = Formula(
        sigma,
        f"σ = {S} - [{lam}({N} - 1) - {W_rob} + {W_a} - {S_ai}] = {sigma}  (S = S_i + S_a = {S_i} + {S_a})",
    )
    return ExternalAnalysis(S_a=S_a, W_f=W_f, W_rob=W_rob, W_a=W_a, S_ai=S_ai, S_i=S_i, S=S, N=N,
                            external_redundant=ea, system_redundant=sa)
