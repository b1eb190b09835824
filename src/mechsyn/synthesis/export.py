"""Synthesised linkages as mechanism files (issue-2 format)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.io import mechanism_from_dict
from mechsyn.results import dumps, write_atomic
from mechsyn.synthesis.fourbar import fourbar_position, rotate


def fourbar_mechanism_dict(
    r1: float, r2: float, r3: float, r4: float, theta2: float, *, branch: int = -1,
    rcx: float = 0.0, rcy: float = 0.0, x0: float = 0.0, y0: float = 0.0, theta0: float = 0.0,
    name: str = "Synthesised four-bar", point_name: str = "P",
) -> dict[str, Any]:
    """A four-bar as a mechanism-file dict, joint points at crank angle ``theta2``.

    Joints: ``A`` frame-crank at ``O2`` (actuated), ``B`` crank-coupler, ``C``
    coupler-rocker, ``D`` rocker-frame at ``O4``; the coupler point is ``points.P`` on the
    coupler (global coordinates in the same configuration). Raises
    :class:`~mechsyn.errors.MechsynInputError` (one line) where the four-bar does not
    assemble at ``theta2``.

    Examples
    --------
    >>> fourbar_mechanism_dict(4.0, 1.0, 3.5, 3.0, 0.0)["joints"][1]["point"]
    [1.0, 0.0]
    >>> fourbar_mechanism_dict(10.0, 1.0, 2.0, 2.0, 0.0)
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: theta2: the four-bar of ground 10, crank 1, coupler 2, rocker 2 does not assemble at crank angle 0 deg (fix: give a crank angle inside its working range, or lengths where the coupler and rocker can meet)
    """
    pose = fourbar_position(r1, r2, r3, r4, theta2, branch=branch, rcx=rcx, rcy=rcy, x0=x0, y0=y0, theta0=theta0)
    if not bool(pose.assembled):
        raise MechsynInputError(
            f"the four-bar of ground {r1:.6g}, crank {r2:.6g}, coupler {r3:.6g}, rocker {r4:.6g} does not assemble "
            f"at crank angle {np.degrees(theta2):.6g} deg", field="theta2",
            hint="give a crank angle inside its working range, or lengths where the coupler and rocker can meet")
    ox, oy = rotate(np.float64(r1), np.float64(0.0), theta0)
    o4 = [float(ox + x0), float(oy + y0)]

    def pt(a):
        return [float(a[0]), float(a[1])]

    return {
        "name": name,
        "kind": "planar",
        "ground": "frame",
        "links": ["frame", "crank", "coupler", "rocker"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [float(x0), float(y0)], "actuated": True},
            {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": pt(pose.A)},
            {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": pt(pose.B)},
            {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": o4},
        ],
        "points": {point_name: {"link": "coupler", "at": pt(pose.C)}},
    }


def mechanism_yaml(mech: dict[str, Any], header: str = "") -> str:
    """YAML text of a mechanism dict with an optional ``#`` comment header."""
    import yaml

    lines = "".join(f"# {h}\n" for h in header.splitlines()) if header else ""
    return lines + yaml.safe_dump(mech, sort_keys=False, default_flow_style=None)


def write_mechanism_file(mech: dict[str, Any], path, header: str = "") -> None:
    """Write a mechanism dict as YAML (``.yaml``/``.yml``) or JSON, atomically.

    The dict is validated by :func:`mechsyn.io.mechanism_from_dict` first; the YAML keeps
    a comment header (how the linkage was obtained).
    """
    path = Path(path)
    mechanism_from_dict(mech)
    if path.suffix.lower() == ".json":
        write_atomic(path, dumps(mech) + "\n")
    else:
        write_atomic(path, mechanism_yaml(mech, header))
