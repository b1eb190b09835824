"""Helpers for the kinematics tests."""

from pathlib import Path

import numpy as np

import pytest

from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.kinematics.plane import cos_sin, perp, rotate

EX = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture
def ex():
    """Load an example file by its path under examples/."""
    def load(rel: str):
        return load_mechanism(EX / rel)
    return load


def point_state(S, q, qd, qdd, i, s):
    """Position, velocity and acceleration (N, 2) of the local point ``s`` on link ``i`` of
    ``S`` (-1: the frame) over the poses ``q`` and their rates, one point on its own:
    ``P = r + A s``, ``v = r' + w R90 A s``, ``a = r'' + alpha R90 A s - w^2 A s`` (the
    tests' oracle of the library's batched point states, the same arithmetic)."""
    if i < 0:
        z = np.zeros((q.shape[0], 2))
        return z + rotate(*cos_sin(np.zeros(q.shape[0])), s), z, z
    As = rotate(*cos_sin(q[:, 3 * i + 2]), s)
    w, al = qd[:, 3 * i + 2], qdd[:, 3 * i + 2]
    return (q[:, 3 * i:3 * i + 2] + As, qd[:, 3 * i:3 * i + 2] + w[:, None] * perp(As),
            qdd[:, 3 * i:3 * i + 2] + al[:, None] * perp(As) - (w ** 2)[:, None] * As)


def fourbar_dict(a=1.0, b=3.5, c=3.0, g=4.0, theta=60.0, branch=1, extra=None):
    """A four-bar (crank a, coupler b, rocker c, frame g) assembled at crank angle theta."""
    A = np.array([0.0, 0.0])
    D = np.array([g, 0.0])
    B = a * np.array([np.cos(np.radians(theta)), np.sin(np.radians(theta))])
    d = D - B
    L = np.linalg.norm(d)
    aa = (b ** 2 - c ** 2 + L ** 2) / (2 * L)
    h = np.sqrt(b ** 2 - aa ** 2)
    e = d / L
    C = B + aa * e + branch * h * np.array([-e[1], e[0]])
    data = {
        "name": "four-bar", "kind": "planar", "ground": "frame",
        "links": ["frame", "crank", "coupler", "rocker"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "point": A.tolist(), "actuated": True},
            {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": B.tolist()},
            {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": C.tolist()},
            {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": D.tolist()},
        ],
        "points": {"M": {"link": "coupler", "at": (B + 0.5 * (C - B) + [0.3, 0.8]).tolist()}},
    }
    if extra:
        data.update(extra)
    return data


def fourbar(**kw):
    return mechanism_from_dict(fourbar_dict(**kw), "fourbar")


def driven_planar_examples():
    """(name, mechanism) of every bundled planar example with a drive (files that are not
    mechanisms, such as arms and cases, left out)."""
    import mechsyn as ms
    from mechsyn.model.mechanism import Mechanism

    out = []
    for name in ms.examples.names():
        try:
            m = ms.examples.load(name)
        except Exception:  # noqa: BLE001  (not a mechanism file)
            continue
        if isinstance(m, Mechanism) and m.kind == "planar" and any(j.actuated for j in m.joints):
            out.append((name, m))
    return out
