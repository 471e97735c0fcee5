# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Building occupancy maps from scans and poses (`kiseki.mapping.build`): the map size limits,
the log-odds map builder, local scan maps and the endpoint agreement of scans with a map.
``from kiseki.mapping import build_map`` is the one import path; the module holds the code."""

from __future__ import annotations

from kiseki.mapping.build import (
    MAX_MAP_CELLS,
    MIN_MAP_SIDE,
    MapBuildConfig,
    build_map,
    check_map_poses,
    check_map_size,
    endpoint_agreement,
    map_of_log,
    scan_local_builder,
    scan_local_map,
)

__all__ = [
    "MAX_MAP_CELLS",
    "MIN_MAP_SIDE",
    "MapBuildConfig",
    "build_map",
    "check_map_poses",
    "check_map_size",
    "endpoint_agreement",
    "map_of_log",
    "scan_local_builder",
    "scan_local_map",
]
