# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The inputs and settings the AMCL side-by-side benchmarks share (bench_nav2_amcl.py,
bench_anchors.py): a CARMEN log with its map, its noisy odometry and the beams each filter gets,
and the parameters every filter is given. Imported from beside this file.

The corrected logs' odometry is their reference path, so every filter gets the same noisy
odometry made from it (kiseki.filters.noisy_odometry: each increment component with SD =
F x |component|), the same map (built from the log at 0.05 m) and the same beams of each scan.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from kiseki.datasets import read_carmen_log
from kiseki.filters import LocalizeConfig, motion_alphas, noisy_odometry
from kiseki.mapping import MapBuildConfig, map_of_log

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
LOGS = ("intel", "aces", "csail", "freiburg-079")
MAP_RESOLUTION = 0.05  # m

# --- the settings every filter shares --------------------------------------------------------
ODOMETRY_NOISE = 0.1  # F
# Motion noise: nav2's defaults are alpha1..alpha5 = 0.2 each, far more than the odometry above
# has. Every filter gets the alphas that describe it (kiseki.filters.motion_alphas: alpha1 =
# alpha3 = F^2 = 0.01, alpha2 = alpha4 = F^2 / 10 = 0.001), in the same convention (Probabilistic
# Robotics Table 5.6; nav2's "differential" model: alpha1 rotation from rotation, alpha2
# rotation from translation, alpha3 translation from translation, alpha4 translation from
# rotation). alpha5 is used only by nav2's "omni" model: 0.
ALPHA5 = 0.0
# Beam model mixture: nav2's defaults (z_hit 0.5, z_short 0.05, z_max 0.05, z_rand 0.5,
# sigma_hit 0.2 m, lambda_short 0.1 1/m). The likelihood field gets the same z_hit, z_rand and
# sigma_hit (nav2's likelihood-field defaults are the same three values) and nav2's
# laser_likelihood_max_dist 2.0 m (the distance at which the field stops growing).
Z_HIT, Z_SHORT, Z_MAX, Z_RAND = 0.5, 0.05, 0.05, 0.5
SIGMA_HIT = 0.2
LAMBDA_SHORT = 0.1
CHI_OUTLIER = 0.05  # nav2's default; its beam model does not use it
LIKELIHOOD_MAX_DIST = 2.0
# Initial cloud: a Gaussian around the log's first reference pose, SD 0.1 m, 0.1 m, 3 degrees.
INITIAL_SD = (0.1, 0.1, float(np.radians(3.0)))


@dataclasses.dataclass(frozen=True)
class LogInputs:
    """A log's scans (with its reference poses), the map built from it and the motion noise
    that describes its noisy odometry."""

    scans: object  # kiseki.scans.LaserScans
    grid: object  # kiseki.grid.OccupancyGrid
    alphas: tuple[float, ...]


def load_log(log: str, data: Path = DATA) -> LogInputs:
    """The corrected CARMEN log `log`, its 0.05 m map and the alphas of its noisy odometry."""
    full = read_carmen_log(data / "carmen" / f"{log}-corrected.log.gz").scans
    grid = map_of_log(full, MapBuildConfig(resolution=MAP_RESOLUTION))
    alphas = motion_alphas(LocalizeConfig(odometry_noise=ODOMETRY_NOISE), full)
    return LogInputs(full, grid, alphas)


def log_odometry(inputs: LogInputs, seed: int) -> np.ndarray:
    """The noisy odometry of a log for one seed (the same for every filter)."""
    return noisy_odometry(inputs.scans.odometry, ODOMETRY_NOISE, seed)


def nav2_beam_indices(count: int, max_beams: int) -> np.ndarray:
    """nav2's max_beams rule: every step-th beam from the first, step = (count - 1) //
    (max_beams - 1) (at least 1). Every filter is given these beams only."""
    step = max(1, (count - 1) // max(1, max_beams - 1))
    return np.arange(0, count, step)


def select_scans(full, odometry: np.ndarray, beams: int, scans: int | None):
    """The first `scans` scans of a log (all when None) with the given odometry and only the
    beams nav2's max_beams rule picks."""
    m = len(full) if scans is None else min(scans, len(full))
    idx = nav2_beam_indices(full.ranges.shape[1], beams)
    return dataclasses.replace(
        full,
        times=full.times[:m],
        poses=full.poses[:m],
        odometry=odometry[:m],
        ranges=np.ascontiguousarray(full.ranges[:m, idx]),
        angles=full.angles[idx],
    )
