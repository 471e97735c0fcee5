# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Occupancy-grid mapping from scans taken at known poses: the log-odds inverse sensor model
(`build_map`), and the thesis' local map L of one scan (`scan_local_map`). The teaching map built
from logs by the thesis' merge rules is `kiseki.teach.environment_map.build_teaching_map`."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from tqdm import tqdm

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.real_arrays import real_array
from kiseki._support.real_numbers import check_number
from kiseki._support.schema import MAGNITUDE_LIMIT, parse
from kiseki.grid import OccupancyGrid
from kiseki.io.map_schema import MapBuildSettings
from kiseki.scans import LaserScans, check_max_range

__all__ = [
    "MAX_MAP_CELLS",
    "MIN_MAP_SIDE",
    "MapBuildConfig",
    "build_map",
    "check_map_poses",
    "check_map_size",
    "endpoint_agreement",
    "scan_local_builder",
    "scan_local_map",
]


MAX_MAP_CELLS = 10**8  # 100 M int8 cells (and as many float log-odds while building)
MIN_MAP_SIDE = 2  # cells: a map of one cell across says nothing


def check_map_size(width_m: float, height_m: float, resolution: float) -> tuple[int, int]:
    """The (width, height) in cells of a map of this extent, refused in one line when it has
    fewer than MIN_MAP_SIDE cells across or more than MAX_MAP_CELLS cells (limits stated)."""
    for name, v in (("width", width_m), ("height", height_m), ("resolution", resolution)):
        # 0 was a ZeroDivisionError, inf an OverflowError
        check_number(v, f"check_map_size: {name}", 0.0, low_open=True, unit="m")
    wide, high = width_m / resolution, height_m / resolution
    if not math.isfinite(wide * high):  # 1e300 m at 1e-300 m: math.ceil(inf) was an OverflowError
        raise ValueError(
            f"resolution {resolution:g} m makes a map of {wide:.3g} x {high:.3g} cells over "
            f"{width_m:.3g} x {height_m:.3g} m: more than the limit of {MAX_MAP_CELLS:.0e} cells"
        )
    width, height = math.ceil(wide), math.ceil(high)
    if min(width, height) < MIN_MAP_SIDE:
        raise ValueError(
            f"resolution {resolution:g} m makes a map of {width} x {height} cells over "
            f"{width_m:.3g} x {height_m:.3g} m: at least {MIN_MAP_SIDE} cells across are needed"
        )
    if width * height > MAX_MAP_CELLS:
        raise ValueError(
            f"resolution {resolution:g} m makes a map of {width} x {height} cells over "
            f"{width_m:.3g} x {height_m:.3g} m: more than the limit of {MAX_MAP_CELLS:.0e} cells"
        )
    return width, height


def check_map_poses(poses: np.ndarray) -> np.ndarray:
    """The sensor poses a map is built from, as a C-contiguous float64 (n, 3) array: at least
    one, finite, and within +-MAGNITUDE_LIMIT m (a map file's origin is bounded so: a map
    beyond it could be built but not saved)."""
    poses = np.ascontiguousarray(poses, dtype=np.float64)
    if poses.ndim != 2 or poses.shape[0] == 0:
        raise ValueError(f"poses: expected a non-empty (n, 3) array, got shape {poses.shape}")
    if poses.shape[1:] != (3,) or not np.isfinite(poses).all():
        raise ValueError(f"poses: expected (n, 3) rows x, y, theta, no NaN or inf: {poses.shape}")
    far = float(np.abs(poses[:, :2]).max())
    if far > MAGNITUDE_LIMIT:
        raise ValueError(
            f"the poses reach {far:.10g} m, beyond +-{MAGNITUDE_LIMIT:g} (a map there could not "
            "be saved)"
        )
    return poses


@dataclass(frozen=True)
class MapBuildConfig:
    """Parameters of map building. Units: metres; probabilities in (0, 1).

    The log-odds increments and clamping bounds are OctoMap's defaults (hit 0.7, miss 0.4,
    clamp 0.12 / 0.97); the trinary thresholds are the ROS map_server ones.
    """

    resolution: float = 0.05
    usable_range: float = 30.0  # free space is marked at most this far along a beam
    min_range: float = 0.0
    clear_on_no_return: bool = False  # do "no return" readings clear their beam? (see C++ doc)
    prob_hit: float = 0.7
    prob_miss: float = 0.4
    clamp_min: float = 0.12
    clamp_max: float = 0.97
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196
    margin: float = 1.0  # metres of unknown border around everything observed

    def to_dict(self) -> dict[str, float]:
        return asdict(self)

    @classmethod
    def from_dict(cls, values: dict, source: str = "map-building config") -> MapBuildConfig:
        """The config of a mapping of its parameters (unset ones keep their defaults), checked
        by :class:`kiseki.io.map_schema.MapBuildSettings`: a SchemaError (a ValueError) names
        ``source`` (the file), the key and the value."""
        settings = parse(MapBuildSettings, values, source)
        return cls(**{k: getattr(settings, k) for k in settings.model_fields_set})

    def core_params(self, max_range: float) -> _core.LogOddsParams:
        p = _core.LogOddsParams()
        for name in (
            "resolution",
            "usable_range",
            "min_range",
            "clear_on_no_return",
            "prob_hit",
            "prob_miss",
            "clamp_min",
            "clamp_max",
            "occupied_thresh",
            "free_thresh",
        ):
            setattr(p, name, getattr(self, name))
        p.max_range = float(max_range)
        p.validate()
        return p


