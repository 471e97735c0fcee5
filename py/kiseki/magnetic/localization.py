# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Monte Carlo localization on a 2-D magnetic field map (thesis chapter 6.7, eqs. 6.17-6.18).

The particle filter is kiseki's engine (:class:`kiseki.filters.MonteCarloLocalizer`); the
measurement model is :class:`MagneticMapModel` (C++: ``kiseki/models/magnetic_map_model.hpp``):
each magnetometer's 3-axis reading is Gaussian about the map's mean at the sensor's position,
with the map's variance plus the sensor's noise, and the sensors are independent (eq. 6.18).
The thesis' settings: 1000 particles, resampling when the ESS falls below n/2.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from tqdm import tqdm

from kiseki import _core
from kiseki._support.field_types import check_field_types
from kiseki._support.real_numbers import check_number
from kiseki.core import check_seed
from kiseki.filters import REAL_ODOMETRY_ALPHAS, MclConfig, MonteCarloLocalizer
from kiseki.filters.initial_pose import check_spread

__all__ = [
    "FRAMES",
    "MagneticLocalization",
    "MagneticMapModel",
    "MagneticMclConfig",
    "check_stream",
    "localize_on_magnetic_map",
    "map_noise_sd",
    "sensor_offsets",
]

# body: x forward, y left, z up (REP-103); sensor: the thesis' x forward, y right, z down;
# world: readings already turned into the map's frame (the Aalto recordings).
FRAMES = ("body", "sensor", "world")


def sensor_offsets(offsets: Any) -> np.ndarray:
    """(s, 2) magnetometer offsets on the robot, checked."""
    o = np.asarray(offsets, dtype=float)
    if o.ndim == 1 and o.size == 2:
        o = o[None, :]
    if o.ndim != 2 or o.shape[1] != 2 or len(o) < 1 or not np.isfinite(o).all():
        raise ValueError(
            f"offsets: expected finite (x, y) per sensor, shape (s, 2), got {np.shape(offsets)}"
        )
    return o


class MagneticMapModel:
    """Eqs. 6.17-6.18 on a 2-D :class:`kiseki.magnetic.field_map.MagneticFieldMap`.

    offsets: each magnetometer's (x, y) on the robot (body frame, m); noise_sd: the sensors'
    noise (the map's units); frame: that of the readings (see ``FRAMES``)."""

    def __init__(self, field_map: Any, offsets: Any, noise_sd: float, frame: str = "body") -> None:
        if getattr(field_map, "dimension", None) != 2:
            raise ValueError("magnetic-map localization needs a 2-D field map (dimension 2)")
        if frame not in FRAMES:
            raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
        noise_sd = check_number(noise_sd, "noise_sd", 0.0)
        self.offsets = sensor_offsets(offsets)
        self.frame = frame
        self.field_map = field_map
        origin = np.asarray(field_map.origin, dtype=float)
        self.core = _core.MagneticMapModel(
            np.ascontiguousarray(field_map.mean, dtype=float),
            np.ascontiguousarray(field_map.variance, dtype=float),
            float(origin[0]),
            float(origin[1]),
            float(field_map.resolution),
            np.asarray(field_map.prior_mean, dtype=float),
            np.asarray(field_map.prior_variance, dtype=float),
            self.offsets,
            float(noise_sd),
            frame == "world",
        )

    def set_readings(self, readings: Any) -> _core.MagneticMapModel:
        """One (mx, my, mz) per sensor, in the model's frame; returns the C++ model."""
        r = np.array(readings, dtype=float, copy=True)
        if r.shape != (len(self.offsets), 3):
            raise ValueError(f"readings: expected shape ({len(self.offsets)}, 3), got {r.shape}")
        if self.frame == "sensor":  # x forward, y right, z down -> x forward, y left, z up
            r[:, 1:] *= -1.0
        self.core.set_readings(r)
        return self.core

    def log_likelihoods(self, poses: Any, readings: Any) -> np.ndarray:
        """log p(z | x) at robot poses (n, 3) for one set of readings."""
        return np.asarray(
            self.set_readings(readings).log_likelihoods(np.asarray(poses, dtype=float))
        )


