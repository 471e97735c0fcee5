# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""3-D localization and mapping in rubble (paper 003): sphere elevation maps (S-DEM) from a
tilting laser, plane removal (the paper's Hough lines per tilt scan, or PCL's 3-D planes), the
correlation search over virtual S-DEMs (eq. 4), the loop that merges local maps into an OctoMap
(:mod:`kiseki.terrain.mapper`), and PCL's ICP and GICP as baselines."""

from __future__ import annotations

from kiseki.terrain.baselines import Registration, register_pcl
from kiseki.terrain.correlation import (
    PAPER_SEARCH,
    SearchGrid,
    SearchResult,
    correlation_search,
    search_grid,
)
from kiseki.terrain.plane_removal import (
    METHODS,
    HoughParams,
    PclParams,
    PlaneRemoval,
    remove_planes,
)
from kiseki.terrain.sdem import (
    PAPER_GRID,
    SphereElevationMap,
    SphereGrid,
    attitude_matrix,
    sdem_from_points,
    sdem_from_ranges,
    sdem_median,
    sdem_points,
    sphere_grid,
)

__all__ = [
    "METHODS",
    "PAPER_GRID",
    "PAPER_SEARCH",
    "HoughParams",
    "PclParams",
    "PlaneRemoval",
    "Registration",
    "SearchGrid",
    "SearchResult",
    "SphereElevationMap",
    "SphereGrid",
    "attitude_matrix",
    "correlation_search",
    "register_pcl",
    "remove_planes",
    "sdem_from_points",
    "sdem_from_ranges",
    "sdem_median",
    "sdem_points",
    "search_grid",
    "sphere_grid",
]
