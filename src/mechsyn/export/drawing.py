"""A drawing of a mechanism at a pose with the paths of its points (SVG text)."""

from __future__ import annotations

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.export.svg import mechanism_svg
from mechsyn.kinematics.analysis import simulate
from mechsyn.kinematics.system import build_system
from mechsyn.model.mechanism import Mechanism

__all__ = ["drawing_of"]


def drawing_of(mech: Mechanism, pose: dict[str, float] | None = None, paths: list[str] | None = None,
               sweep: dict[str, np.ndarray] | None = None, dimensions: bool = False) -> str:
    """SVG of ``mech`` at ``pose`` (driven joint values; default: the file's configuration)
    with the ``paths`` of named points or joints over ``sweep`` (driven joint values).

    The pose is a step of the sweep when one is given (the nearest value of its first
    joint), so the drawn mechanism lies on the drawn paths.

    Examples
    --------
    >>> from mechsyn.io import load_mechanism
    >>> svg = drawing_of(load_mechanism("examples/kinematics/crank_rocker.yaml"), paths=["M"],
    ...                  sweep={"A": np.arange(0.0, 361.0, 10.0)})  # doctest: +SKIP
    """

    drivers = build_system(mech).drivers
    if not drivers:
        raise MechsynInputError("the mechanism has no driven joint to pose it", field="pose",
                                hint="mark a joint `actuated: true`")
    home = {d.joint: (np.degrees(d.assembled) if d.type == "R" else d.assembled) for d in drivers}
    pose = dict(pose or {})
    for j in pose:
        if j not in home:
            raise MechsynInputError(f"joint {j} is not driven", field="pose",
                                    hint=f"driven joints: {', '.join(home)}")
    if paths and not sweep:
        raise MechsynInputError("the paths need an input range", field="sweep",
                                hint="sweep the driven joint, e.g. A from 0 to 360 deg")
    if sweep:
        n = len(next(iter(sweep.values())))
        first = next(iter(sweep))
        inputs = {j: np.asarray(v, float) for j, v in sweep.items()}
        target = pose.get(first, home[first])
        k = int(np.argmin(np.abs(inputs[first] - target)))
        for j, v in pose.items():
            if j not in inputs:
                inputs[j] = np.full(n, v)
    else:
        inputs = {j: np.array([pose.get(j, home[j])]) for j in home}
        k = 0
    sim = simulate(mech, inputs, points=paths or None)
    if not sim.assembled[k]:
        raise MechsynInputError("the mechanism does not assemble at that pose", field="pose",
                                hint="choose an input inside its working range")
    return mechanism_svg(sim, k, paths, dimensions, title=mech.name)
