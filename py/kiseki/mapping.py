# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Occupancy-grid mapping from scans taken at known poses: the log-odds inverse sensor model
(`build_map`), and the teaching-and-playback thesis' environment map (`build_teaching_map`), in
which local maps are merged by the thesis' rules and the space behind every obstacle is occupied."""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields

import numpy as np
from tqdm import tqdm

from kiseki import _core
from kiseki.grid import OccupancyGrid

__all__ = [
    "MapBuildConfig",
    "build_map",
    "build_teaching_map",
    "endpoint_agreement",
    "scan_local_map",
]


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
    def from_dict(cls, values: dict) -> MapBuildConfig:
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(values) - known)
        if unknown:
            raise ValueError(f"unknown map-building parameter(s): {', '.join(unknown)}")
        kinds = {f.name: f.type for f in fields(cls)}
        return cls(**{k: (bool(v) if kinds[k] == "bool" else float(v)) for k, v in values.items()})

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
    (n, 3: x, y, theta) with beam angles (b,). Readings >= max_range are "no return"."""
    config = config or MapBuildConfig()
    if not np.isfinite(config.margin) or config.margin < 0:
        raise ValueError(f"margin must be >= 0, got {config.margin}")
    params = config.core_params(max_range)
    poses = np.ascontiguousarray(poses, dtype=np.float64)
    ranges = np.ascontiguousarray(ranges, dtype=np.float32)
    if poses.ndim != 2 or poses.shape[0] == 0:
        raise ValueError(f"poses: expected a non-empty (n, 3) array, got shape {poses.shape}")
    min_x, min_y, max_x, max_y = _core.LogOddsMapper.scan_bounds(poses, ranges, angles, params)
    m = config.margin
    mapper = _core.LogOddsMapper(min_x - m, min_y - m, max_x + m, max_y + m, params)
    starts = range(0, len(poses), chunk)
    for s in tqdm(starts, desc="mapping", unit="chunk", disable=not progress, leave=False):
        mapper.integrate_scans(poses[s : s + chunk], ranges[s : s + chunk], angles)
    return mapper.to_occupancy()


def scan_local_map(
    angles: np.ndarray,
    ranges: np.ndarray,
    max_range: float,
    size: float = 8.0,
    resolution: float = 0.1,
) -> OccupancyGrid:
    """The thesis' local map L (robot frame, sensor at its centre) from one 2-D scan. Readings
    >= max_range ("no return": glass, black surfaces, open space) are left out, as in
    `build_map`: a missing echo says nothing certain about the space along the beam."""
    ranges = np.array(ranges, dtype=np.float32)  # a copy: the caller's scan stays as it was
    ranges[ranges >= max_range] = np.nan
    builder = _core.LocalMapBuilder(size, resolution)
    builder.add_scan(_core.Pose2(), angles, ranges, max_range)
    return builder.build()


def build_teaching_map(
    poses: np.ndarray,
    ranges: np.ndarray,
    angles: np.ndarray,
    max_range: float,
    resolution: float = 0.1,
    local_size: float = 8.0,
    progress: bool = False,
) -> OccupancyGrid:
    """The environment map the space observation model is defined against (thesis sec. 3.4),
    from scans at known poses: each scan's local map (`scan_local_map`) placed at its pose and
    merged by the thesis' rules (unknown -> local value; local free over occupied -> free;
    local occupied over free -> stays free). Walls are as thin as single scans see them and
    the space behind them is occupied, unlike `build_map`'s log-odds map."""
    poses = np.ascontiguousarray(poses, dtype=np.float64)
    ranges = np.asarray(ranges)
    if poses.ndim != 2 or poses.shape[1] != 3 or poses.shape[0] == 0:
        raise ValueError(f"poses: expected a non-empty (n, 3) array, got shape {poses.shape}")
    if ranges.ndim != 2 or ranges.shape[0] != poses.shape[0]:
        raise ValueError(f"ranges: expected ({poses.shape[0]}, beams), got shape {ranges.shape}")
    if not np.isfinite(poses).all():
        raise ValueError("poses: every pose must be finite")
    reach = local_size / np.sqrt(2.0) + resolution  # half the diagonal of a local map
    lo = poses[:, :2].min(axis=0) - reach
    hi = poses[:, :2].max(axis=0) + reach
    width, height = np.ceil((hi - lo) / resolution).astype(int)
    grid = _core.OccupancyGrid(int(width), int(height), resolution, _core.Pose2(lo[0], lo[1], 0))
    for k in tqdm(range(len(poses)), desc="teaching map", disable=not progress, leave=False):
        local = scan_local_map(angles, ranges[k], max_range, local_size, resolution)
        _core.merge_local_map(grid, local, _core.Pose2(*poses[k]))
    return grid


def endpoint_agreement(
    grid: OccupancyGrid,
    poses: np.ndarray,
    ranges: np.ndarray,
    angles: np.ndarray,
    max_range: float,
    neighbourhood: int = 1,
) -> float:
    """Share of scan endpoints (readings below max_range) that land on an occupied cell or,
    with neighbourhood 1, on one of its 8 neighbours."""
    hits, endpoints = _core.endpoint_agreement(
        grid, poses, ranges, angles, max_range, neighbourhood=neighbourhood
    )
    if endpoints == 0:
        raise ValueError("no scan endpoint below max_range: agreement is undefined")
    return hits / endpoints
