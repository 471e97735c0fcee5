# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Paper 004's speed limit: A. Yorozu, T. Moriguchi and M. Takahashi, "Real time speed control
for autonomous mobile robots considering occluded regions based on map and sensor data".

- Eq. 1, the occlusion term: v_max * R_recognize(theta) / (R_map_free intersect R_sensor(theta)):
  within +-theta of the direction of motion, the prior map's free cells the current scan sees,
  over the map's free cells within the sensor's reach (walls of the map hide some of them: a
  known corner or crossing shrinks the ratio, and so does an obstacle the map does not know).
- Eqs. 2-3, the width term: v_max * f(w), f(w) = 1 / (1 + exp(-a (w - b))), b = w2 - w1, w the
  distance between the obstacles detected, perpendicular to the direction of motion (Fig. 3a):
  measured on the line across the heading through the sensor, so a wall the robot drives
  towards is not a side of the passage. The paper prints ``1 - exp``, a typo: that function has
  a pole at w = b and is negative below it; its Fig. 3b draws the sigmoid.
- Eq. 4, both: v_max * ratio * f(w).

The counting is in C++ (``kiseki._core``; one limit of a 683-beam scan on a 0.05 m grid with a
4 m range takes well under a millisecond, see benchmarks/bench_speed.py). ``SpeedLimiter`` adds
the acceleration limit (the robot can change its speed by at most a_max * dt per update) and
offers the limit as ``kiseki.control.SpeedLimitSource`` to the code that drives the robot.

