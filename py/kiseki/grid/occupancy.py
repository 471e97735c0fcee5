# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Occupancy grids in the ROS convention (int8 cells: 0 free, 100 occupied, -1 unknown).

``OccupancyGrid`` is implemented in C++ (OpenCV storage). ``grid.cells`` is a writable numpy
view of the cells without a copy, indexed ``[y, x]`` with row 0 at the map origin (as in the
ROS message, not as in the image file). Cell values outside -1..100 are refused by the
constructors (and by ``save_map``); writes through the ``cells`` view are not checked. Ray
casting (``cast_ray``, ``cells_on_ray``, ``cast_scans``), the distance field and local windows
are methods of the grid.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from kiseki._core import FREE, OCCUPIED, UNKNOWN, OccupancyGrid
from kiseki._support.counts import check_count
from kiseki._support.options import BEAM_LIMIT

__all__ = ["FREE", "OCCUPIED", "UNKNOWN", "OccupancyGrid", "beam_angles", "grid_summary"]


def beam_angles(count: int, field_of_view: float, start: float | None = None) -> np.ndarray:
    """Evenly spaced beam angles (radians) covering ``field_of_view`` with both ends included,
    starting at ``start`` (default ``-field_of_view / 2``)."""
    count = check_count(count, "beam count", 1, BEAM_LIMIT)
    fov_ok = isinstance(field_of_view, numbers.Real) and not isinstance(field_of_view, bool)
    # a scanner covers at most one turn (100 rad put every beam on 16 turns)
    if not fov_ok or not 0 < field_of_view <= 2 * math.pi + 1e-9:
        raise ValueError(f"field of view must be in (0, 2 pi] rad, got {field_of_view!r}")
    start_ok = isinstance(start, numbers.Real) and not isinstance(start, bool)
    if start is not None and not (start_ok and math.isfinite(start)):
        raise ValueError(f"start must be a finite angle in rad, got {start!r}")
    first = -field_of_view / 2 if start is None else start
    if count == 1:
        return np.array([first])
    return first + np.arange(count) * (field_of_view / (count - 1))


def grid_summary(grid: OccupancyGrid) -> dict[str, float | int]:
    """Size, extent and cell counts of a grid."""
    if not isinstance(grid, OccupancyGrid):  # None was "no attribute 'cells'"
        raise TypeError(f"grid must be a kiseki OccupancyGrid, got {type(grid).__name__}")
    cells = grid.cells
    return {
        "width": grid.width,
        "height": grid.height,
        "resolution": grid.resolution,
        "origin_x": grid.origin.x,
        "origin_y": grid.origin.y,
        "origin_yaw": grid.origin.theta,
        "size_x_m": grid.width * grid.resolution,
        "size_y_m": grid.height * grid.resolution,
        "free": int(np.count_nonzero(cells == FREE)),
        "occupied": int(np.count_nonzero(cells == OCCUPIED)),
        "unknown": int(np.count_nonzero(cells < 0)),
        "intermediate": int(np.count_nonzero((cells > 0) & (cells < 100))),
    }
