# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Sphere digital elevation maps (S-DEM) of the rubble paper (``003_fd335d240f62896b.txt``,
sec. 4): the range r(theta, phi) seen from the sensor on 1 deg cells, tilt theta -120..30 deg
(rows, theta < 0 looks down), scan angle phi -90..90 deg (columns), ranges below 5 m only.

A cell's point is eq. 2 with the printed ``y = r sin(theta)`` read as ``sin(phi)``:
``x = r cos th cos ph, y = r sin ph, z = r sin th cos ph`` (sensor frame x forward, y left, z
up; the sign of z follows eq. 3, see :mod:`kiseki.sim.tilting_laser`), and a point goes back
by eq. 3. The C++ core does the work (``kiseki/terrain/sphere_elevation_map.hpp``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from kiseki import _core
from kiseki._support.real_numbers import check_number
from kiseki.core import rotation_zyx

__all__ = [
    "PAPER_GRID",
    "SphereElevationMap",
    "SphereGrid",
    "attitude_matrix",
    "sdem_from_points",
    "sdem_from_ranges",
    "sdem_median",
    "sdem_points",
    "sphere_grid",
]

SphereGrid = _core.SphereGrid
SphereElevationMap = _core.SphereElevationMap


def sphere_grid(
    theta_deg: tuple[float, float] = (-120.0, 30.0),
    phi_deg: tuple[float, float] = (-90.0, 90.0),
    step_deg: float = 1.0,
    max_range: float = 5.0,
) -> SphereGrid:
    """The S-DEM's cells (the paper's by default: 151 x 181 cells of 1 deg, r < 5 m). Raises
    ValueError naming the field for a bad range, step or reach."""
    grid = _core.SphereGrid()
    try:
        grid.theta_min_deg, grid.theta_max_deg = (float(v) for v in theta_deg)
        grid.phi_min_deg, grid.phi_max_deg = (float(v) for v in phi_deg)
        grid.step_deg, grid.max_range = float(step_deg), float(max_range)
    except (TypeError, ValueError) as e:
        raise ValueError(f"sphere_grid: expected numbers, {e}") from None
    grid.validate()
    return grid


PAPER_GRID = sphere_grid()
"""The paper's grid (sec. 4.1)."""


def attitude_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """R = Rz(yaw) Ry(pitch) Rx(roll), angles in rad (the gyro's attitude: from the sensor
    frame to the level frame). Raises ValueError for a non-finite angle (a failed gyro)."""
    for name, value in (("roll", roll), ("pitch", pitch), ("yaw", yaw)):
        check_number(value, f"attitude: {name}")
    return rotation_zyx(float(yaw), float(pitch), float(roll))


def _grid(grid: SphereGrid | None) -> SphereGrid:
    if grid is None:
        return PAPER_GRID
    if not isinstance(grid, _core.SphereGrid):
        raise TypeError(f"grid: expected a SphereGrid, got {type(grid).__name__}")
    return grid


def sdem_from_ranges(ranges: Any, grid: SphereGrid | None = None) -> SphereElevationMap:
    """An S-DEM from a (rows, cols) array of ranges (a tilting-laser sweep, NaN where nothing
    was hit); ranges at or beyond the grid's reach, <= 0 or NaN are no data. Raises ValueError
    for a wrong shape and for a sweep with no range within the limits."""
    grid = _grid(grid)
    m = SphereElevationMap.from_ranges(grid, ranges)
    if m.valid_cells == 0:
        raise ValueError(
            f"S-DEM: the sweep has no range within 0..{grid.max_range:g} m"
            " (empty or all out of limits)"
        )
    return m


def sdem_from_points(
    points: Any, attitude: Any = None, grid: SphereGrid | None = None
) -> SphereElevationMap:
    """An S-DEM from (n, 3) points in the sensor frame, each first turned by ``attitude`` (3x3,
    the gyro's compensation; None: level). The nearest point of a cell is kept. Raises
    ValueError for NaN points or attitude, and when no point lies within the grid."""
    grid = _grid(grid)
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) == 0:
        raise ValueError(f"S-DEM points: expected a non-empty (n, 3) array, got shape {pts.shape}")
    m = SphereElevationMap.from_points(grid, pts, attitude)
    if m.valid_cells == 0:
        raise ValueError(
            f"S-DEM: none of the {len(pts)} points lies within the grid and {grid.max_range:g} m"
        )
    return m


def sdem_median(sweeps: Sequence[SphereElevationMap]) -> SphereElevationMap:
    """The cell-wise median of sweeps (the paper: "the median of three measurements"); a cell
    with data in fewer than half of them is empty."""
    sweeps = list(sweeps)
    if not sweeps or not all(isinstance(s, SphereElevationMap) for s in sweeps):
        raise ValueError("S-DEM median: expected one or more SphereElevationMaps")
    return SphereElevationMap.median(sweeps)


def sdem_points(sdem: SphereElevationMap) -> tuple[np.ndarray, np.ndarray]:
    """(points (n, 3) by eq. 2, their cell indices (n,), row-major theta by phi)."""
    return sdem.to_points()
