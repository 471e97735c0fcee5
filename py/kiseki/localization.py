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

__all__ = [
    "LOCALIZATION_METHODS",
    "REAL_ODOMETRY_ALPHAS",
    "LocalizeConfig",
    "localize",
    "motion_alphas",
    "noisy_odometry",
]

LOCALIZATION_METHODS = ("odometry", "space-observation", "likelihood-field")
# The motion noise for a log's own odometry, whose error is unknown: wide, AMCL-like values.
REAL_ODOMETRY_ALPHAS = (0.05, 0.01, 0.05, 0.01)


@dataclass(frozen=True)
class LocalizeConfig:
    method: str = "space-observation"
    seed: int = 0
    odometry_noise: float = 0.0  # SD as a fraction of each odometry increment's component
    particles: int = 500
    initial_sd: tuple[float, float, float] = (0.1, 0.1, np.radians(3.0))
    # Odometry motion model noise (Probabilistic Robotics Table 5.6); None: `motion_alphas`
    alphas: tuple[float, float, float, float] | None = None
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
        if self.alphas is not None and (
            len(self.alphas) != 4 or not all(a >= 0 and np.isfinite(a) for a in self.alphas)
        ):
            raise ValueError(f"alphas must be four finite numbers >= 0, got {self.alphas}")


def motion_alphas(config: LocalizeConfig, scans: LaserScans) -> tuple[float, ...]:
    """The filter's motion noise: `config.alphas` if given, else the noise the odometry has.

    That is the log's own odometry error plus the noise `noisy_odometry` adds. The log's own:
    none when its odometry equals its reference poses (the CARMEN "corrected" logs), else
    unknown, and then `REAL_ODOMETRY_ALPHAS`. The added noise has SD F |component| on each
    increment, so in the motion model's terms a rotation SD of F |rotation| and a translation
    SD of F |translation|: alpha1 = alpha3 = F^2; the cross terms (translation turning the
    heading, rotation moving the robot) get a tenth of that. A filter told of more noise than
    the odometry has spreads its particles further than one scan can pull them back, which the
    weakly peaked space observation model does not survive on long corridors."""
    if config.alphas is not None:
        return tuple(config.alphas)
    exact = scans.odometry.shape == scans.poses.shape and np.allclose(
        scans.odometry, scans.poses, atol=1e-6
    )
    base = (0.0, 0.0, 0.0, 0.0) if exact else REAL_ODOMETRY_ALPHAS
    f2 = config.odometry_noise**2
    added = (f2, 0.1 * f2, f2, 0.1 * f2)
    return tuple(max(b + a, 1e-6) for b, a in zip(base, added, strict=True))


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
    a1, a2, a3, a4 = motion_alphas(config, scans)
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
