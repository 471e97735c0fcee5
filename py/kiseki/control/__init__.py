# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Control: following a path. Teaching, playback and the simulator drive their robots with the
same follower; navigators are arbitrated by priority (PriorityArbiter) and steer by PD
(PdSteering); control imports nothing of the methods above it nor of the simulator."""

from __future__ import annotations

from kiseki.control.arbitration import PriorityArbiter
from kiseki.control.fuzzy_potential import FuzzyPotentialConfig, FuzzyPotentialMethod
from kiseki.control.pd_steering import PdSteering
from kiseki.control.pure_pursuit import PurePursuit
from kiseki.control.speed_limit import SpeedLimit, SpeedLimitSource

__all__ = [
    "FuzzyPotentialConfig",
    "FuzzyPotentialMethod",
    "PdSteering",
    "PriorityArbiter",
    "PurePursuit",
    "SpeedLimit",
    "SpeedLimitSource",
]
