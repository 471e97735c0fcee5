# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Where the magnetic-mapping thesis measured (``002_74cea16d239c028f.txt``, chapter 6): a
regular grid of points, and stops every 0.1 m of a robot's travel.

* :class:`MeasurementGrid`: the hand survey of sec. 6.3.2 (a 3.0 x 3.0 x 2.2 m elevator hall
  measured every 0.2 m, 2816 points, Table 6.2), or any regular evaluation grid; a scene states
  it under ``measurement_grid: {lower: [x, y, z], upper: [x, y, z], spacing: m}``.
  :meth:`MeasurementGrid.mask` picks the thinned-out training sets of Table 6.2 (every 2nd, 3rd,
  4th or 5th point along each axis: 0.4, 0.6, 0.8, 1.0 m).
* :func:`hand_survey`: the field at such points and a 3DM-DH's noisy readings of it, in the
  world frame (the hand survey records the field along the grid's axes).
* :func:`route_stops` / :func:`poses_along_route`: the robotized survey of sec. 6.5 records a
  reading every 0.1 m of travel; these give the robot's poses at equal distances along a
  scene's route (a polyline of waypoints, each pose heading along its leg).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki.core import Random, check_seed
from kiseki.sim.magnetic import DEFAULT_NOISE_SD, MagneticWorld

__all__ = [
    "MAX_GRID_POINTS",
    "MeasurementGrid",
    "hand_survey",
    "poses_along_route",
    "route_stops",
]

#: At most this many points in a measurement grid (a 10 million point grid of 3 floats is
#: 240 MB; a 450 m^2 floor at 0.05 m with 10 heights is 1.8 million).
MAX_GRID_POINTS = 10_000_000

_TOL = 1e-6  # relative tolerance for "the span is a whole number of spacings"


def _triple(value: Any, name: str, where: str) -> tuple[float, float, float]:
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if (
        not isinstance(value, list | tuple)
        or len(value) != 3
        or not all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in value)
        or not all(math.isfinite(v) for v in value)
    ):
        raise ValueError(f"{where}: {name} must be [x, y, z], three finite numbers, got {value!r}")
    return float(value[0]), float(value[1]), float(value[2])


