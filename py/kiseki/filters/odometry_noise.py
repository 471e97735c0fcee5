# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The odometry a log replay feeds the filter (:func:`noisy_odometry`: the reference poses'
increments with added noise) and the motion noise the filter assumes for it
(:func:`motion_alphas`)."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.core import Pose2, Random
from kiseki.filters.engine import REAL_ODOMETRY_ALPHAS
from kiseki.scans import LaserScans


class OdometrySettings(Protocol):
    """What :func:`motion_alphas` reads of a config (kiseki.filters.LocalizeConfig)."""

    alphas: tuple[float, ...] | None
    odometry_noise: float


__all__ = ["NOISE_FRACTION_LIMIT", "motion_alphas", "noisy_odometry"]


def motion_alphas(config: OdometrySettings, scans: LaserScans) -> tuple[float, ...]:
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


NOISE_FRACTION_LIMIT = 10.0
"""The largest odometry noise, as a multiple of each step's size (exclusive): noise ten times the
motion itself is no odometry."""


def noisy_odometry(poses: np.ndarray, fraction: float, seed: int) -> np.ndarray:
    """Odometry rebuilt from the increments of `poses` (in each previous pose's frame), each
    component perturbed by zero-mean Gaussian noise with SD = fraction x |component|."""
    poses = np.asarray(poses, dtype=float)
    # -0.5 or NaN added no noise without a word
    fraction = check_number(
        fraction, "noisy_odometry: fraction", 0.0, NOISE_FRACTION_LIMIT, high_open=True
    )
    if poses.ndim != 2 or poses.shape[1] != 3 or not np.isfinite(poses).all():
        raise ValueError(
            f"noisy_odometry: poses must be an (n, 3) array of finite numbers, got {poses.shape}"
        )
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
