# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Teaching and playback for factory AGVs (the teaching-and-playback thesis): local maps, the
environment map built while the robot is pushed along a route, waypoints, and playback with the
space-observation-model particle filter."""

from __future__ import annotations

from kiseki.teach.local_maps import METHODS, LocalMapMaker
from kiseki.teach.playback import PlaybackConfig, PlaybackResult, playback
from kiseki.teach.teaching import TeachResult, teach

__all__ = [
    "METHODS",
    "LocalMapMaker",
    "PlaybackConfig",
    "PlaybackResult",
    "TeachResult",
    "playback",
    "teach",
]
