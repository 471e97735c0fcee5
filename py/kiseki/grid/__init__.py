# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Occupancy grids (`kiseki.grid.occupancy`): the grid type of the C++ core, its cell values,
beam angles and a grid's summary; ray casters for many rays per map (`kiseki.grid.casters`).
``from kiseki.grid import OccupancyGrid`` is the one import path; the modules hold the code."""

from __future__ import annotations

from kiseki.grid.casters import (
    DEFAULT_RAY_CASTER,
    RAY_CASTERS,
    RangeCaster,
    SectorCaster,
    ray_caster,
)
from kiseki.grid.occupancy import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    OccupancyGrid,
    beam_angles,
    grid_summary,
)

__all__ = [
    "DEFAULT_RAY_CASTER",
    "FREE",
    "OCCUPIED",
    "RAY_CASTERS",
    "UNKNOWN",
    "OccupancyGrid",
    "RangeCaster",
    "SectorCaster",
    "beam_angles",
    "grid_summary",
    "ray_caster",
]
