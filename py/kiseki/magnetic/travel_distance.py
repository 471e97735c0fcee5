# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The travel-distance localization of the magnetic-navigation thesis
(``002_74cea16d239c028f.txt``, sec. 4.4.1) and its azimuth heading correction (sec. 4.4.2), on
kiseki's 1-D particle engine :class:`kiseki._core.TravelDistanceFilter`.

Travel distance (sec. 4.4.1), per reading:

* motion, eq. 4.6: ``d_t = d_{t-1} + delta d_t``; the thesis writes no noise term, but a
  particle filter needs one to spread its particles: each particle adds N(0, sigma^2) with
  ``sigma = odometry_noise * sqrt(|delta d|)`` (a random walk whose variance grows with the
  distance travelled, so the spread does not depend on the reading rate);
* the readings of the last ``l`` metres of travel are kept ("first the magnetometer's readings
  over l m of travel are accumulated"), indexed by the odometry's travel distance and averaged
  per 0.1 m bin, the map's own node spacing (sec. 3.3.2);
* eq. 4.7: ``s_i = int_{d_i - l}^{d_i} |map m(d) - sensor m(d)| dd``, the sum over the window's
  bins of the absolute difference times the bin width, the map read at particle i's alignment
  (bin k, k * 0.1 m behind the newest reading, against the map at ``d_i - k * 0.1``, linear
  between nodes, the end nodes' values beyond the map's ends);
* eq. 4.8: ``w_i = 1 / (a s_i + 1)``, a = 50; eq. 4.9: normalised. The thesis sets the weights
  from s alone at each step (eq. 4.8 has no previous weight in it: the window already holds the
  history), so the engine's weights are set to uniform before ``update(log w)``;
* eq. 4.10: the estimate is the weighted mean ``sum w_i d_i`` of these weights (computed before
  the engine resamples);
* eq. 4.11: ``ESS = 1 / sum w_i^2``; resampling only when ESS < 9n/10 (the engine's
  ``resample_threshold`` 0.9).

Which field enters |m - m_map|: the z component (down) only. The thesis says so for the same
linear map in ch. 3: "the x and y components change with the robot's heading, so only the z
component is used for localization" (sec. 3.3.2); eq. 4.7 writes a scalar |.| of the "field
strength" plotted as one curve in Fig. 4.5, and the heading correction of sec. 4.4.2 also uses
m_z for its gate (eq. 4.5). A heading error of a few degrees turns mx and my by
|m_h| * sin(error), as much as the disturbances the filter looks for.

Units: G, as in the thesis (a = 50 is per G m; the gates' dm_z,max = 1 G). Readings in uT are
divided by 100 first.

The window length l: the thesis names it ("l m") without a value. We take 6 m, the length of the
mz window Rahok's travel-distance correction keeps (sec. 3.3.2, "6 m of field strength every
10 cm"), and say so wherever a result depends on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from kiseki import _core
from kiseki._support.counts import check_count
from kiseki._support.field_types import check_field_types
from kiseki._support.options import PARTICLE_LIMIT
from kiseki._support.real_numbers import check_number, hold_number
from kiseki.core import check_seed
from kiseki.magnetic.linear_map import LinearMagneticMap

__all__ = [
    "GAIN",
    "R_THETA_GATE",
    "R_Z_GATE",
    "WINDOW",
    "HeadingCorrection",
    "TravelDistanceConfig",
    "TravelDistanceLocalizer",
    "azimuth_heading",
    "heading_from_map",
    "MapWindows",
]

GAIN = 50.0
"""a of eq. 4.8, per G m (sec. 4.4.1: "a is a gain, 50 in the implementation")."""
WINDOW = 6.0
"""m: l of eq. 4.7 (no value in the thesis; Rahok's 6 m window of sec. 3.3.2)."""
R_Z_GATE = 0.992
"""r_z of eq. 4.5 at or above which the heading is corrected (sec. 4.4.2)."""
R_THETA_GATE = 0.990
"""r_theta of eq. 4.13 at or above which the heading is corrected (sec. 4.4.2)."""
DM_Z_MAX = 1.0
"""G: dm_z,max of eq. 4.5 ("= 1")."""
DM_THETA_MAX = math.pi
"""rad: dm_theta,max of eq. 4.13 ("= pi rad")."""


@dataclass(frozen=True)
class TravelDistanceConfig:
    """The filter's settings (sec. 4.4.1; see the module text)."""

    particles: int = 1000  # sec. 4.5.1, Fig. 4.7: "1000 particles"
    gain: float = GAIN  # a of eq. 4.8, per G m
    window: float = WINDOW  # l of eq. 4.7, m
    odometry_noise: float = 0.1  # m per sqrt(m) of travel, the motion's spread
    initial_sd: float = 0.0  # m, spread of the particles around the start
    resample_threshold: float = 0.9  # ESS < 9n/10 (sec. 4.4.1)
    seed: int = 0

    def __post_init__(self) -> None:
        check_field_types(self)
        check_count(self.particles, "travel distance: particles", 1, PARTICLE_LIMIT)

        def hold(name: str, label: str, *bounds: float, **rule: Any) -> None:
            hold_number(self, name, f"travel distance: {label}", *bounds, **rule)

        hold("gain", "gain a", 0.0, low_open=True)
        hold("window", "window l", 0.0, low_open=True, unit="m")
        hold("odometry_noise", "odometry_noise", 0.0)
        hold("initial_sd", "initial_sd", 0.0, unit="m")
        hold("resample_threshold", "resample_threshold", 0.0, 1.0)
        check_seed(self.seed, "travel distance: seed")


def _map_profile(linear_map: Any) -> tuple[np.ndarray, np.ndarray, float]:
    """(node s, node mz in G, spacing) of a linear map."""
    if not isinstance(linear_map, LinearMagneticMap):
        raise ValueError(
            f"travel distance: the map must be a LinearMagneticMap, got {type(linear_map).__name__}"
        )
    if len(linear_map) < 2:
        raise ValueError(f"travel distance: the map has {len(linear_map)} node(s); 2 are needed")
    mz = np.asarray(linear_map.field[:, 2], dtype=np.float64)
    if not np.all(np.isfinite(mz)):
        raise ValueError("travel distance: the map's mz holds NaN or infinity")
    return np.asarray(linear_map.s, dtype=np.float64), mz, float(linear_map.spacing)


class MapWindows:
    """The map's mz (G, nodes at ``first_s + j * spacing``) padded for windows of ``bins``
    bins (the first node's value before the map, the last one's after it, as ``np.interp``
    clamps): row i of ``low`` holds ``bins`` consecutive node values, row i of ``slope`` the
    differences to the next node; both are views, gathered by a particle's node index."""

    def __init__(self, first_s: float, spacing: float, node_mz: np.ndarray, bins: int) -> None:
        self.first_s, self.spacing, self.bins, self.nodes = first_s, spacing, bins, len(node_mz)
        edge = (np.full(bins + 1, node_mz[0]), np.full(bins + 2, node_mz[-1]))
        padded = np.concatenate([edge[0], node_mz, edge[1]])
        window = np.lib.stride_tricks.sliding_window_view  # views: no copy of the map
        self.low = window(padded[:-1], bins)  # row i: padded[i : i + bins]
        self.slope = window(np.diff(padded), bins)

    def mismatch(self, particles: np.ndarray, readings: np.ndarray, mask: np.ndarray) -> np.ndarray:
        """Eq. 4.7 for every particle: ``sum_k mask_k |map mz(d_i - k * spacing) - r_k| *
        spacing`` (G m), k = 0 .. bins - 1, the map linear between nodes. The bins are whole
        node spacings, so a particle's fraction between nodes is the same for all of them: its
        window is one row of node values and one of slopes, in reverse order of k."""
        u = (particles - self.first_s) / self.spacing
        base = np.floor(u)
        frac = (u - base)[:, None]
        # row b + 2 holds nodes b - bins + 1 .. b (k = bins - 1 .. 0); beyond these bounds
        # every value is an end node's
        row = np.clip(base, -2, self.nodes + self.bins).astype(np.int64) + 2
        expected = self.slope[row]
        expected *= frac
        expected += self.low[row]
        expected -= readings[::-1]
        np.abs(expected, out=expected)
        return (expected @ mask[::-1]) * self.spacing


class TravelDistanceLocalizer:
    """Travel distance along a :class:`LinearMagneticMap` from odometry increments and mz
    readings (G, sensor z down), on the C++ engine. ``start``: the travel distance at the first
    reading (m). Seeded: the same config and inputs give the same estimates."""

    def __init__(
        self,
        linear_map: LinearMagneticMap,
        config: TravelDistanceConfig | None = None,
        start: float = 0.0,
    ) -> None:

        self.config = TravelDistanceConfig() if config is None else config
        if not isinstance(self.config, TravelDistanceConfig):
            raise ValueError("travel distance: config must be a TravelDistanceConfig")
        start = check_number(start, "travel distance: start", unit="m")
        self._s, self._mz, self._spacing = _map_profile(linear_map)
        params = _core.TravelDistanceParams()
        params.particles = self.config.particles
        params.resample_threshold = self.config.resample_threshold
        self._filter = _core.TravelDistanceFilter(params, self.config.seed)
        self._filter.initialize(float(start), self.config.initial_sd)
        self._bins = int(round(self.config.window / self._spacing))
        if self._bins < 1:
            raise ValueError(
                f"travel distance: window l {self.config.window} m is shorter than the map's "
                f"{self._spacing} m node spacing"
            )
        # beyond the map the window compares the padding only; each step gathers particles x
        # bins values (15 GiB at l = 1e6 m): at most twice the map's length, or 100 m
        longest = max(2.0 * len(self._mz) * self._spacing, 100.0)
        if self.config.window > longest:
            raise ValueError(
                f"travel distance: window l {self.config.window:g} m is longer than twice the "
                f"map ({len(self._mz)} nodes, {len(self._mz) * self._spacing:g} m) or 100 m"
            )
        self._windows = MapWindows(float(self._s[0]), self._spacing, self._mz, self._bins)
        self._odometry = 0.0
        self._u = np.empty(64)  # the readings' odometry distances, live in [_lo, _hi)
        self._m = np.empty(64)
        self._lo = self._hi = 0
        self._uniform = np.full(self.config.particles, 1.0 / self.config.particles)
        self.estimate = float(start)
        self.effective_sample_size = float(self.config.particles)
        self.resampled = False
        self.weights = self._uniform.copy()

    @property
    def particles(self) -> np.ndarray:
        return np.asarray(self._filter.particles)

    def window_readings(self) -> tuple[np.ndarray, np.ndarray]:
        """(mean mz G, 1 where the bin holds readings else 0) of the window's bins k = 0, 1, ...,
        each k node spacings behind the newest reading."""
        u, m = self._u[self._lo : self._hi], self._m[self._lo : self._hi]
        k = np.floor((self._odometry - u) / self._spacing + 0.5).astype(np.int64)
        keep = (k >= 0) & (k < self._bins)
        k, m = k[keep], m[keep]
        count = np.bincount(k, minlength=self._bins)
        total = np.bincount(k, weights=m, minlength=self._bins)
        return total / np.maximum(count, 1), (count > 0).astype(np.float64)

    def _keep(self, mz: float) -> None:
        """Appends the newest reading; drops those more than l + one bin behind."""
        if self._hi == len(self._u):
            n = self._hi - self._lo
            u, m = np.empty(max(64, 2 * n)), np.empty(max(64, 2 * n))
            u[:n], m[:n] = self._u[self._lo : self._hi], self._m[self._lo : self._hi]
            self._u, self._m, self._lo, self._hi = u, m, 0, n
        self._u[self._hi], self._m[self._hi] = self._odometry, mz
        self._hi += 1
        horizon = self._odometry - self.config.window - self._spacing
        while self._lo < self._hi - 1 and self._u[self._lo] < horizon:
            self._lo += 1

    def step(self, distance: float, mz: float) -> float:
        """One reading: the odometry's travel since the last reading (m) and mz (G). Returns
        the estimate of eq. 4.10."""
        distance = check_number(distance, "travel distance: the odometry increment", unit="m")
        mz = check_number(mz, "travel distance: the mz reading", unit="G")
        sd = self.config.odometry_noise * math.sqrt(abs(distance))
        self._filter.predict(float(distance), sd)  # eq. 4.6 plus the spread
        self._odometry += float(distance)
        self._keep(float(mz))
        readings, mask = self.window_readings()
        particles = self.particles
        s = self._windows.mismatch(particles, readings, mask)
        w = 1.0 / (self.config.gain * s + 1.0)  # eq. 4.8
        w /= w.sum()  # eq. 4.9
        self.weights = w
        self.estimate = float(np.dot(w, particles))  # eq. 4.10
        self.effective_sample_size = float(1.0 / np.dot(w, w))  # eq. 4.11
        self.resampled = self.effective_sample_size < self.config.resample_threshold * len(w)
        self._filter.set_weights(self._uniform)  # eq. 4.8 replaces the weights
        self._filter.update(np.log(w))
        return self.estimate

    def run(self, distances: Any, mz: Any) -> np.ndarray:
        """:meth:`step` over a stream: increments (n,) m and mz (n,) G; the estimates (n,)."""
        d = _stream(distances, "the odometry increments")
        m = _stream(mz, "the mz readings")
        if d.shape != m.shape:
            raise ValueError(
                f"travel distance: {d.shape[0]} odometry increments but {m.shape[0]} mz readings"
            )
        return np.array([self.step(float(a), float(b)) for a, b in zip(d, m, strict=True)])


def _stream(values: Any, name: str) -> np.ndarray:
    try:
        a = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"travel distance: {name} must be numbers") from None
    if a.ndim != 1:
        raise ValueError(f"travel distance: {name} must be one-dimensional, got shape {a.shape}")
    bad = ~np.isfinite(a)
    if bad.any():
        raise ValueError(f"travel distance: {name}[{int(np.argmax(bad))}] is NaN or infinity")
    return a


class HeadingCorrection(NamedTuple):
    """The heading after sec. 4.4.2 (rad), whether the gates held, and r_z, r_theta."""

    theta: float
    applied: bool
    r_z: float
    r_theta: float


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def azimuth_heading(
    theta: float,
    m_theta: float,
    m_z: float,
    node_heading: float,
    node_m_theta: float,
    node_m_z: float,
    r_z_gate: float = R_Z_GATE,
    r_theta_gate: float = R_THETA_GATE,
) -> HeadingCorrection:
    """Sec. 4.4.2: the node's azimuth ``theta_(n,m) = theta_n - m_theta,n`` (eq. 4.12 on the
    map); ``r_z = 1 - |m_z,n - m_z,t| / dm_z,max`` (eq. 4.5, dm_z,max = 1 G) and
    ``r_theta = 1 - |m_theta,n - m_theta,t| / pi`` (eq. 4.13, the difference wrapped to
    [0, pi]); when ``r_z >= 0.992`` and ``r_theta >= 0.990`` the heading becomes
    ``theta_(n,m) + m_theta,t`` (eq. 4.14), otherwise it stays ``theta``. Angles rad, fields G."""
    values = (theta, m_theta, m_z, node_heading, node_m_theta, node_m_z, r_z_gate, r_theta_gate)
    names = (
        "theta",
        "m_theta",
        "m_z",
        "node_heading",
        "node_m_theta",
        "node_m_z",
        "r_z_gate",
        "r_theta_gate",
    )
    theta, m_theta, m_z, node_heading, node_m_theta, node_m_z, r_z_gate, r_theta_gate = (
        check_number(value, f"travel distance: {name}")
        for name, value in zip(names, values, strict=True)
    )
    r_z = 1.0 - abs(node_m_z - m_z) / DM_Z_MAX
    r_theta = 1.0 - abs(_wrap(node_m_theta - m_theta)) / DM_THETA_MAX
    if r_z >= r_z_gate and r_theta >= r_theta_gate:
        return HeadingCorrection(_wrap(node_heading - node_m_theta + m_theta), True, r_z, r_theta)
    return HeadingCorrection(_wrap(theta), False, r_z, r_theta)


def heading_from_map(
    linear_map: LinearMagneticMap,
    d: float,
    theta: float,
    reading: Any,
) -> HeadingCorrection:
    """:func:`azimuth_heading` at the node nearest travel distance ``d`` (the filter's
    estimate, "after the travel distance is estimated, the robot is at node n"), for a reading
    (mx, my, mz) G in the sensor frame (x forward, y right, z down)."""
    _map_profile(linear_map)
    d = check_number(d, "travel distance: d", unit="m")
    m = _stream(reading, "the reading")
    if m.shape != (3,):
        raise ValueError(f"travel distance: the reading must be (mx, my, mz), got {m.shape}")
    n = int(linear_map.index(d))
    return azimuth_heading(
        theta,
        math.atan2(m[1], m[0]),
        float(m[2]),
        float(linear_map.heading[n]),
        float(linear_map.m_theta[n]),
        float(linear_map.field[n, 2]),
    )
