# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The attitude a 3-axis gyro unit reports, with a stated error model, per axis (roll, pitch,
yaw), in degrees:

    error(t) = b t + N W(t) + s e,

- ``b``: the rate bias left after the start-up calibration, constant for a run and drawn once
  per seed, b ~ N(0, bias_sd^2) deg/s (a turn-on bias);
- ``N W(t)``: angle random walk, the integral of white rate noise, W a standard Wiener process,
  N in deg/sqrt(s);
- ``s e``: the reading's own error, e ~ N(0, 1) independent per reading (the rubble paper's
  sensor unit's figure of 0.5 deg, 1 sigma, an assumption kept from before).

So error(T) has mean 0 and SD sqrt(s^2 + (bias_sd T)^2 + N^2 T) at T seconds after the start:
the closed form :func:`error_sd` that the tests compare with.

Values (assumptions, stated): bias_sd = 0.01 deg/s (36 deg/h) and N = 0.005 deg/sqrt(s)
(0.3 deg/sqrt(h)): the order of a consumer MEMS rate gyro after a start-up calibration, whose
bias instability is quoted in tens of deg/h and its angle random walk in tenths of deg/sqrt(h).
The paper's unit (NEC Tokin) adds a geomagnetic sensor that "ドリフトによる誤差をキャンセルする"
(cancels the error from drift); its figures are not given, so drift is kept on all three axes as
the worst case, and setting bias_sd and N to 0 models the compensated unit.
"""

from __future__ import annotations

import math

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.core import Random, check_seed, derive_seed

__all__ = ["Gyro", "error_sd"]


def error_sd(t: float, reading_sd_deg: float, bias_sd_deg_s: float, arw_deg_rt_s: float) -> float:
    """SD (deg) of one axis's attitude error t seconds after the start (closed form)."""
    t = check_number(t, "gyro: t", 0.0, unit="s")
    return math.sqrt(reading_sd_deg**2 + (bias_sd_deg_s * t) ** 2 + arw_deg_rt_s**2 * t)


class Gyro:
    """A seeded 3-axis gyro: :meth:`read` adds the error at time t (s, non-decreasing from the
    start at t = 0) to the true attitude. The bias, the random walk and the readings' errors
    are three separate streams of the seed, so one reading's draws do not shift another's."""

    def __init__(
        self,
        reading_sd_deg: float = 0.5,
        bias_sd_deg_s: float = 0.01,
        arw_deg_rt_s: float = 0.005,
        seed: int = 0,
    ) -> None:
        self.reading_sd_deg = check_number(reading_sd_deg, "gyro: reading_sd_deg", 0.0)
        self.bias_sd_deg_s = check_number(bias_sd_deg_s, "gyro: bias_sd_deg_s", 0.0)
        self.arw_deg_rt_s = check_number(arw_deg_rt_s, "gyro: arw_deg_rt_s", 0.0)
        seed = check_seed(seed)
        self.bias_deg_s = self.bias_sd_deg_s * Random(derive_seed(seed, 0)).normal(0.0, 1.0, 3)
        self._walk_rng = Random(derive_seed(seed, 1))
        self._read_rng = Random(derive_seed(seed, 2))
        self._t = 0.0
        self._walk = np.zeros(3)  # N W(t) in degrees

    def error_deg(self, t: float) -> np.ndarray:
        """The drift part of the error at t (deg): b t + N W(t), advancing the walk to t."""
        t = check_number(t, "gyro: t", 0.0, unit="s")
        if t < self._t:
            raise ValueError(f"gyro: time must not go back, got {t} s after {self._t} s")
        if t > self._t and self.arw_deg_rt_s > 0:
            step = math.sqrt(t - self._t) * self._walk_rng.normal(0.0, 1.0, 3)
            self._walk = self._walk + self.arw_deg_rt_s * step
        self._t = t
        return self.bias_deg_s * t + self._walk

    def read(self, true_rpy, t: float) -> np.ndarray:
        """The reported (roll, pitch, yaw) in radians: the true attitude plus the error at t."""
        rpy = np.asarray(true_rpy, dtype=float)
        if rpy.shape != (3,) or not np.isfinite(rpy).all():
            raise ValueError(f"gyro: true attitude must be 3 finite angles (rad), got {true_rpy!r}")
        drift = self.error_deg(t)
        noise = self.reading_sd_deg * self._read_rng.normal(0.0, 1.0, 3)
        return rpy + np.radians(drift + noise)
