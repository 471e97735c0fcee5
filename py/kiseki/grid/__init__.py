# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Occupancy grids (`kiseki.grid.occupancy`): the grid type of the C++ core, its cell values,
beam angles and a grid's summary. ``from kiseki.grid import OccupancyGrid`` is the one import
path; the module holds the code."""

from __future__ import annotations

from kiseki.grid.occupancy import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    OccupancyGrid,
    beam_angles,
    grid_summary,
)

__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "OccupancyGrid", "beam_angles", "grid_summary"]
