# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki's loop filter (:mod:`kiseki.magnetic.loop_travel_distance`) on a recorded hand-held
walk of repeated laps, as a user would run it:

* The mapping lap is the walk's first lap (:func:`~kiseki.magnetic.travel_distance_walk.
  split_laps`, its positions are the mapping run's); the loop's length L is that lap's
  horizontal travel; one :class:`~kiseki.magnetic.loop_profile.LoopProfile` per
  heading-invariant channel (m_z and |m_h|, G) of the lap's readings.
* Everything after the mapping lap is one stream: odometry increments and readings only. The
  filter is never told where a lap begins; with ``start="known"`` it starts where the mapping
  lap ended (the loop's start), with ``"global"`` anywhere on the loop.
* Odometry: as :class:`~kiseki.magnetic.travel_distance_walk.WalkOdometry` (the same increments
  for the same seed).
* Scoring only (the filter never sees it): ``s_true`` per later lap as in
  :func:`~kiseki.magnetic.travel_distance_walk.localize_walk`; errors are taken around the loop
  (wrapped to [-L/2, L/2)). Two dead reckonings beside it: ``s_dr``, the same odometry from the
  same start, continued around the loop (what a user has without the filter), and ``s_dr_lap``,
  odometry restarted at the map's start at each lap's true beginning (the thesis' filter's
  baseline in ``localize_walk``, which is given the lap boundaries from the reference).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from kiseki.core import check_seed
from kiseki.datasets.magnetic import MagneticSamples
from kiseki.magnetic.loop_profile import LoopProfile, fit_loop_profile, heading_invariant_channels
from kiseki.magnetic.loop_travel_distance import LoopTravelConfig, LoopTravelDistanceLocalizer
from kiseki.magnetic.travel_distance_walk import (
    WalkLaps,
    WalkOdometry,
    lap_truth,
    read_walk_laps,
    walk_odometry,
)

NOISE_FLOOR = 1e-4
"""G (0.01 uT): the least sigma_n of a profile, far below any magnetometer's noise, so that a
noise-free (synthetic) mapping lap does not give a likelihood of zero width."""

__all__ = ["LoopWalkMap", "LoopWalkResult", "localize_walk_loop", "map_walk_loop", "wrap_around"]


def wrap_around(error: np.ndarray, length: float) -> np.ndarray:
    """Errors along a loop of ``length`` m taken the short way round, in [-L/2, L/2)."""
    return (np.asarray(error) + length / 2.0) % length - length / 2.0


@dataclass(frozen=True)
class LoopWalkResult:
    """One row per scored sample (the later laps); the loop and the profiles."""

    t: np.ndarray
    s_true: np.ndarray
    s_est: np.ndarray
    s_dr: np.ndarray
    s_dr_lap: np.ndarray
    scale: np.ndarray  # the filter's mean odometry scale
    lap: np.ndarray
    scale_error: float
    length: float
    profiles: tuple[LoopProfile, ...]
    laps: list[tuple[int, int]]

    def rmse(self, column: str) -> float:
        err = wrap_around(getattr(self, column) - self.s_true, self.length)
        return float(np.sqrt(np.mean(err**2))) if err.size else math.nan


@dataclass(frozen=True)
class LoopWalkMap:
    """What the mapping lap gives (module text): fitted once, localized against many times."""

    times: np.ndarray  # (n,) s
    laps: WalkLaps  # positions, travel, laps, the first lap's linear map (for scoring)
    channels: np.ndarray  # (n, 2) m_z and |m_h|, G
    length: float
    profiles: tuple[LoopProfile, ...]


def map_walk_loop(walk: MagneticSamples, odometry: WalkOdometry | None = None) -> LoopWalkMap:
    """The mapping lap's loop and profiles (module text); ``odometry`` gives the lap rules."""
    odometry = WalkOdometry() if odometry is None else odometry
    if not isinstance(odometry, WalkOdometry):
        raise ValueError("walk: odometry must be a WalkOdometry")
    w = read_walk_laps(walk, odometry)
    channels = heading_invariant_channels(w.frame_field)
    b, e = w.laps[0]
    length = float(w.travel[e] - w.travel[b])
    s_map = w.travel[b : e + 1] - w.travel[b]
    profiles = tuple(
        fit_loop_profile(s_map, channels[b : e + 1, c], length, noise_floor=NOISE_FLOOR)
        for c in range(2)
    )
    return LoopWalkMap(np.asarray(walk.times, dtype=np.float64), w, channels, length, profiles)


def localize_walk_loop(
    walk: MagneticSamples | LoopWalkMap,
    seed: int = 0,
    odometry: WalkOdometry | None = None,
    config: LoopTravelConfig | None = None,
    *,
    use_field: bool = True,
) -> LoopWalkResult:
    """Map the first lap (unless given its :class:`LoopWalkMap`), then localize the rest of the
    walk as one stream (module text). ``use_field=False`` runs the filter without readings:
    odometry with the scale's prior (a control)."""
    odometry = WalkOdometry() if odometry is None else odometry
    config = LoopTravelConfig() if config is None else config
    if not isinstance(odometry, WalkOdometry) or not isinstance(config, LoopTravelConfig):
        raise ValueError("walk: odometry must be a WalkOdometry and config a LoopTravelConfig")
    seed = check_seed(seed, "walk: seed")
    wm = walk if isinstance(walk, LoopWalkMap) else map_walk_loop(walk, odometry)
    w, length = wm.laps, wm.length
    e_scale, odo_step = walk_odometry(w.xy, odometry, seed)
    stream = np.arange(w.laps[0][1], len(w.xy))
    increments = odo_step[stream].copy()
    increments[0] = 0.0
    filter_config = replace(config, seed=(config.seed + seed * 1009) % 2**64)
    profiles = wm.profiles if use_field else ()
    localizer = LoopTravelDistanceLocalizer(profiles, filter_config, 0.0, length=length)
    est, scale = localizer.run(increments, wm.channels[stream][:, : len(profiles)])
    dr = np.mod(np.cumsum(increments), length)
    # scoring only: the reference's lap boundaries and s_true, as localize_walk
    truth = np.full(len(w.xy), np.nan)
    dr_lap = np.full(len(w.xy), np.nan)
    lap_of = np.zeros(len(w.xy), dtype=int)
    for number, (lb, le) in enumerate(w.laps[1:], start=2):
        s_true, offset = lap_truth(w, (lb, le), odometry)
        keep = offset <= odometry.max_offset  # a sample off the map's path is not scored
        rows = np.arange(lb, le + 1)[keep]
        truth[rows] = s_true[keep]
        lap_steps = odo_step[lb : le + 1].copy()
        lap_steps[0] = 0.0
        dr_lap[rows] = (w.linear_map.s[0] + np.cumsum(lap_steps))[keep]
        lap_of[rows] = number
    scored = np.isfinite(truth[stream])
    rows = stream[scored]
    return LoopWalkResult(
        wm.times[rows] - wm.times[0],
        truth[rows],
        est[scored],
        dr[scored],
        dr_lap[rows],
        scale[scored],
        lap_of[rows],
        e_scale,
        length,
        wm.profiles,
        w.laps,
    )
