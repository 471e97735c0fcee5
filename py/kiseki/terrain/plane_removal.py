# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Plane removal before matching (paper 003 sec. 5.1): walls and ceilings carry no features and
much data, so they are taken out and the floor's irregularities are matched.

* ``"hough"``: the paper's method: in each tilt scan a plane is a straight line, found by a
  Hough transform on the scan's points and removed (C++ ``kiseki/terrain/hough_line_removal.hpp``);
* ``"pcl"``: 3-D planes with PCL: normals by ``pcl::NormalEstimation``, then
  ``pcl::SACSegmentationFromNormals`` with a normal-plane model, repeated
  (``kiseki/terrain/pcl_plane_removal.hpp``); RANSAC is seeded;
* ``"none"``: nothing removed (the paper's corridor case).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Literal

import numpy as np

from kiseki import _core
from kiseki.core import check_seed
from kiseki.terrain.sdem import SphereElevationMap

__all__ = ["METHODS", "HoughParams", "PclParams", "PlaneRemoval", "remove_planes"]

METHODS = ("hough", "pcl", "none")
Method = Literal["hough", "pcl", "none"]


@dataclass(frozen=True)
class HoughParams:
    """The Hough transform per tilt scan: bins of 1 deg and 3 cm; a point within 3 cm of the
    refitted line is on it; a line needs 30 points (30 cells of 1 deg: a wall seen over 30 deg
    of scan, or 0.5 m of wall at 1 m); at most 8 lines per scan. The paper gives no values;
    3 cm is six times the laser's 5 mm noise, so a flat wall's points all fall within it."""

    angle_step_deg: float = 1.0
    rho_step: float = 0.03
    inlier_distance: float = 0.03
    min_votes: int = 30
    max_lines: int = 8

    def core(self) -> _core.HoughLineParams:
        p = _core.HoughLineParams()
        for k, v in asdict(self).items():
            setattr(p, k, v)
        p.validate()
        return p


@dataclass(frozen=True)
class PclParams:
    """PCL planes: 3 cm inliers (as the Hough's), normals from 12 neighbours weighted 0.1,
    planes of at least 400 points (a wall patch of about 0.2 m^2 at 2 m), at most 8 planes, 500
    RANSAC iterations each."""

    distance: float = 0.03
    normal_weight: float = 0.1
    normal_neighbours: int = 12
    min_inliers: int = 400
    max_planes: int = 8
    max_iterations: int = 500

    def core(self) -> _core.PclPlaneParams:
        p = _core.PclPlaneParams()
        for k, v in asdict(self).items():
            setattr(p, k, v)
        p.validate()
        return p


@dataclass(frozen=True)
class PlaneRemoval:
    """The map without the removed cells, which cells were removed (rows, cols), and how many
    lines (Hough, summed over the scans) or planes (PCL) were found; ``planes`` holds PCL's
    plane coefficients (k, 4) as a x + b y + c z + d = 0 (empty for the others)."""

    kept: SphereElevationMap
    removed: np.ndarray
    found: int
    method: str
    planes: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))

    @property
    def kept_share(self) -> float:
        before = self.kept.valid_cells + int(self.removed.sum())
        return self.kept.valid_cells / before if before else 0.0


def remove_planes(
    sdem: SphereElevationMap,
    method: Method = "hough",
    hough: HoughParams | None = None,
    pcl: PclParams | None = None,
    seed: int = 0,
) -> PlaneRemoval:
    """Removes planes from an S-DEM with ``method`` (see the module). Raises ValueError for an
    unknown method or bad parameters."""
    if not isinstance(sdem, SphereElevationMap):
        raise TypeError(f"remove_planes: expected a SphereElevationMap, got {type(sdem).__name__}")
    if method not in METHODS:
        raise ValueError(f"plane removal method must be one of {METHODS}, got {method!r}")
    seed = check_seed(seed)
    grid = sdem.grid
    if method == "none":
        return PlaneRemoval(sdem, np.zeros((grid.rows, grid.cols), dtype=bool), 0, method)
    if method == "hough":
        kept, removed, lines = _core.remove_lines_hough(sdem, (hough or HoughParams()).core())
        return PlaneRemoval(kept, removed, int(lines), method)
    points, cells = sdem.to_points()
    mask, planes, _ = _core.remove_planes_pcl(points, (pcl or PclParams()).core(), seed)
    removed = np.zeros(grid.rows * grid.cols, dtype=bool)
    removed[cells[mask]] = True
    ranges = sdem.ranges.reshape(-1)
    ranges[removed] = np.nan
    kept = SphereElevationMap.from_ranges(grid, ranges.reshape(grid.rows, grid.cols))
    return PlaneRemoval(kept, removed.reshape(grid.rows, grid.cols), len(planes), method, planes)