def build_map(
    poses: np.ndarray,
    ranges: np.ndarray,
    angles: np.ndarray,
    max_range: float,
    config: MapBuildConfig | None = None,
    progress: bool = False,
    chunk: int = 100,
) -> OccupancyGrid:
    """Builds a trinary occupancy grid from scans (ranges (n, b)) taken at sensor poses
    (n, 3: x, y, theta) with beam angles (b,). Readings >= max_range are "no return"; NaN
    readings (no measurement) say nothing and are skipped; a negative reading is an error, as
    is a pose that is not finite or beyond +-MAGNITUDE_LIMIT m (`check_map_poses`), or a
    resolution giving a map outside `check_map_size`."""
    config = MapBuildConfig() if config is None else config
    if not isinstance(config, MapBuildConfig):  # a dict was "no attribute 'margin'"
        raise TypeError(f"build_map: config must be a MapBuildConfig, got {type(config).__name__}")
    check_number(config.margin, "margin", 0.0, unit="m")
    max_range = check_max_range("build_map", max_range)
    # -1 gave a map of unknown cells only, 0 Python's "range() arg 3 must not be zero"
    chunk = check_count(chunk, "chunk", 1, note="scans per pass")
    params = config.core_params(max_range)
    poses = check_map_poses(poses)
    ranges = np.ascontiguousarray(real_array(ranges, "ranges"), dtype=np.float32)
    if ranges.ndim != 2 or ranges.shape[1] == 0:  # no beam built a map of unknown cells
        raise ValueError(f"ranges: expected (scans, beams), beams >= 1, got shape {ranges.shape}")
    angles = real_array(angles, "angles")
    negative = np.flatnonzero((ranges < 0).any(axis=tuple(range(1, ranges.ndim))))
    if negative.size:
        first = negative[0]
        raise ValueError(
            f"ranges: scan {first} has a negative reading ({np.nanmin(ranges[first]):g} m; "
            f"{negative.size} scans with negative readings): a range is >= 0 (NaN: none)"
        )
    min_x, min_y, max_x, max_y = _core.LogOddsMapper.scan_bounds(poses, ranges, angles, params)
    m = config.margin
    check_map_size(max_x - min_x + 2 * m, max_y - min_y + 2 * m, config.resolution)
    mapper = _core.LogOddsMapper(min_x - m, min_y - m, max_x + m, max_y + m, params)
    starts = range(0, len(poses), chunk)
    for s in tqdm(starts, desc="mapping", unit="chunk", disable=not progress, leave=False):
        mapper.integrate_scans(poses[s : s + chunk], ranges[s : s + chunk], angles)
    return mapper.to_occupancy()


def map_of_log(scans: LaserScans, config: MapBuildConfig | None = None, progress: bool = False):
    """``build_map`` over a log's scans at its reference poses (a corrected CARMEN log, a
    simulated run)."""
    return build_map(scans.poses, scans.ranges, scans.angles, scans.max_range, config, progress)


def scan_local_builder(
    angles: np.ndarray,
    ranges: np.ndarray,
    max_range: float,
    size: float = 8.0,
    resolution: float = 0.1,
) -> _core.LocalMapBuilder:
    """The builder of the thesis' local map L (robot frame, sensor at its centre) filled with
    one 2-D scan; readings >= max_range ("no return": glass, black surfaces, open space) are
    left out, as in `build_map`: a missing echo says nothing certain about the space along the
    beam. Readings that are NaN, zero or negative are no reading and add nothing. Its `build()`
    is L, its `hits()` the cells a beam ended in."""
    max_range = check_max_range("local map", max_range)
    angles = real_array(angles, "local map: angles")
    # a copy: the caller's scan stays as it was
    ranges = np.array(real_array(ranges, "local map: ranges"), dtype=np.float32)
    if angles.size == 0:  # their shapes are the binding's to check
        raise ValueError("local map: the scan has no beams")
    if not np.isfinite(angles).all():  # a NaN angle's beam was left out without a word
        raise ValueError("local map: angles: contains NaN or infinite values")
    ranges[ranges >= max_range] = np.nan
    builder = _core.LocalMapBuilder(size, resolution)
    builder.add_scan(_core.Pose2(), angles, ranges, max_range)
    return builder


def scan_local_map(
    angles: np.ndarray,
    ranges: np.ndarray,
    max_range: float,
    size: float = 8.0,
    resolution: float = 0.1,
) -> OccupancyGrid:
    """The thesis' local map L from one 2-D scan (see `scan_local_builder`)."""
    return scan_local_builder(angles, ranges, max_range, size, resolution).build()


def endpoint_agreement(
    grid: OccupancyGrid,
    poses: np.ndarray,
    ranges: np.ndarray,
    angles: np.ndarray,
    max_range: float,
    neighbourhood: int = 1,
) -> float:
    """Share of scan endpoints (readings > 0 and below max_range; NaN, zero and negative ones
    are no reading) that land on an occupied cell or, with neighbourhood 1, on one of its 8
    neighbours."""
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(
            f"endpoint_agreement: grid must be a kiseki OccupancyGrid, got {type(grid).__name__}"
        )
    max_range = check_max_range("endpoint_agreement", max_range)
    neighbourhood = check_count(neighbourhood, "endpoint_agreement: neighbourhood", 0, 10, "cells")
    hits, endpoints = _core.endpoint_agreement(
        grid, poses, ranges, angles, max_range, neighbourhood=int(neighbourhood)
    )
    if endpoints == 0:
        raise ValueError(
            f"endpoint_agreement: no scan endpoint (a reading > 0 and below max_range "
            f"{max_range:g} m): agreement is undefined"
        )
    return hits / endpoints
