# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The thesis' travel-distance filter (sec. 4.4.1), printed, never asserted: CPU time per
update with 1000 particles at 10 Hz (0.6 m/s, a 0.1 G disturbance every 10 m, a 6 m window of
mz) and the share of one core it takes, kiseki's (:class:`TravelDistanceLocalizer` on the C++
engine) beside a plain numpy filter of the same equations (np.interp for the map, numpy
Gaussian motion, systematic resampling in numpy when ESS < 9n/10), with both filters' travel
distance errors. Goal (issue 11): under 1 % of a core.

Run: python benchmarks/bench_travel_distance.py
"""

from __future__ import annotations

import time

import numpy as np

from arguments import no_options  # beside this file
from kiseki.magnetic.linear_map import build_linear_map
from kiseki.magnetic.travel_distance import TravelDistanceConfig, TravelDistanceLocalizer
from timing import machine_line  # beside this file

RATE = 10.0  # Hz
SPEED = 0.6  # m/s
LENGTH = 120.0  # m


def field(x: np.ndarray) -> np.ndarray:
    """mz (G): 0.45 G with a 0.1 G disturbance every 10 m (sec. 4.5.1, Fig. 4.5)."""
    return 0.45 + 0.1 * np.exp(-0.5 * ((np.asarray(x) % 10.0 - 5.0) / 0.4) ** 2)


class NumpyFilter:
    """The same filter in plain numpy: eqs. 4.6-4.11, one array per state."""

    def __init__(self, node_s, node_mz, config: TravelDistanceConfig) -> None:
        self.s, self.mz, self.c = node_s, node_mz, config
        self.rng = np.random.default_rng(config.seed)
        self.p = np.zeros(config.particles)
        self.odometry = 0.0
        self.u: list[float] = []
        self.m: list[float] = []

    def step(self, distance: float, mz: float) -> float:
        c, n = self.c, self.c.particles
        self.p += distance + self.rng.normal(0.0, c.odometry_noise * np.sqrt(abs(distance)), n)
        self.odometry += distance
        self.u.append(self.odometry)
        self.m.append(mz)
        k = np.floor((self.odometry - np.array(self.u)) / 0.1 + 0.5).astype(int)
        bins = int(round(c.window / 0.1))
        keep = (k >= 0) & (k < bins)
        count = np.bincount(k[keep], minlength=bins)
        total = np.bincount(k[keep], weights=np.array(self.m)[keep], minlength=bins)
        filled = np.flatnonzero(count)
        readings = total[filled] / count[filled]
        expected = np.interp(self.p[:, None] - filled[None, :] * 0.1, self.s, self.mz)
        s = np.abs(expected - readings).sum(axis=1) * 0.1  # eq. 4.7
        w = 1.0 / (c.gain * s + 1.0)  # eq. 4.8
        w /= w.sum()  # eq. 4.9
        estimate = float(w @ self.p)  # eq. 4.10
        if 1.0 / (w @ w) < c.resample_threshold * n:  # eq. 4.11, 9n/10
            edges = np.cumsum(w)
            edges[-1] = 1.0
            picks = (self.rng.random() + np.arange(n)) / n
            self.p = self.p[np.searchsorted(edges, picks)]
        if len(self.u) > 4 * bins:  # forget readings far behind the window
            self.u, self.m = self.u[-2 * bins :], self.m[-2 * bins :]
        return estimate


def timed(step, increments, readings) -> tuple[np.ndarray, float]:
    start = time.process_time()
    out = np.array([step(float(d), float(m)) for d, m in zip(increments, readings, strict=True)])
    return out, (time.process_time() - start) / len(increments)


def main() -> None:
    print(machine_line(), flush=True)
    s = np.arange(0.0, LENGTH + 10.0, SPEED / RATE)
    readings = np.column_stack([np.zeros_like(s), np.zeros_like(s), field(s)])
    linear_map = build_linear_map(s, readings, np.zeros_like(s), path_id="0" * 40)
    rng = np.random.default_rng(0)
    true = np.arange(0.0, LENGTH, SPEED / RATE)
    increments = np.diff(true, prepend=0.0) * 1.05  # odometry 5 % long
    mz = field(true) + rng.normal(0.0, 0.01, len(true))
    config = TravelDistanceConfig()
    kiseki_filter = TravelDistanceLocalizer(linear_map, config)
    plain = NumpyFilter(linear_map.s, linear_map.field[:, 2], config)
    est_k, cpu_k = timed(kiseki_filter.step, increments, mz)
    est_n, cpu_n = timed(plain.step, increments, mz)
    odom = np.cumsum(increments)
    rms = {
        k: float(np.sqrt(np.mean((v - true) ** 2)))
        for k, v in (("kiseki", est_k), ("numpy", est_n), ("odometry", odom))
    }
    print(
        f"{config.particles} particles, {RATE:g} Hz, window {config.window:g} m, "
        f"{len(true)} updates over {LENGTH:g} m"
    )
    for name, cpu in (("kiseki (C++ engine)", cpu_k), ("plain numpy", cpu_n)):
        print(
            f"  {name:20s} {cpu * 1e3:7.3f} ms CPU per update = {cpu * RATE * 100:5.2f} % "
            "of a core at 10 Hz"
        )
    print(f"  speed-up {cpu_n / cpu_k:.2f}x; goal < 1 % of a core")
    print(
        f"  travel distance RMSE: kiseki {rms['kiseki']:.3f} m, numpy {rms['numpy']:.3f} m, "
        f"odometry {rms['odometry']:.3f} m"
    )


if __name__ == "__main__":
    no_options(__doc__)
    main()
