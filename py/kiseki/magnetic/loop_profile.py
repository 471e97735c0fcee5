# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The field along a closed loop as a function of travel distance: one 1-D Gaussian process per
channel, fitted to a mapping lap's readings (kiseki's loop filter,
:mod:`kiseki.magnetic.loop_travel_distance`).

* Inputs: the readings' travel distances s in [0, L) along a loop of length L and one value per
  reading. The loop closes, so each reading is also placed at s - L and s + L before the fit:
  the map is continuous across the lap's seam, and the GP at either end sees the other.
* Hyperparameters sigma_f, l, sigma_n by maximum marginal likelihood (:func:`kiseki.gp.
  fit_hyperparameters`, the thesis' eqs. 6.11-6.15) on the lap's readings alone, each once:
  sigma_n is then what the mapping lap says about its own noise, and l its own length scale;
  nothing is set by hand. The copies at s - L and s + L are for the map's continuity, not more
  data: in the likelihood they would count each reading three times and cost 27 times as much
  (n^3; a lap of MAX_READINGS would need 12,000-point factorisations).
* The mean and the variance of the noise-free field (eqs. 6.8-6.9) are tabulated every
  ``resolution`` m over one period and read linearly between table points, the distance taken
  modulo L.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.gp import ExactGP, SquaredExponential, fit_hyperparameters

__all__ = ["LoopProfile", "fit_loop_profile", "heading_invariant_channels"]

RESOLUTION = 0.02
"""m: the table's spacing (a fifth of the linear map's 0.1 m nodes)."""
MAX_READINGS = 4000
"""Readings of one lap above which the fit refuses (3 copies each, exact GP: n^3)."""


@dataclass(frozen=True)
class LoopProfile:
    """A channel's GP along a loop of ``length`` m: mean and variance (units of the channel and
    their square) at ``i * resolution``, i = 0 .. len - 1, and the fitted kernel."""

    length: float
    resolution: float
    mean: np.ndarray
    variance: np.ndarray
    kernel: SquaredExponential

    def at(self, s: Any) -> tuple[np.ndarray, np.ndarray]:
        """(mean, variance of a reading: the field's variance plus sigma_n^2) at travel
        distances s (any shape), taken modulo the loop's length."""
        u = np.mod(np.asarray(s, dtype=np.float64), self.length) / self.resolution
        n = len(self.mean)
        lo = np.floor(u)
        f = u - lo
        i0 = lo.astype(np.int64) % n
        i1 = (i0 + 1) % n
        mean = self.mean[i0] * (1.0 - f) + self.mean[i1] * f
        var = self.variance[i0] * (1.0 - f) + self.variance[i1] * f
        return mean, var + self.kernel.sigma_n**2


def fit_loop_profile(
    s: Any,
    values: Any,
    length: float,
    *,
    noise_floor: float = 0.0,
    resolution: float = RESOLUTION,
    seed: int = 0,
) -> LoopProfile:
    """The profile of one channel (module text). ``s`` (n,) m in [0, length], ``values`` (n,);
    ``noise_floor``: the least sigma_n (the channel's units) the profile keeps, for a lap whose
    readings carry no noise (a synthetic one): without it the likelihood's width is zero."""
    check_number(length, "loop profile: the loop's length", 0.0, low_open=True, unit="m")
    if isinstance(resolution, bool) or not (
        isinstance(resolution, numbers.Real) and length / 100_000 <= resolution <= length / 4
    ):  # the profile's grid: 4 to 100,000 points (1e-9 m asked for 149 GiB)
        raise ValueError(
            f"loop profile: resolution must be in [length / 100000, length / 4], got {resolution!r}"
        )
    s = np.asarray(s, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    if s.ndim != 1 or v.shape != s.shape:
        raise ValueError(f"loop profile: s {s.shape} and values {v.shape} must be (n,) alike")
    check_number(noise_floor, "loop profile: noise_floor", 0.0)
    if len(s) < 4:
        raise ValueError(f"loop profile: {len(s)} readings; at least 4 are needed")
    if len(s) > MAX_READINGS:
        raise ValueError(f"loop profile: {len(s)} readings; at most {MAX_READINGS} per lap")
    if not (np.all(np.isfinite(s)) and np.all(np.isfinite(v))):
        raise ValueError("loop profile: s and values must be finite")
    if s.min() < -1e-9 or s.max() > length + 1e-9:
        raise ValueError(f"loop profile: s must lie in [0, {length}] m")
    fit = fit_hyperparameters(s[:, None], v[:, None], seed=seed, max_points=len(s))
    k = fit.kernel
    if k.sigma_n < noise_floor:
        k = SquaredExponential(max(k.sigma_f, noise_floor), k.length_scale, noise_floor)
    x = np.concatenate([s - length, s, s + length])[:, None]
    gp = ExactGP.fit(x, np.tile(v, 3)[:, None], kernel=k)
    grid = np.arange(0.0, length, resolution)
    mean, var = gp.predict(grid[:, None])
    return LoopProfile(
        float(length),
        float(resolution),
        np.ascontiguousarray(np.asarray(mean)[:, 0]),
        np.ascontiguousarray(np.asarray(var).reshape(len(grid), -1)[:, 0]),
        k,
    )


def heading_invariant_channels(field: Any) -> np.ndarray:
    """(n, 2): the vertical component and the horizontal magnitude of fields (n, 3) in a frame
    with z vertical: both are the same whichever way the sensor is turned about the vertical."""
    f = np.asarray(field, dtype=np.float64)
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"loop profile: fields must be (n, 3), got {f.shape}")
    return np.column_stack([f[:, 2], np.hypot(f[:, 0], f[:, 1])])
