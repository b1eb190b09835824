"""The Assur-group engines' public names in one place (the closed-form kinematics of
mechanisms of drivers and dyads): the plan and its decomposition
(:mod:`mechsyn.kinematics.groups`), the generic group steps
(:mod:`mechsyn.kinematics.positions`), the driver-R + RRR chain
(:mod:`mechsyn.kinematics.chain`) and branch tracking (:mod:`mechsyn.kinematics.tracking`).
Code of the package imports those modules directly; this module keeps ``dyads.decompose``,
``dyads.solve_tracked`` and the other public names for callers outside it.
"""

from __future__ import annotations

from mechsyn.kinematics.groups import Plan, Step, circle_circle, decompose
from mechsyn.kinematics.positions import TrackedPositions, solve_positions
from mechsyn.kinematics.chain import chain_poses, solve_all, tracked_pass
from mechsyn.kinematics.sweep import REGULAR_DISC
from mechsyn.kinematics.tracking import BRANCHED, SINGULAR_DISC, solve_tracked, solve_tracked_rates

__all__ = [
    "Plan", "Step", "circle_circle", "decompose", "solve_positions", "chain_poses",
    "tracked_pass", "solve_all", "BRANCHED", "REGULAR_DISC", "SINGULAR_DISC",
    "TrackedPositions", "solve_tracked", "solve_tracked_rates"
]
