# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Cooperative positioning of a robot group (Hirose, Nagata and Kurazume): standing robots
measure the bearings of a moving one and triangulate it; the group takes turns to advance."""

from __future__ import annotations

from kiseki.coop.positioning import (
    ANGLE_SIGMA,
    FORMS,
    GOAL,
    START,
    Move,
    Plan,
    paper_angle,
    plan,
)
from kiseki.coop.simulation import CoopRun, CoopRun3D, simulate, simulate_3d
from kiseki.coop.triangulation import (
    MIN_INTERSECTION_ANGLE,
    paper_error,
    paper_position,
    triangulate,
)

__all__ = [
    "ANGLE_SIGMA",
    "FORMS",
    "GOAL",
    "MIN_INTERSECTION_ANGLE",
    "START",
    "CoopRun",
    "CoopRun3D",
    "Move",
    "Plan",
    "paper_angle",
    "paper_error",
    "paper_position",
    "plan",
    "simulate",
    "simulate_3d",
    "triangulate",
]