@dataclass(frozen=True)
class MeasurementGrid:
    """Points ``lower + spacing * (i, j, k)`` from ``lower`` to ``upper`` (both corners on the
    grid), m, world frame. A side with ``upper == lower`` holds one layer (a 2-D grid at one
    height). Points are ordered x slowest, z fastest: ``points().reshape(*shape, 3)``.
    """

    lower: tuple[float, float, float]
    upper: tuple[float, float, float]
    spacing: float
    where: str = field(default="measurement_grid", compare=False, repr=False)  # for errors

    def __post_init__(self) -> None:
        w = self.where
        lo, hi = _triple(self.lower, "lower", w), _triple(self.upper, "upper", w)
        s = check_number(self.spacing, f"{w}: spacing", 0.0, low_open=True, unit="m")
        counts = []
        for axis, a, b in zip("xyz", lo, hi, strict=True):
            if b < a:
                raise ValueError(f"{w}: upper {axis} ({b}) is below lower {axis} ({a})")
            steps = (b - a) / s
            if abs(steps - round(steps)) > _TOL * max(1.0, steps):
                raise ValueError(
                    f"{w}: the {axis} span {b - a:g} m is not a whole number of {s:g} m "
                    "spacings (both corners must lie on the grid)"
                )
            counts.append(round(steps) + 1)
        total = math.prod(counts)
        if total > MAX_GRID_POINTS:
            raise ValueError(f"{w}: {total:,} points, more than {MAX_GRID_POINTS:,}")
        object.__setattr__(self, "lower", lo)
        object.__setattr__(self, "upper", hi)
        object.__setattr__(self, "spacing", s)

    @classmethod
    def from_dict(cls, value: Any, where: str = "measurement_grid") -> MeasurementGrid:
        """From a scene's ``{lower: [x, y, z], upper: [x, y, z], spacing: m}``; ValueError
        naming ``where`` for a missing or unknown key or a bad value."""
        if not isinstance(value, Mapping):
            raise ValueError(
                f"{where}: expected {{lower: [x, y, z], upper: [x, y, z], spacing: m}}, "
                f"got {value!r}"
            )
        unknown = sorted(set(value) - {"lower", "upper", "spacing"})
        if unknown:
            raise ValueError(f"{where}: unknown key(s) {', '.join(map(str, unknown))}")
        missing = [k for k in ("lower", "upper", "spacing") if k not in value]
        if missing:
            raise ValueError(f"{where}: missing {', '.join(missing)}")
        lo = _triple(value["lower"], "lower", where)
        hi = _triple(value["upper"], "upper", where)
        return cls(lo, hi, value["spacing"], where)

    @property
    def shape(self) -> tuple[int, int, int]:
        """Points along x, y and z."""
        return tuple(
            round((b - a) / self.spacing) + 1 for a, b in zip(self.lower, self.upper, strict=True)
        )

    @property
    def size(self) -> int:
        return math.prod(self.shape)

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The x, y and z coordinates of the grid's planes."""
        return tuple(
            a + self.spacing * np.arange(n) for a, n in zip(self.lower, self.shape, strict=True)
        )

    def points(self) -> np.ndarray:
        """(size, 3) points, x slowest, z fastest."""
        gx, gy, gz = np.meshgrid(*self.axes(), indexing="ij")
        return np.column_stack([gx.ravel(), gy.ravel(), gz.ravel()])

    def mask(self, step: int) -> np.ndarray:
        """(size,) bool: every ``step``-th point along each axis from the lower corner, the
        thinned-out grid of spacing ``step * spacing`` (Table 6.2's training sets)."""
        step = check_count(step, f"{self.where}: step", 1)
        keep = np.zeros(self.shape, dtype=bool)
        keep[::step, ::step, ::step] = True
        return keep.ravel()

    def contains(self, points: Any) -> np.ndarray:
        """(n,) bool: which of (n, 3) points lie in the grid's box (its corners included)."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        lo, hi, eps = np.array(self.lower), np.array(self.upper), 1e-9
        return np.all((p >= lo - eps) & (p <= hi + eps), axis=1)


def hand_survey(
    world: MagneticWorld,
    points: Any,
    noise_sd: float = DEFAULT_NOISE_SD,
    seed: int = 0,
    times: Any = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """(true field (n, 3), readings (n, 3)), G, world frame, at (n, 3) points and times (s,
    scalar or (n,)): a sensor held at each point with its axes along the world's, reading the
    field plus ``N(0, noise_sd^2)`` per axis from ``kiseki.core.Random(seed)`` (3 n draws in
    row order). Default noise: the 3DM-DH's 0.01 G (thesis sec. 6.3.2)."""
    if not isinstance(world, MagneticWorld):
        raise ValueError(f"world: expected a MagneticWorld, got {type(world).__name__}")
    check_number(noise_sd, "noise_sd", 0.0, unit="G")
    seed = check_seed(seed)
    truth = np.reshape(world.field_at(points, times), (-1, 3))
    if noise_sd == 0:
        return truth, truth.copy()
    noise = Random(seed).normal(0.0, float(noise_sd), truth.size).reshape(truth.shape)
    return truth, truth + noise


def _legs(waypoints: Any) -> tuple[np.ndarray, np.ndarray]:
    pts = np.asarray(waypoints, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2 or not np.isfinite(pts).all():
        raise ValueError(f"waypoints: expected two or more finite [x, y], got shape {pts.shape}")
    lengths = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if np.any(lengths == 0):
        raise ValueError("waypoints: two consecutive waypoints coincide (a leg of zero length)")
    return pts, lengths


def poses_along_route(waypoints: Any, distances: Any) -> np.ndarray:
    """(n, 3) poses (x, y, theta) at the given travel distances (m, 0 .. the route's length)
    along the polyline ``waypoints``; theta is the heading of the leg the point lies on (at a
    waypoint, of the leg that starts there). The robot's turns in place take no distance."""
    pts, lengths = _legs(waypoints)
    s = np.asarray(distances, dtype=float).reshape(-1)
    total = float(lengths.sum())
    if not np.isfinite(s).all() or np.any(s < 0) or np.any(s > total * (1 + 1e-12)):
        raise ValueError(f"distances: must lie in [0, {total:g}] m, the route's length")
    ends = np.cumsum(lengths)
    leg = np.minimum(np.searchsorted(ends, s, side="right"), len(lengths) - 1)
    start = ends[leg] - lengths[leg]
    d = pts[leg + 1] - pts[leg]
    f = ((s - start) / lengths[leg])[:, None]
    xy = pts[leg] + f * d
    return np.column_stack([xy, np.arctan2(d[:, 1], d[:, 0])])


def route_stops(waypoints: Any, step: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """The robot's poses (n, 3) every ``step`` m of travel along the route from its first
    waypoint (the thesis records a reading every 0.1 m, sec. 6.5.1), and their travel distances
    (n,): ``floor(length / step) + 1`` stops."""
    check_number(step, "step", 0.0, low_open=True, unit="m")
    total = float(_legs(waypoints)[1].sum())
    s = step * np.arange(int(math.floor(total / step + 1e-9)) + 1)
    return poses_along_route(waypoints, s), s