@dataclass(frozen=True)
class MagneticMclConfig:
    """The filter's settings. particles 1000 and resample_threshold 0.5 (ESS < n/2) are the
    thesis'; alphas the engine's odometry noise for a real wheeled robot
    (``kiseki.filters.REAL_ODOMETRY_ALPHAS``); noise_sd None: the map's kernel sigma_n;
    update_min_d: travel between updates (0: every reading)."""

    particles: int = 1000
    resample_threshold: float = 0.5
    alphas: tuple[float, ...] = REAL_ODOMETRY_ALPHAS
    noise_sd: float | None = None
    update_min_d: float = 0.0
    initial_sd: tuple[float, float, float] = (0.3, 0.3, 0.1)
    threads: int = 0

    def __post_init__(self) -> None:
        check_field_types(self)
        if self.noise_sd is not None:
            check_number(
                self.noise_sd,
                "MagneticMclConfig.noise_sd",
                0.0,
                unit="(or None: the map's sigma_n)",
            )
        check_spread("initial_sd", self.initial_sd)  # 1e300 was refused only by the run
        self.mcl()  # the engine's own checks

    def mcl(self) -> MclConfig:
        return MclConfig(
            particles=self.particles,
            resample_threshold=self.resample_threshold,
            alphas=tuple(self.alphas),
            update_min_d=self.update_min_d,
            threads=self.threads,
        )

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class MagneticLocalization:
    """Estimates (T, 3) after each step, the effective sample size at each update, and how
    many updates resampled."""

    estimates: np.ndarray
    ess: np.ndarray
    resamplings: int
    config: MagneticMclConfig
    extra: dict = field(default_factory=dict)


def map_noise_sd(field_map: Any) -> float:
    """The largest sigma_n of a field map's kernel(s): a reading's noise about the map."""
    kernel = field_map.kernel
    kernels = kernel if isinstance(kernel, Sequence) else (kernel,)
    return float(max(k.sigma_n for k in kernels))


def check_stream(odometry: Any, readings: Any, sensors: int) -> tuple[np.ndarray, np.ndarray]:
    """(odometry poses (T, 3), readings (T, sensors, 3)), finite, or ValueError naming the
    first bad step."""
    odo = np.asarray(odometry, dtype=float)
    if odo.ndim != 2 or odo.shape[1] != 3 or len(odo) < 1 or not np.isfinite(odo).all():
        raise ValueError(
            f"odometry: expected finite poses of shape (T, 3), got {np.shape(odometry)}"
        )
    z = np.asarray(readings, dtype=float)
    if z.shape != (len(odo), sensors, 3):
        raise ValueError(f"readings: expected shape ({len(odo)}, {sensors}, 3), got {z.shape}")
    bad = ~np.isfinite(z).all(axis=(1, 2))
    if bad.any():
        raise ValueError(f"readings: step {int(np.argmax(bad))} has NaN or infinite values")
    return odo, z


def localize_on_magnetic_map(
    field_map: Any,
    odometry: Any,
    readings: Any,
    offsets: Any,
    *,
    initial_pose: Any,
    config: MagneticMclConfig | None = None,
    seed: int = 0,
    frame: str = "body",
    progress: bool = False,
) -> MagneticLocalization:
    """Runs the filter over a recording: odometry poses (T, 3) and the magnetometers' readings
    (T, s, 3) at the same instants. Particles start Gaussian about initial_pose with
    config.initial_sd."""
    config = config or MagneticMclConfig()
    seed = check_seed(seed)
    off = sensor_offsets(offsets)
    odo, z = check_stream(odometry, readings, len(off))
    noise = map_noise_sd(field_map) if config.noise_sd is None else config.noise_sd
    model = MagneticMapModel(field_map, off, noise, frame)
    localizer = MonteCarloLocalizer(config.mcl(), seed)
    localizer.initialize(np.asarray(initial_pose, dtype=float), config.initial_sd)
    estimates = np.empty_like(odo)
    ess: list[float] = []
    resamplings = 0
    steps = range(len(odo))
    if progress:
        steps = tqdm(steps, desc="magnetic MCL", unit="step")
    for t in steps:
        report = localizer.step(odo[t], lambda t=t: model.set_readings(z[t]))
        if report is not None:
            ess.append(float(report.effective_sample_size))
            resamplings += int(bool(report.resampled))
        estimates[t] = localizer.estimate
    return MagneticLocalization(estimates, np.asarray(ess), resamplings, config)
