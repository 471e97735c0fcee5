# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The rubble paper's loop (paper 003, Fig. 1): take a local map (S-DEM) at a stop, move, take
another, estimate the motion by the correlation search (eq. 4), and merge the new local map into
the global map at the estimated pose.

Frames. Each sweep comes with the gyro's attitude (roll, pitch, yaw) of the sensor. A sweep's
S-DEM is built *levelled*: its points are turned by Ry(pitch) Rx(roll), so its frame has z up
and x along the sensor's heading ("the attitude from the 3-axis gyro is compensated, not
searched"). Between two levelled S-DEMs only the heading changes, by the gyro's yaw difference;
the search finds the translation in the previous levelled frame (the paper's box: x 0..70 cm
forward, y -50..50 cm, z -30..30 cm) and the world position advances by it turned by the
previous yaw. The global map is an OctoMap OcTree (C++ ``kiseki/terrain/global_map.hpp``)
filled with each sweep's points (after the range cut, before plane removal) at the estimated
pose. Nothing here uses the simulator: sweeps are ranges and attitudes, from a log or a scene.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Literal

import numpy as np

from kiseki import _core
from kiseki._support.field_types import check_field_types
from kiseki._support.real_numbers import check_number
from kiseki.core import check_seed, derive_seed, rotation_zyx
from kiseki.terrain.correlation import SearchResult, correlation_search, search_grid
from kiseki.terrain.plane_removal import HoughParams, PclParams, remove_planes
from kiseki.terrain.sdem import PAPER_GRID, SphereElevationMap, sdem_from_points, sdem_from_ranges

__all__ = ["MapperConfig", "SdemMapper", "Sweep"]


@dataclass(frozen=True)
class MapperConfig:
    """removal: plane removal before matching (``hough`` the paper's, ``pcl``, ``none``); search:
    ``exhaustive`` (the paper's) or ``coarse-to-fine`` (the default, what ``kiseki terrain run``
    runs: 42 ms a pair of sweeps against the exhaustive search's second, and the exhaustive minimum
    on 12 of 12 simulated pairs, README; the experiments set theirs); cost: ``sum`` (eq. 4 as
    printed, the default) or ``mean`` (kiseki's named variant: the sum over the summed weights, so
    that sharing fewer cells is not rewarded; kiseki.terrain.correlation); the search box (m) and
    step; voxel: the global map's resolution (m); seed: PCL's RANSAC (the only random part)."""

    removal: Literal["hough", "pcl", "none"] = "hough"
    search: Literal["exhaustive", "coarse-to-fine"] = "coarse-to-fine"
    cost: Literal["sum", "mean"] = "sum"
    x: tuple[float, float] = (0.0, 0.70)
    y: tuple[float, float] = (-0.50, 0.50)
    z: tuple[float, float] = (-0.30, 0.30)
    step: float = 0.02
    voxel: float = 0.05
    hough: HoughParams = field(default_factory=HoughParams)
    pcl: PclParams = field(default_factory=PclParams)
    seed: int = 0

    def __post_init__(self) -> None:
        check_field_types(self)
        if self.removal not in ("hough", "pcl", "none"):
            raise ValueError(f"removal must be hough, pcl or none, got {self.removal!r}")
        if self.search not in ("exhaustive", "coarse-to-fine"):
            raise ValueError(f"search must be exhaustive or coarse-to-fine, got {self.search!r}")
        if self.cost not in ("sum", "mean"):
            raise ValueError(f"cost must be sum (eq. 4) or mean, got {self.cost!r}")
        check_number(self.voxel, "voxel", 0.005, 10.0, unit="m")
        check_seed(self.seed)
        search_grid(self.x, self.y, self.z, self.step)  # raises for a bad box

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class Sweep:
    """What the mapper keeps of one stop: the levelled S-DEM before and after plane removal,
    the estimated sensor pose (4x4, world from sensor), and the search that placed it (None
    for the first)."""

    sdem: SphereElevationMap
    kept: SphereElevationMap
    pose: np.ndarray
    search: SearchResult | None


def _attitude(rpy: Any) -> tuple[float, float, float]:
    a = np.asarray(rpy, dtype=float)
    if a.shape != (3,) or not np.isfinite(a).all():
        raise ValueError(f"attitude: expected finite (roll, pitch, yaw) in rad, got {rpy!r}")
    return float(a[0]), float(a[1]), float(a[2])


class SdemMapper:
    """Feed sweeps with :meth:`add`; the estimated poses and the global map grow."""

    def __init__(self, config: MapperConfig | None = None, start: Any = (0.0, 0.0, 0.0)) -> None:
        self.config = config or MapperConfig()
        p0 = np.asarray(start, dtype=float)
        if p0.shape != (3,) or not np.isfinite(p0).all():
            raise ValueError(f"start: expected a finite sensor position (x, y, z), got {start!r}")
        self._start = p0
        self._grid = search_grid(self.config.x, self.config.y, self.config.z, self.config.step)
        self.global_map = _core.GlobalVoxelMap(self.config.voxel, PAPER_GRID.max_range)
        self.sweeps: list[Sweep] = []
        self._yaw: float | None = None

    def add(self, ranges: Any, attitude_rpy: Any) -> np.ndarray:
        """One stop: ranges (151, 181) of the tilting laser (NaN where nothing was hit) and the
        gyro's (roll, pitch, yaw) in rad. Returns the estimated sensor pose (4x4)."""
        roll, pitch, yaw = _attitude(attitude_rpy)
        raw = sdem_from_ranges(ranges)
        points, _ = raw.to_points()
        levelled = sdem_from_points(points, rotation_zyx(0.0, pitch, roll))
        k = len(self.sweeps)
        removal = remove_planes(
            levelled, self.config.removal, self.config.hough, self.config.pcl,
            derive_seed(self.config.seed, k),
        )  # fmt: skip
        if removal.kept.valid_cells == 0:
            raise ValueError(f"sweep {k}: nothing is left after plane removal")
        if k == 0:
            position, search = self._start.copy(), None
        else:
            prev = self.sweeps[-1]
            turn = rotation_zyx(yaw - self._yaw)
            search = correlation_search(
                prev.kept, removal.kept, turn, self._grid, self.config.search, self.config.cost,
            )  # fmt: skip
            if not search.found:
                raise ValueError(f"sweep {k}: no candidate shares enough cells with sweep {k - 1}")
            position = prev.pose[:3, 3] + rotation_zyx(self._yaw) @ search.translation
        pose = np.eye(4)
        pose[:3, :3] = rotation_zyx(yaw, pitch, roll)
        pose[:3, 3] = position
        self.global_map.insert(points, pose)
        self._yaw = yaw
        self.sweeps.append(Sweep(levelled, removal.kept, pose, search))
        return pose

    @property
    def positions(self) -> np.ndarray:
        """(k, 3) estimated sensor positions."""
        return np.array([s.pose[:3, 3] for s in self.sweeps]).reshape(-1, 3)
