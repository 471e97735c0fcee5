# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Teaching and playback for factory AGVs (the teaching-and-playback thesis): local maps, the
environment map built while the robot is pushed along a route, waypoints, and the log of a
playback with the space-observation-model particle filter. The simulated teaching and playback
runs that drive a scene are the app tier's, in `kiseki.apps.teach`."""

from __future__ import annotations

from kiseki.teach.local_maps import METHODS, LocalMapMaker

__all__ = ["METHODS", "LocalMapMaker"]
