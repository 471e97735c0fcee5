# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The thesis' travel-distance filter (:mod:`kiseki.magnetic.travel_distance`, sec. 4.4.1) on a
recorded hand-held walk of repeated laps of one loop (:func:`kiseki.datasets.kok.read_kok_walk`:
positions from the visual-inertial odometry, the field turned to the world frame, z up).

* Laps: the walker "comes back" when within ``radius`` (1.5 m) of the start after at least
  ``min_travel`` (10 m) of travel since the lap began; the lap ends at the closest approach to
  the start during that return (so that the map lap covers the whole loop and a later lap
  starts where the map does). The first lap is the linear map; the later ones (the last may be
  partial) are localized, each from travel distance 0.
* The map: :func:`~kiseki.magnetic.linear_map.build_linear_map` (nodes every 0.1 m) of the
  first lap's samples, travel distance from the walk's horizontal positions (the teaching run's
  odometry is the visual-inertial one). The field is in the thesis' frame of a robot on flat
  ground (sec. 4.4.2: x forward, y right, z down): x along the horizontal direction of travel,
  z the world's down, so that mz (the component the filter compares) is the vertical field,
  the same whatever way the hand holds the iPad; G (uT / 100).
* Odometry of a later lap: each horizontal increment ``|dp|`` of the positions becomes
  ``(1 + e) |dp| + N(0, (noise |dp|)^2)``, e drawn once per walk from N(0, scale_sd^2); defaults
  scale_sd 0.05, noise 0.1; the seed draws e, the noise and the filter's randomness.
* ``s_true``: the travel distance of the map node nearest the true position, among the nodes
  within ``truth_window`` (3 m) of the lap's own travel distance scaled to the map lap's length
  (the loop of an eight crosses itself: the nearest node alone would jump to the other branch).
* A later lap with a sample farther than ``max_offset`` (2 m) from every map node leaves the
  map's path: it is reported and not localized.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from kiseki._support.real_numbers import hold_number
from kiseki.core import check_seed
from kiseki.datasets.magnetic import MagneticSamples
from kiseki.magnetic.linear_map import LinearMagneticMap, build_linear_map, path_identity
from kiseki.magnetic.travel_distance import TravelDistanceConfig, TravelDistanceLocalizer

__all__ = [
    "WalkLaps",
    "WalkOdometry",
    "WalkResult",
    "horizontal_travel",
    "lap_truth",
    "localize_walk",
    "path_frame_field",
    "read_walk_laps",
    "split_laps",
    "truth_on_map",
    "walk_odometry",
]

UT_PER_G = 100.0
MIN_PARTIAL = 1.0
"""m: the shortest tail after the last return that counts as a (partial) lap."""


@dataclass(frozen=True)
class WalkOdometry:
    """The made-up odometry of the later laps and the lap and path rules (module text)."""

    scale_sd: float = 0.05
    noise: float = 0.1
    scale_error: float | None = None  # fixed e instead of one drawn from N(0, scale_sd^2)
    radius: float = 1.5
    min_travel: float = 10.0
    max_offset: float = 2.0
    truth_window: float = 3.0

    def __post_init__(self) -> None:
        for name in ("scale_sd", "noise", "radius", "min_travel", "max_offset", "truth_window"):
            hold_number(self, name, f"walk: {name}", 0.0)
        if self.scale_error is not None:
            hold_number(self, "scale_error", "walk: scale_error", -1.0, low_open=True)


@dataclass(frozen=True)
class WalkResult:
    """One row per localized sample; the laps that left the map's path."""

    t: np.ndarray
    s_true: np.ndarray
    s_est: np.ndarray
    s_odom: np.ndarray
    lap: np.ndarray
    scale_error: float
    linear_map: LinearMagneticMap
    laps: list[tuple[int, int]]
    off_path: list[tuple[int, float, float]] = field(default_factory=list)  # lap, t, metres

    def rmse(self, column: str) -> float:
        err = getattr(self, column) - self.s_true
        return float(np.sqrt(np.mean(err**2))) if err.size else math.nan


