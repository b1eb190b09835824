"""Equivalence check of a kinematics refactoring: every planar example, perturbed copies,
seven input grids and both change-point modes, recorded on one version of the code and
compared with another (positions, rates, angles to 1e-12 relative; events identical).

Run from the repository root::

    python benchmarks/kinematics_equivalence.py record /tmp/kin-baseline.pkl   # on the old code
    python benchmarks/kinematics_equivalence.py check /tmp/kin-baseline.pkl    # on the new code

``record`` stores, for every sweep, the simulation's point and link arrays, the assembled
mask, the events and the method, or the one-line refusal (a ``MechsynInputError``);
``check`` recomputes them and lists every difference (exit 1 when one is found). A
perturbed copy moves every joint point by up to 2 % of the mechanism's size (each link's
dimensions come from its drawn joint points, so the copy is a consistent mechanism).
"""

from __future__ import annotations

import argparse
import pickle
import re
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import mechsyn as ms  # noqa: E402
from mechsyn.errors import MechsynInputError  # noqa: E402
from mechsyn.kinematics.analysis import simulate  # noqa: E402
from mechsyn.kinematics.system import build_system  # noqa: E402
from mechsyn.model.mechanism import Mechanism  # noqa: E402

REL = 1e-12
COPIES = 3


def _grids(u0: float, kind: str, size: float) -> list[np.ndarray]:
    """Seven input grids around the drawn value ``u0`` (degrees for R, length for P)."""
    if kind == "R":
        return [np.arange(0.0, 361.0, 1.0), u0 + np.arange(-30.0, 30.5, 0.5), np.arange(360.0, -1.0, -3.0),
                u0 + 720 + np.arange(0.0, 361.0, 7.0), np.array([u0 + 10.0]), np.array([u0 - 5.0, u0 + 5.0]),
                np.arange(-180.0, 541.0, 2.5)]
    h = 0.3 * size
    return [u0 + np.linspace(-h, h, 121), u0 + np.linspace(h, -h, 61), u0 + np.linspace(0, h, 41),
            u0 + np.linspace(-h, 0, 41), np.array([u0 + 0.1 * h]), np.array([u0 - 0.1 * h, u0 + 0.1 * h]),
            u0 + np.linspace(-2 * h, 2 * h, 201)]


def _size(m) -> float:
    pts = np.array([j.point for j in m.joints if j.point is not None and len(j.point) == 2], float)
    return float(np.ptp(pts, axis=0).max()) if len(pts) else 1.0


def _mechanisms() -> list[tuple[str, object]]:
    out = []
    for name in ms.examples.names():
        try:
            m = ms.examples.load(name)
        except Exception:  # noqa: BLE001  (a non-mechanism example)
            continue
        if not isinstance(m, Mechanism) or m.kind != "planar" or not any(j.actuated for j in m.joints):
            continue
        out.append((name, m))
        size = _size(m)
        rng = np.random.default_rng(len(out))
        for c in range(COPIES):
            moved = {j.id: np.asarray(j.point, float) + rng.uniform(-0.02, 0.02, 2) * size for j in m.joints
                     if j.type == "R" and j.point is not None and len(j.point) == 2}
            joints = tuple(replace(j, point=moved[j.id]) if j.id in moved else j for j in m.joints)
            out.append((f"{name}~{c}", m.with_joints(joints)))
    return out


def _cases():
    for name, m in _mechanisms():
        drivers = [j for j in m.joints if j.actuated]
        size = _size(m)
        try:
            S = build_system(m)
            u0 = {d.joint: (np.degrees(d.assembled) if d.type == "R" else d.assembled) for d in S.drivers}
            types = {d.joint: d.type for d in S.drivers}
        except Exception as e:  # noqa: BLE001
            yield f"{name}", m, None, repr(e)
            continue
        first = drivers[0].id
        for g, grid in enumerate(_grids(u0[first], types[first], size)):
            inputs = {first: grid}
            for d in drivers[1:]:
                if d.id in u0:
                    inputs[d.id] = np.full(len(grid), u0[d.id])
            for mode in ("keep", "switch"):
                yield f"{name} grid {g} {mode}", m, (inputs, mode), None


