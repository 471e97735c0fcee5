# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic-map MCL with several magnetometers, each on its own map (thesis eq. 6.18: the
sensors are independent, so their likelihoods multiply), with a check that drops a sensor whose
readings drift away from its map.

* Each sensor s has its own 2-D field map (built from its own readings: two devices on one
  robot differ by their calibration) and its own :class:`~kiseki.magnetic.localization.
  MagneticMapModel`; the filter's log-likelihood is the sum over the trusted sensors.
* **The drift check** (kiseki's; the thesis trusts its sensors): after each update, each
  trusted sensor's innovation at the estimate, ``(reading - map mean) / sqrt(map variance +
  noise^2)`` per axis, is averaged over its last ``window`` updates. Where the sensor agrees
  with its map this mean stays within about +-1 (the map's errors along a path are correlated,
  so they do not average out, but they are what the map's variance says). A sensor whose mean
  exceeds ``limit`` (3) on any axis is dropped, the one with the largest first, never the
  last trusted one, and the drop is reported (update, axis, mean). A steady offset of three
  predicted SDs is what a drifting axis gives (the Nexus' z: +10 uT in Aalto run 5).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import hold_number
from kiseki.core import check_seed
from kiseki.filters import MonteCarloLocalizer
from kiseki.magnetic.localization import (
    MagneticLocalization,
    MagneticMapModel,
    MagneticMclConfig,
    check_stream,
    map_noise_sd,
    sensor_offsets,
)

__all__ = ["DriftCheck", "SensorDrop", "localize_with_magnetometers"]


@dataclass(frozen=True)
class DriftCheck:
    """The drift check's settings (module text)."""

    window: int = 20  # updates averaged (at 0.1 m between updates: 2 m of travel)
    limit: float = 3.0  # |mean normalised innovation| above which a sensor is dropped

    def __post_init__(self) -> None:
        window = check_count(self.window, "drift check: window", 2)
        object.__setattr__(self, "window", window)  # a numpy integer held as a Python int
        hold_number(self, "limit", "drift check: limit", 0.0, low_open=True)


@dataclass(frozen=True)
class SensorDrop:
    """A sensor the drift check dropped: at update ``update``, its mean normalised innovation
    ``mean`` on ``axis`` (0 x, 1 y, 2 z) over the window."""

    sensor: int
    update: int
    axis: int
    mean: float


@dataclass
class _Innovations:
    """The last ``window`` normalised innovations (3 axes) of one sensor."""

    window: int
    values: list = field(default_factory=list)

    def add(self, z: np.ndarray) -> np.ndarray | None:
        self.values.append(z)
        if len(self.values) > self.window:
            self.values.pop(0)
        return np.mean(self.values, axis=0) if len(self.values) == self.window else None


def _sensor_world(pose: np.ndarray, offset: np.ndarray) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return pose[:2] + np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1]])


def localize_with_magnetometers(
    field_maps: Sequence[Any],
    odometry: Any,
    readings: Any,
    offsets: Any,
    *,
    initial_pose: Any,
    config: MagneticMclConfig | None = None,
    seed: int = 0,
    frame: str = "world",
    drift: DriftCheck | None = DriftCheck(),
) -> MagneticLocalization:
    """MCL over odometry poses (T, 3) and readings (T, s, 3) of s sensors, sensor i read
    against ``field_maps[i]`` at its (x, y) ``offsets[i]`` on the robot (module text).
    ``drift=None`` trusts every sensor throughout. The result's ``extra["dropped"]`` lists
    the :class:`SensorDrop` records, ``extra["trusted"]`` (T, s) which sensors weighed."""
    config = config or MagneticMclConfig()
    seed = check_seed(seed)
    maps = list(field_maps)
    off = sensor_offsets(offsets)
    if not maps or len(maps) != len(off):
        raise ValueError(f"{len(maps)} field map(s) for {len(off)} sensor offset(s)")
    odo, z = check_stream(odometry, readings, len(off))
    if drift is not None and not isinstance(drift, DriftCheck):
        raise ValueError("drift must be a DriftCheck or None")
    noises = [map_noise_sd(m) if config.noise_sd is None else config.noise_sd for m in maps]
    models = [MagneticMapModel(m, off[i : i + 1], noises[i], frame) for i, m in enumerate(maps)]
    localizer = MonteCarloLocalizer(config.mcl(), seed)
    localizer.initialize(np.asarray(initial_pose, dtype=float), config.initial_sd)
    trusted = np.ones(len(maps), dtype=bool)
    history = [_Innovations(drift.window if drift else 2) for _ in maps]
    estimates, trust = np.empty_like(odo), np.empty((len(odo), len(maps)), dtype=bool)
    ess, dropped, resamplings = [], [], 0

    for t in range(len(odo)):

        def log_l(poses, t=t):
            return sum(
                models[i].log_likelihoods(poses, z[t, i : i + 1]) for i in np.flatnonzero(trusted)
            )

        report = localizer.step_log_likelihoods(odo[t], log_l, readings=int(trusted.sum()))
        if report is not None:
            ess.append(float(report.effective_sample_size))
            resamplings += int(bool(report.resampled))
        estimates[t] = localizer.estimate
        trust[t] = trusted
        if drift is None or report is None:
            continue
        worst = None
        for i in np.flatnonzero(trusted):
            where = _sensor_world(estimates[t], off[i])
            mean, var = maps[i].value_at(where[None, :])
            normalised = (z[t, i] - mean[0]) / np.sqrt(var[0] + noises[i] ** 2)
            avg = history[i].add(normalised)
            if avg is not None and np.max(np.abs(avg)) > drift.limit:
                axis = int(np.argmax(np.abs(avg)))
                if worst is None or abs(avg[axis]) > abs(worst.mean):
                    worst = SensorDrop(int(i), t, axis, float(avg[axis]))
        if worst is not None and trusted.sum() > 1:
            trusted[worst.sensor] = False
            dropped.append(worst)
    result = MagneticLocalization(estimates, np.asarray(ess), resamplings, config)
    result.extra = {"dropped": dropped, "trusted": trust}
    return result