Defaults are the paper's sec. 4: v_max 0.5 m/s, a_max 0.5 m/s^2, theta 90 deg, w1 0.70 m (the
robot's width), w2 2.0 m, a 4.9 /m. Two choices are kiseki's, the paper being silent:
``half_band`` (0.05 m: the scan's points within 0.05 m of the line across the heading, ahead or
behind, bound the passage; one cell of the paper's 0.05 m grid either side, which holds four or
more beams of the paper's 683-beam scan at every range up to 4 m) and ``free_threshold`` (map
cells 0..25 are free, nav2 map_server's free_thresh 0.25).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.real_numbers import check_number
from kiseki.control.speed_limit import SpeedLimit
from kiseki.grid import OccupancyGrid
from kiseki.speed.acceleration import AccelerationLimit, check_initial_speed, check_top_speed

__all__ = [
    "LimitTerms",
    "SpeedLimiter",
    "SpeedLimiterConfig",
    "occlusion_labels",
    "occlusion_ratio",
    "passage_width",
    "width_factor",
]


def _pose(pose) -> tuple[float, float, float]:
    if hasattr(pose, "theta"):
        return float(pose.x), float(pose.y), float(pose.theta)
    values = np.asarray(pose, dtype=float).ravel()
    if values.shape != (3,):
        raise ValueError(f"pose must be a Pose2 or (x, y, theta), got {pose!r}")
    return float(values[0]), float(values[1]), float(values[2])


def occlusion_ratio(
    grid: OccupancyGrid,
    pose,
    angles: np.ndarray,
    ranges: np.ndarray,
    max_range: float,
    half_angle: float,
    heading: float | None = None,
) -> float:
    """Eq. 1's ratio R_recognize(theta) / (R_map_free intersect R_sensor(theta)) in [0, 1].

    Args:
        grid: the prior map.
        pose: the sensor's pose (``Pose2`` or (x, y, theta)) in the map frame.
        angles: beam angles in the sensor frame (rad, strictly increasing).
        ranges: the scan (m); readings >= ``max_range`` are no return (free space seen up to
            max_range); NaN readings say nothing, so their directions count as unseen.
        max_range: the sensor's reach (m).
        half_angle: theta (rad), in (0, pi].
        heading: the direction of motion in the map frame (rad); default the sensor's heading.

    Returns:
        the ratio; 1.0 when the map has no free cell in the region.

    Raises:
        ValueError: an empty scan, angles and ranges of different lengths, angles not
            increasing, negative ranges, max_range <= 0, half_angle <= 0 or > pi.
    """
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(f"grid must be a kiseki OccupancyGrid, got {type(grid).__name__}")
    ratio, _, _ = _core.occlusion_ratio(
        grid, _pose(pose), angles, ranges, float(max_range), float(half_angle), heading
    )
    return float(ratio)


def occlusion_labels(
    grid: OccupancyGrid,
    pose,
    angles: np.ndarray,
    ranges: np.ndarray,
    max_range: float,
    half_angle: float,
    heading: float | None = None,
) -> tuple[float, np.ndarray]:
    """Eq. 1's ratio and the cells behind it, for pictures: a uint8 array indexed ``[y, x]`` like
    ``grid.cells``: 0 outside the region, 1 a free cell of the region that the scan does not see
    (occluded), 2 a seen one. Arguments as :func:`occlusion_ratio`."""
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(f"grid must be a kiseki OccupancyGrid, got {type(grid).__name__}")
    ratio, _, _, labels = _core.occlusion_ratio(
        grid, _pose(pose), angles, ranges, float(max_range), float(half_angle), heading,
        with_labels=True,
    )  # fmt: skip
    return float(ratio), labels


def passage_width(
    angles: np.ndarray,
    ranges: np.ndarray,
    max_range: float,
    heading: float = 0.0,
    half_band: float = 0.05,
) -> float:
    """Eq. 2's passage width w (m) across ``heading`` (rad, sensor frame): the nearest hit point
    on the left plus the nearest on the right, among those within ``half_band`` metres of the
    line across the heading through the sensor (an obstacle ahead of it is not a side); a side
    without one counts ``max_range``."""
    width, _, _ = _core.passage_width(angles, ranges, float(max_range), heading, half_band)
    return float(width)


def width_factor(w, w1: float = 0.70, w2: float = 2.0, a: float = 4.9):
    """Eq. 3, f(w) = 1 / (1 + exp(-a (w - b))), b = w2 - w1, for a number or an array of widths
    (m). ValueError unless w2 > w1 > 0, a > 0 and w >= 0."""
    if np.ndim(w) == 0:
        return _core.width_factor(float(w), float(w1), float(w2), float(a))
    values = np.asarray(w, dtype=float)
    return np.array([_core.width_factor(v, w1, w2, a) for v in values.ravel()]).reshape(
        values.shape
    )


@dataclass(frozen=True)
class SpeedLimiterConfig:
    """Paper 004's limit (sec. 4 defaults). ``use_occlusion`` is method 1 (eq. 1),
    ``use_width`` method 2 (eq. 2); both: eq. 4."""

    v_max: float = 0.5  # m/s
    a_max: float = 0.5  # m/s^2
    half_angle: float = math.pi / 2  # rad, theta
    w1: float = 0.70  # m, the robot's width
    w2: float = 2.0  # m, a passage that needs no slowing down
    a: float = 4.9  # 1/m, the sigmoid's slope
    half_band: float = 0.05  # m, where w is measured (kiseki's choice, module docstring)
    free_threshold: int = 25  # map cells 0..25 are free (nav2 map_server's free_thresh)
    use_occlusion: bool = True
    use_width: bool = True

    def __post_init__(self) -> None:
        check_field_types(self)
        check_top_speed("SpeedLimiterConfig.v_max", self.v_max)
        for name, unit in (("a_max", "m/s^2"), ("w1", "m"), ("w2", "m"), ("a", "1/m"),
                           ("half_band", "m")):  # fmt: skip
            value = getattr(self, name)
            check_number(value, f"SpeedLimiterConfig.{name}", 0.0, low_open=True, unit=unit)
        if not (0 < self.half_angle <= math.pi):
            raise ValueError(
                f"SpeedLimiterConfig.half_angle must be in (0, pi], got {self.half_angle}"
            )
        if not self.w2 > self.w1:
            raise ValueError(f"SpeedLimiterConfig: w2 ({self.w2}) must exceed w1 ({self.w1})")
        check_count(self.free_threshold, "SpeedLimiterConfig.free_threshold", 0, 100)

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class LimitTerms:
    """One update's terms: eq. 1's ratio and cell counts, w and f(w), the reference v_ref
    (eq. 4) and the acceleration-limited limit."""

    ratio: float
    seen_cells: int
    free_cells: int
    width: float
    width_factor: float
    reference: float
    limit: float


class SpeedLimiter:
    """Eq. 4 per scan, acceleration-limited: a ``kiseki.control.SpeedLimitSource``.

    ``update`` returns the limit in m/s (``percentage=False``); ``last`` holds that update's
    terms."""

    def __init__(
        self, grid: OccupancyGrid, config: SpeedLimiterConfig | None = None, initial: float = 0.0
    ) -> None:
        if not isinstance(grid, OccupancyGrid):
            raise TypeError(f"grid must be a kiseki OccupancyGrid, got {type(grid).__name__}")
        self.grid = grid
        self.config = config or SpeedLimiterConfig()
        check_initial_speed("initial", initial, self.config.v_max)
        self._rate = AccelerationLimit(self.config.a_max, initial)
        self.last: LimitTerms | None = None

    def reference(
        self, sensor_pose, angles, ranges, max_range: float, heading: float | None = None
    ) -> dict:
        """Eq. 4's v_ref and its factors for one scan (no acceleration limit)."""
        c = self.config
        return _core.speed_reference(
            self.grid,
            _pose(sensor_pose),
            angles,
            ranges,
            float(max_range),
            heading,
            v_max=c.v_max,
            half_angle=c.half_angle,
            free_threshold=c.free_threshold,
            w1=c.w1,
            w2=c.w2,
            a=c.a,
            half_band=c.half_band,
            use_occlusion=c.use_occlusion,
            use_width=c.use_width,
        )

    def update(
        self,
        sensor_pose,
        angles: np.ndarray,
        ranges: np.ndarray,
        max_range: float,
        dt: float,
        heading: float | None = None,
    ) -> SpeedLimit:
        r = self.reference(sensor_pose, angles, ranges, max_range, heading)
        limit = self._rate.step(r["v_ref"], dt)
        self.last = LimitTerms(
            r["ratio"],
            r["seen_cells"],
            r["free_cells"],
            r["width"],
            r["width_factor"],
            r["v_ref"],
            limit,
        )
        return SpeedLimit(max(0.0, limit), False, self.config.v_max)