def _run(m, inputs, mode) -> dict:
    try:
        s = simulate(m, inputs, change_points=mode)
    except MechsynInputError as e:
        return {"error": str(e)}
    return {"assembled": s.assembled.copy(), "method": s.method, "events": s.events,
            "points": {k: (p.position, p.velocity, p.acceleration) for k, p in s.points.items()},
            "links": {k: (v.angle, v.angular_velocity, v.angular_acceleration) for k, v in s.links.items()}}


def _where(message: str | None) -> str | None:
    """A refusal's message with the checkout's path taken out (``/any/checkout/examples/x``
    -> ``examples/x``): a baseline recorded in another checkout says the same."""
    return None if message is None else re.sub(r"(?<![\w.])/\S*?/(?=examples/)", "", message)


def _arrays_equal(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.asarray(a, float), np.asarray(b, float)
    if a.shape != b.shape or not np.array_equal(np.isnan(a), np.isnan(b)):
        return False
    ok = ~np.isnan(a)
    if not ok.any():
        return True
    scale = max(1.0, float(np.abs(a[ok]).max()))
    return bool(np.all(np.abs(a[ok] - b[ok]) <= REL * scale))


def _events_equal(e1: list, e2: list) -> bool:
    if len(e1) != len(e2):
        return False
    for x, y in zip(e1, e2):
        if set(x) != set(y):
            return False
        for k in x:
            if k == "input" and isinstance(x[k], dict):
                if set(x[k]) != set(y[k]) or not all(abs(x[k][j] - y[k][j]) <= REL * max(1.0, abs(x[k][j]))
                                                     for j in x[k]):
                    return False
            elif isinstance(x[k], float):
                if abs(x[k] - y[k]) > REL * max(1.0, abs(x[k])):
                    return False
            elif x[k] != y[k]:
                return False
    return True


def compare(old: dict, new: dict) -> list[str]:
    """What differs between two records of one sweep (empty when equal)."""
    if "error" in old or "error" in new:
        return [] if _where(old.get("error")) == _where(new.get("error")) else [f"error {old.get('error')!r} -> {new.get('error')!r}"]
    out = []
    if not np.array_equal(old["assembled"], new["assembled"]):
        out.append("assembled")
    if old["method"] != new["method"]:
        out.append(f"method {old['method']} -> {new['method']}")
    if not _events_equal(old["events"], new["events"]):
        out.append("events")
    for group in ("points", "links"):
        if set(old[group]) != set(new[group]):
            out.append(f"{group} names")
            continue
        for k in old[group]:
            for a, b, what in zip(old[group][k], new[group][k], ("0", "1", "2")):
                if not _arrays_equal(a, b):
                    out.append(f"{group} {k} [{what}]")
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("action", choices=("record", "check"))
    ap.add_argument("path")
    args = ap.parse_args()
    if args.action == "record":
        rec = {}
        for key, m, case, err in _cases():
            rec[key] = {"error": err} if case is None else _run(m, *case)
        Path(args.path).write_bytes(pickle.dumps(rec))
        print(f"{len(rec)} sweeps recorded ({sum('error' in r for r in rec.values())} refusals)")
        return 0
    old = pickle.loads(Path(args.path).read_bytes())
    bad, n = 0, 0
    for key, m, case, err in _cases():
        new = {"error": err} if case is None else _run(m, *case)
        n += 1
        if key not in old:
            print(f"{key}: not in the record")
            bad += 1
            continue
        diff = compare(old[key], new)
        if diff:
            bad += 1
            print(f"{key}: {', '.join(diff)}")
    print(f"{n} sweeps compared, {bad} differ")
    return 1 if bad or n != len(old) else 0


if __name__ == "__main__":
    sys.exit(main())
