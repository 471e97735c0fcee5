# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Speed limits (paper 004): occlusion- and width-aware limits, the baselines they are compared
with, and the navigator that drives a robot under a limit. Imports control, never the
simulator."""

from __future__ import annotations

from kiseki.speed.acceleration import AccelerationLimit
from kiseki.speed.along_log import LimitsAlongLog, limits_along_log, motion_headings
from kiseki.speed.baselines import (
    DistanceLimiterConfig,
    DistanceSpeedLimiter,
    PolygonLimiterConfig,
    PolygonSpeedLimiter,
)
from kiseki.speed.limiter import (
    LimitTerms,
    SpeedLimiter,
    SpeedLimiterConfig,
    occlusion_labels,
    occlusion_ratio,
    passage_width,
    width_factor,
)
from kiseki.speed.navigator import NavigatorLog, SpeedControlledNavigator, scan_about_body

__all__ = [
    "AccelerationLimit",
    "DistanceLimiterConfig",
    "DistanceSpeedLimiter",
    "LimitTerms",
    "LimitsAlongLog",
    "NavigatorLog",
    "PolygonLimiterConfig",
    "PolygonSpeedLimiter",
    "SpeedControlledNavigator",
    "SpeedLimiter",
    "SpeedLimiterConfig",
    "limits_along_log",
    "motion_headings",
    "occlusion_labels",
    "occlusion_ratio",
    "passage_width",
    "scan_about_body",
    "width_factor",
]
