"""Paper 000, structural part: groups of links to attach to an adaptive finger.

A base mechanism of mobility ``W0`` driven by ``A`` actuators is completed by a group of
``n_f`` links and ``P_f`` lower pairs so that, with its variable-length links locked, it is
fully actuated:

1. ``W0 = 3n - 2 P5 - P4`` of the base;
2. the group's mobility ``W_f = -(W0 - A)``;
3. integer solutions of ``W_f = 3 n_f - 2 P_f``: ``P_f = (3 n_f - W_f) / 2``;
4. free leashes of the group ``m_f = P_f - (n_f - 1)``;
5. the base needs ``m_0 = 2 (W0 - 1)`` free leashes;
6. conditions: ``P_f >= 2 (W0 - 1) + (n_f - 1)`` and ``m_f >= m_0``.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class GroupRow:
    """One candidate group: ``n_f`` links, ``P_f`` pairs, ``m_f`` free leashes."""

    n_f: int
    P_f: int
    m_f: int
    meets_conditions: bool
    P_f_expression: str


@dataclass(frozen=True)
class GroupTable:
    """Paper 000's table of attachable groups for a base of mobility ``W0``."""

    W0: int
    actuators: int
    W_f: int
    m_0: int
    rows: list[GroupRow]
    no_solution: list[int] = field(default_factory=list)

    def to_dict(self) -> dict:
        return {
            "W0": self.W0, "actuators": self.actuators, "W_f": self.W_f, "m_0": self.m_0,
            "rows": [{"n_f": r.n_f, "P_f": r.P_f, "m_f": r.m_f, "meets_conditions": r.meets_conditions,
                      "P_f_expression": r.P_f_expression} for r in self.rows],
            "no_integer_solution": self.no_solution,
        }


def group_table(W0: int, actuators: int = 1, max_links: int = 5) -> GroupTable:
    """Groups ``(n_f, P_f)`` with ``n_f = 1..max_links`` for a base of mobility ``W0`` (paper 000).

    Examples
    --------
    >>> [(r.n_f, r.P_f, r.m_f) for r in group_table(2, 1, 5).rows]
    [(1, 2, 2), (3, 5, 3), (5, 8, 4)]
    """
    W_f = -(W0 - actuators)
    m_0 = 2 * (W0 - 1)
    rows, none = [], []
    for n_f in range(1, max_links + 1):
        twice = 3 * n_f - W_f
        if twice % 2:
            none.append(n_f)
            continue
        P_f = twice // 2
        m_f = P_f - (n_f - 1)
        ok = P_f >= 2 * (W0 - 1) + (n_f - 1) and m_f >= m_0 and P_f >= 0
        rows.append(GroupRow(n_f, P_f, m_f, ok, f"P_f = (3·{n_f} - ({W_f}))/2 = {P_f}"))
    return GroupTable(W0=W0, actuators=actuators, W_f=W_f, m_0=m_0, rows=rows, no_solution=none)