def horizontal_travel(xy: np.ndarray) -> np.ndarray:
    """(n,) cumulative horizontal distance along positions (n, 2), from 0."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])


def split_laps(xy: Any, radius: float = 1.5, min_travel: float = 10.0) -> list[tuple[int, int]]:
    """(first, last) sample indices of each lap of horizontal positions (n, 2) (module text);
    the samples after the last return form a last, partial lap when they span at least
    ``MIN_PARTIAL`` (1 m) of travel."""
    p = np.asarray(xy, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 2:
        raise ValueError(f"walk: positions must be (n, 2) with n >= 2, got {p.shape}")
    near = np.linalg.norm(p - p[0], axis=1) <= radius
    s = horizontal_travel(p)
    dist = np.linalg.norm(p - p[0], axis=1)
    laps, begin = [], 0
    while True:
        hit = np.flatnonzero(near & (s - s[begin] >= min_travel) & (np.arange(len(p)) > begin))
        if hit.size == 0:
            break
        first = int(hit[0])
        last = first
        while last + 1 < len(p) and near[last + 1]:
            last += 1
        end = first + int(np.argmin(dist[first : last + 1]))
        laps.append((begin, end))
        begin = end
    if not laps:
        raise ValueError(
            f"walk: the walker never comes back within {radius} m of the start after "
            f"{min_travel} m (travelled {s[-1]:.1f} m): no lap to map"
        )
    if s[-1] - s[begin] >= MIN_PARTIAL:
        laps.append((begin, len(p) - 1))
    return laps


def path_frame_field(field_world: Any, xy: Any) -> tuple[np.ndarray, np.ndarray]:
    """(field (n, 3) in the frame x forward (horizontal direction of travel), y right, z down,
    heading (n,) rad of the direction of travel) from a world field with z up and horizontal
    positions; the direction from the positions 0.2 s around each sample (central difference)."""
    f = np.asarray(field_world, dtype=np.float64)
    p = np.asarray(xy, dtype=np.float64)
    v = np.gradient(p, axis=0)
    heading = np.arctan2(v[:, 1], v[:, 0])
    c, s = np.cos(heading), np.sin(heading)
    fx = f[:, 0] * c + f[:, 1] * s
    fy = f[:, 0] * s - f[:, 1] * c  # right of forward with z up: (sin, -cos)
    return np.column_stack([fx, fy, -f[:, 2]]), heading


def truth_on_map(xy: np.ndarray, m: LinearMagneticMap, expected: np.ndarray, window: float):
    """(s of the map node nearest each position among those within ``window`` m of the
    ``expected`` travel distance, each position's distance to the nearest node) (module text:
    ``s_true``)."""
    d = np.linalg.norm(xy[:, None, :] - m.position[None, :, :], axis=2)
    offset = d.min(axis=1)
    gated = np.where(np.abs(m.s[None, :] - expected[:, None]) <= window, d, np.inf)
    return m.s[np.argmin(gated, axis=1)], offset


@dataclass(frozen=True)
class WalkLaps:
    """A walk read for travel distance (module text): horizontal positions, their travel, the
    laps, the field in the path's frame (G) and the direction of travel, and the first lap's
    linear map (``s`` from 0)."""

    xy: np.ndarray
    travel: np.ndarray
    laps: list[tuple[int, int]]
    frame_field: np.ndarray
    heading: np.ndarray
    linear_map: LinearMagneticMap


def read_walk_laps(walk: MagneticSamples, odometry: WalkOdometry) -> WalkLaps:
    """Checks a walk, splits its laps and maps the first (module text)."""
    if walk.times is None:
        raise ValueError(f"{walk.source}: the walk has no times")
    scale = {"uT": 1.0 / UT_PER_G, "G": 1.0}.get(walk.units)
    if scale is None or walk.dimension != 3:
        raise ValueError(f"{walk.source}: a walk needs 3-D positions and a field in uT or G")
    xy = np.asarray(walk.positions[:, :2])
    laps = split_laps(xy, odometry.radius, odometry.min_travel)
    if len(laps) < 2:
        raise ValueError(f"{walk.source}: one lap only: nothing to localize against its map")
    frame_field, heading = path_frame_field(np.asarray(walk.field) * scale, xy)
    travel = horizontal_travel(xy)
    b, e = laps[0]
    lap = slice(b, e + 1)
    m = build_linear_map(
        travel[lap] - travel[b],
        frame_field[lap],
        heading[lap],
        position=xy[lap],
        path_id=path_identity(xy[lap]),
        provenance={"source": walk.source, "lap": "1"},
    )
    return WalkLaps(xy, travel, laps, frame_field, heading, m)


def walk_odometry(xy: np.ndarray, odometry: WalkOdometry, seed: int) -> tuple[float, np.ndarray]:
    """(the scale error e, each sample's odometry step (n,), 0 first) (module text)."""
    rng = np.random.default_rng(seed)
    e_scale = odometry.scale_error
    e_scale = float(rng.normal(0.0, odometry.scale_sd)) if e_scale is None else float(e_scale)
    step = np.concatenate([[0.0], np.linalg.norm(np.diff(xy, axis=0), axis=1)])
    return e_scale, (1.0 + e_scale) * step + rng.normal(0.0, 1.0, len(step)) * odometry.noise * step


def lap_truth(w: WalkLaps, lap: tuple[int, int], odometry: WalkOdometry):
    """(s_true (module text), each sample's distance to the nearest map node) of a later lap
    (first, last sample)."""
    b, e = lap
    m = w.linear_map
    lap_travel = w.travel[b : e + 1] - w.travel[b]
    closed = (
        lap_travel[-1] >= odometry.min_travel
        and np.linalg.norm(w.xy[e] - w.xy[0]) <= odometry.radius
    )
    ratio = (m.s[-1] - m.s[0]) / lap_travel[-1] if closed else 1.0  # 1: the partial last lap
    return truth_on_map(w.xy[b : e + 1], m, lap_travel * ratio + m.s[0], odometry.truth_window)


def localize_walk(
    walk: MagneticSamples,
    seed: int = 0,
    odometry: WalkOdometry | None = None,
    config: TravelDistanceConfig | None = None,
) -> WalkResult:
    """Map the first lap, localize the later ones (module text)."""
    odometry = WalkOdometry() if odometry is None else odometry
    config = TravelDistanceConfig() if config is None else config
    seed = check_seed(seed, "walk: seed")
    w = read_walk_laps(walk, odometry)
    m, laps = w.linear_map, w.laps
    e_scale, odo_step = walk_odometry(w.xy, odometry, seed)
    t0 = float(walk.times[0])
    rows: list[np.ndarray] = []
    off_path = []
    for number, (b, e) in enumerate(laps[1:], start=2):
        lap = slice(b, e + 1)
        s_true, offset = lap_truth(w, (b, e), odometry)
        if offset.max() > odometry.max_offset:
            k = int(np.argmax(offset))
            off_path.append((number, float(walk.times[b + k] - t0), float(offset[k])))
            continue
        increments = odo_step[lap].copy()
        increments[0] = 0.0
        lap_config = _with_seed(config, (config.seed + seed * 1009 + number) % 2**64)
        localizer = TravelDistanceLocalizer(m, lap_config, start=float(m.s[0]))
        est = localizer.run(increments, w.frame_field[lap, 2])
        odom = m.s[0] + np.cumsum(increments)
        t = walk.times[lap] - t0
        table = np.column_stack([t, s_true, est, odom, np.full(len(t), number)])
        rows.append(table if number == len(laps) else table[:-1])  # e begins the next lap
    table = np.vstack(rows) if rows else np.empty((0, 5))
    return WalkResult(
        table[:, 0],
        table[:, 1],
        table[:, 2],
        table[:, 3],
        table[:, 4].astype(int),
        e_scale,
        m,
        laps,
        off_path,
    )


def _with_seed(config: TravelDistanceConfig, seed: int) -> TravelDistanceConfig:

    return replace(config, seed=seed)
