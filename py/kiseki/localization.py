# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Localization along recorded logs (CARMEN, kiseki's MCAP runs): dead reckoning, the
teaching-and-playback thesis' space observation model (local maps from each 2-D scan), and the
standard likelihood-field MCL as a baseline, all in the same particle filter with the same
motion noise. Position tracking from the log's first reference pose (not global localization).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from kiseki import _core
from kiseki.core import Pose2, Random, derive_seed
from kiseki.datasets.carmen import LaserScans
from kiseki.grid import OccupancyGrid
from kiseki.mapping import scan_local_map

__all__ = ["LOCALIZATION_METHODS", "LocalizeConfig", "localize", "noisy_odometry"]

LOCALIZATION_METHODS = ("odometry", "space-observation", "likelihood-field")


@dataclass(frozen=True)
class LocalizeConfig:
    method: str = "space-observation"
    seed: int = 0
    odometry_noise: float = 0.0  # SD as a fraction of each odometry increment's component
    particles: int = 500
    initial_sd: tuple[float, float, float] = (0.1, 0.1, np.radians(3.0))
    alphas: tuple[float, float, float, float] = (0.05, 0.01, 0.05, 0.01)
    beam_stride: int = 2  # likelihood field: every other beam (AMCL-like)

    def __post_init__(self) -> None:
        if self.method not in LOCALIZATION_METHODS:
            raise ValueError(
                f"method must be one of {', '.join(LOCALIZATION_METHODS)}, got {self.method!r}"
            )
        if not (self.odometry_noise >= 0 and np.isfinite(self.odometry_noise)):
            raise ValueError(f"odometry noise must be >= 0, got {self.odometry_noise}")
        if self.particles < 1:
            raise ValueError("particles must be >= 1")


def noisy_odometry(poses: np.ndarray, fraction: float, seed: int) -> np.ndarray:
    """Odometry rebuilt from the increments of `poses` (in each previous pose's frame), each
    component perturbed by zero-mean Gaussian noise with SD = fraction x |component|."""
    poses = np.asarray(poses, dtype=float)
    rng = Random(seed)
    out = np.empty_like(poses)
    out[0] = poses[0]
    current = Pose2(*poses[0])
    for k in range(1, len(poses)):
        step = Pose2(*poses[k - 1]).between(Pose2(*poses[k])).to_array()
        if fraction > 0:
            step = step + fraction * np.abs(step) * rng.normal(0.0, 1.0, 3)
        current = current * Pose2(*step)
        out[k] = current.to_array()
    return out


def localize(
    scans: LaserScans, grid: OccupancyGrid, config: LocalizeConfig, progress: bool = False
) -> np.ndarray:
    """Estimated sensor poses (n, 3), one per scan."""
    odom = noisy_odometry(scans.odometry, config.odometry_noise, derive_seed(config.seed, 1))
    if config.method == "odometry":
        return odom
    a1, a2, a3, a4 = config.alphas
    pf = _core.ParticleFilter(config.particles, a1, a2, a3, a4, 0.5, derive_seed(config.seed, 2))
    pf.initialize(Pose2(*scans.poses[0]), *config.initial_sd)
    if config.method == "space-observation":
        model = _core.SpaceObservationModel(grid)
    else:
        model = _core.LikelihoodFieldModel(grid, beam_stride=config.beam_stride)
    out = np.empty((len(scans), 3))
    for k in tqdm(range(len(scans)), desc=config.method, unit="scan", disable=not progress):
        if k > 0:
            pf.predict(Pose2(*odom[k - 1]), Pose2(*odom[k]))
        ranges = scans.ranges[k]
        if config.method == "space-observation":
            model.set_local_map(scan_local_map(scans.angles, ranges, scans.max_range))
            pf.weight(model.likelihoods(pf.poses))
        else:
            model.set_scan(scans.angles, ranges, scans.max_range)
            log_l = model.log_likelihoods(pf.poses)
            pf.weight(np.exp(log_l - log_l.max()))
        out[k] = pf.estimate().to_array()
        pf.resample_if_needed()
    return out
