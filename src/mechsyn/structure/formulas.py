"""The classic structural formulas, each with the numbers substituted as the papers print them.

Every function returns a :class:`Formula`: the value and the expression, e.g.
``W = 6·7 - 3·2 - 4·1 - 5·6 + 1 = 3``.

Sources: Chebyshev (1869); Grübler's form as written in paper 002; Malyshev and
Somov-Malyshev (with Reshetov's redundant-constraint term) as in paper 003; Gokhman's
number of contours and Ozol's redundant constraints as in paper 002.

References
----------
.. [1] "Rational structural synthesis of schemes of crank-slider mechanisms of gripping
   devices" (in Ukrainian, with an English abstract) ("paper 002"; see docs/references.md).
.. [2] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Formula:
    """A formula's value (``None`` where it does not apply), its substituted expression and
    its reading: ``"planar"`` (3 freedoms per free link, 3 closure equations per contour),
    ``"spatial"`` (6 and 6) or ``"topology"`` (counts of links, pairs and contours only)."""

    value: float | int | None
    expression: str
    reading: str = ""


def _fmt(x: float | int) -> str:
    if isinstance(x, float) and x.is_integer():
        x = int(x)
    return f"{x:g}" if isinstance(x, float) else str(x)


def _terms(counts: dict[int, int], weight: dict[int, int] | None = None) -> str:
    """`` - 3·2 - 4·1`` for ``{3: 2, 4: 1}`` (class·count, ascending class)."""
    out = ""
    for i, p in sorted(counts.items()):
        if p:
            out += f" - {(weight or {}).get(i, i)}·{p}"
    return out


def _signed(x: int | float) -> str:
    return f" + {_fmt(x)}" if x >= 0 else f" - {_fmt(-x)}"


def chebyshev(n: int, p5: int, p4: int) -> Formula:
    """Chebyshev (1869), planar: ``W = 3n - 2 p5 - p4``."""
    w = 3 * n - 2 * p5 - p4
    return Formula(w, f"W = 3·{n} - 2·{p5} - {p4} = {w}", "planar")


def grubler(N: int, p5: int, p4: int) -> Formula:
    """Grübler, planar, ``N`` counting the frame (paper 002): ``W = 3(N - 1) - 2 p5 - p4``."""
    w = 3 * (N - 1) - 2 * p5 - p4
    return Formula(w, f"W = 3({N} - 1) - 2·{p5} - {p4} = {w}", "planar")


def malyshev(n: int, pairs_by_class: dict[int, int]) -> Formula:
    """Malyshev, spatial: ``W = 6n - Σ_{i=1..5} i·p_i``."""
    w = 6 * n - sum(i * p for i, p in pairs_by_class.items())
    return Formula(w, f"W = 6·{n}{_terms(pairs_by_class)} = {w}", "spatial")


def somov_malyshev(n: int, pairs_by_class: dict[int, int], s_sum: int, g_sum: int | float) -> Formula:
    """Somov-Malyshev with Reshetov's term, per-contour form of paper 003.

    ``W = 6n - Σ i·p_i + S_Σ + G_Σ`` with ``S_Σ`` the structural and ``G_Σ`` the
    constructive redundancy (both zero terms omitted from the expression).
    """
    w = 6 * n - sum(i * p for i, p in pairs_by_class.items()) + s_sum + g_sum
    w = int(w) if float(w).is_integer() else w
    extra = (_signed(s_sum) if s_sum else "") + (_signed(g_sum) if g_sum else "")
    return Formula(w, f"W = 6·{n}{_terms(pairs_by_class)}{extra} = {_fmt(w)}", "spatial")


def redundant_from_mobility(W: int, n: int, pairs_by_class: dict[int, int], planar: bool = False) -> Formula:
    """Somov-Malyshev solved for the redundant constraints: ``S = W - 6n + Σ i·p_i``.

    For a planar mechanism (``planar``): ``S = W - 3n + 2 p5 + p4``.
    """
    if planar:
        p5, p4 = pairs_by_class.get(5, 0), pairs_by_class.get(4, 0)
        s = W - 3 * n + 2 * p5 + p4
        return Formula(s, f"S = {W} - 3·{n} + 2·{p5} + {p4} = {s}", "planar")
    s = W - 6 * n + sum(i * p for i, p in pairs_by_class.items())
    terms = "".join(f" + {i}·{p}" for i, p in sorted(pairs_by_class.items()) if p)
    return Formula(s, f"S = {W} - 6·{n}{terms} = {s}", "spatial")


def gokhman(n: int, pairs_total: int) -> Formula:
    """Gokhman: number of independent contours ``K = Σ p_i - n``."""
    k = pairs_total - n
    return Formula(k, f"K = {pairs_total} - {n} = {k}", "topology")


def scheme_check(N: int, K: int, pairs_total: int) -> Formula:
    """Check of a drawn structural scheme (paper 002): ``p = N + K - 1``."""
    rhs = N + K - 1
    ok = rhs == pairs_total
    return Formula(int(ok), f"p = N + K - 1: {pairs_total} {'=' if ok else '≠'} {N} + {K} - 1 = {rhs}", "topology")


def ozol(W: int, K: int, freedoms: list[int], planar: bool = False) -> Formula:
    """Ozol (paper 002): redundant constraints ``q = W + 6K - f``, ``f = Σ`` pair freedoms.

    In the plane the contour closes 3 equations: ``q = W + 3K - f``.
    """
    lam = 3 if planar else 6
    f = sum(freedoms)
    q = W + lam * K - f
    counts: dict[int, int] = {}
    for x in freedoms:
        counts[x] = counts.get(x, 0) + 1
    f_expr = " + ".join(f"{c}·{x}" for x, c in sorted(counts.items()))
    return Formula(q, f"q = {W} + {lam}·{K} - {f} = {q} (f = {f_expr or 0})", "planar" if planar else "spatial")
