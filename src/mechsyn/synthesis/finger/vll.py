"""Variable-length links (VLL) of paper 000's adaptive fingers: the cylinder-piston pair
of a VLL, the locked (fully actuated) model and the working-region test, in NumPy.

A VLL is a P pair between a *cylinder* link (pivoted at ``K``) and a *piston* link
(pivoted at ``L``, the P pair's point); locked, the two are one rigid binary link.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import numpy as np

from mechsyn.errors import MechsynInputError

__all__ = ["vll_ends", "locked_model", "points_in_region", "region_excess", "copy_mechanism"]


def copy_mechanism(d: dict) -> dict:
    """A copy of a mechanism file dict for this package's edits, without a deep copy:
    every link, joint, point and load entry is a new dict and joint points and point
    coordinates are new lists; the other values are shared (the edits here replace them,
    never change them in place).

    Examples
    --------
    >>> d = {"links": ["f", {"name": "c", "mass": 1.0}], "joints": [{"id": "A", "point": [0, 0]}],
    ...      "points": {"tip": {"link": "c", "at": [1, 2]}}}
    >>> e = copy_mechanism(d)
    >>> e["joints"][0]["point"][0] = 5.0; e["points"]["tip"]["at"][1] = 7.0; e["links"][1]["mass"] = 2.0
    >>> d["joints"][0]["point"], d["points"]["tip"]["at"], d["links"][1]["mass"]
    ([0, 0], [1, 2], 1.0)
    """
    out = dict(d)
    out["links"] = [dict(e) if isinstance(e, dict) else e for e in d["links"]]
    out["joints"] = [dict(j, point=list(j["point"])) if j.get("point") is not None else dict(j)
                     for j in d["joints"]]
    if d.get("points"):
        out["points"] = {k: dict(p, at=list(p["at"])) for k, p in d["points"].items()}
    if d.get("loads"):
        out["loads"] = [dict(ld) for ld in d["loads"]]
    return out


def vll_ends(md: dict, jid: str, src: str = "<case>") -> tuple[str, str, str, str]:
    """(cylinder link, piston pivot joint L, cylinder pivot joint K, piston link) of a VLL."""
    joints = md["joints"]
    j = next(x for x in joints if x["id"] == jid)
    cyl, pis = j["links"]
    k_j = [x for x in joints if cyl in x["links"] and x["id"] != jid]
    l_j = [x for x in joints if pis in x["links"] and x["id"] != jid]
    if len(k_j) != 1 or len(l_j) != 1 or k_j[0]["type"] != "R" or l_j[0]["type"] != "R" \
            or np.linalg.norm(np.subtract(l_j[0]["point"], j["point"])) > 1e-9:
        raise MechsynInputError(f"VLL {jid}: expected a cylinder and a piston, each binary with one R "
                                "pivot, the P point at the piston's pivot", source=src, field=f"joints.{jid}")
    return cyl, l_j[0]["id"], k_j[0]["id"], pis


def _link_entry(d: dict, name: str) -> dict:
    for k, e in enumerate(d["links"]):
        if (e if isinstance(e, str) else e["name"]) == name:
            if isinstance(e, str):
                d["links"][k] = {"name": e}
            return d["links"][k]
    raise KeyError(name)


def locked_model(d: dict, vlls: list[str], source: str = "<case>") -> dict:
    """The fully actuated model: each locked VLL's cylinder and piston merged into one
    rigid binary link (mass summed, centre of mass mass-weighted; inertia summed about
    the combined centre, parallel-axis theorem)."""
    d = copy_mechanism(d)
    for jid in vlls:
        cyl, L, K, pis = vll_ends(d, jid, source)
        pts = {j["id"]: np.asarray(j["point"], float) for j in d["joints"]}
        ec, ep = _link_entry(d, cyl), _link_entry(d, pis)
        mc, mp = float(ec.get("mass") or 0.0), float(ep.get("mass") or 0.0)
        cc = np.asarray(ec.get("com", (pts[K] + pts[jid]) / 2), float)
        cp = np.asarray(ep.get("com", (pts[jid] + pts[L]) / 2), float)
        m = mc + mp
        if m > 0:
            com = (mc * cc + mp * cp) / m
            ec["mass"] = m
            ec["com"] = com.tolist()
            ec["inertia"] = float(ec.get("inertia") or 0.0) + float(ep.get("inertia") or 0.0) \
                + mc * float(np.sum((cc - com) ** 2)) + mp * float(np.sum((cp - com) ** 2))
        d["links"] = [e for e in d["links"] if (e if isinstance(e, str) else e["name"]) != pis]
        d["joints"] = [j for j in d["joints"] if j["id"] != jid]
        for j in d["joints"]:
            if j["id"] == L:
                j["links"] = [cyl if lk == pis else lk for lk in j["links"]]
        for p in (d.get("points") or {}).values():
            if p["link"] == pis:
                p["link"] = cyl
        for ld in d.get("loads") or []:
            if ld.get("link") == pis:
                ld["link"] = cyl
    return d


def points_in_region(P: np.ndarray, region: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Which points (N, 2) lie inside the polygon or within ``tol`` of its boundary (NaN rows:
    outside). Even-odd ray casting, vectorised over points and edges."""
    P = np.asarray(P, float).reshape(-1, 2)
    region = np.asarray(region, float)
    ok = np.all(np.isfinite(P), axis=1)
    out = np.zeros(len(P), bool)
    if not ok.any():
        return out
    Q = P[ok]
    a, b = region, np.roll(region, -1, axis=0)
    x, y = Q[:, :1], Q[:, 1:]
    crosses = (a[:, 1] > y) != (b[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    inside = np.count_nonzero(crosses & (x < xc), axis=1) % 2 == 1
    ab = b - a
    t = np.clip(np.einsum("nkj,kj->nk", Q[:, None] - a[None], ab) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0, 1)
    dist = np.linalg.norm(Q[:, None] - (a[None] + t[..., None] * ab[None]), axis=2).min(axis=1)
    out[ok] = inside | (dist <= tol)
    return out


def region_excess(P: np.ndarray, region: np.ndarray) -> float:
    """Sum of distances of the points outside the polygon to it (0 when all inside)."""
    inside = points_in_region(P, region)
    bad = P[~inside & np.all(np.isfinite(P), axis=1)]
    if not len(bad):
        return 0.0
    a, b = region, np.roll(region, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("nkj,kj->nk", bad[:, None] - a[None], ab) / np.sum(ab * ab, axis=1), 0, 1)
    proj = a[None] + t[..., None] * ab[None]
    return float(np.sum(np.min(np.linalg.norm(bad[:, None] - proj, axis=2), axis=1)))
