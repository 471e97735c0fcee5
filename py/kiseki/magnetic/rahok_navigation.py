# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Rahok's magnetic navigation method as re-implemented in the magnetic-navigation thesis
(``002_74cea16d239c028f.txt``, ch. 3): the robot's state is its travel distance d alone,
corrected at taught peaks of the field, and it steers on the field along the taught path.

* **Travel-distance correction at peaks** (sec. 3.3.3): "the places with a change like Fig. 2.7
  and the change's maximum are taught beforehand. During autonomous travel the robot keeps 6 m of
  field intensity every 10 cm. 3 m past a taught landmark it takes the maximum of what it kept;
  if the difference to the taught maximum is below some value, the landmark was observed, and
  the travel distance is corrected so that the observed disturbance lies where it was taught.
  The map is recorded every 10 cm, so the correction is in 10 cm steps. Only m_z is used (m_x,
  m_y change with the robot's heading)." :class:`PeakCorrection`. kiseki's choices: the peaks
  are found in the taught map (:func:`taught_peaks`) rather than by hand; a pipe's anomaly can
  be a dip as well as a rise, so a peak is an extreme of ``sign (m_z - m_z,ref)``, m_z,ref the
  median of the taught m_z (the undisturbed level); the "some value" is ``tolerance`` (0.02 G,
  twice the sensor noise, by default).
* **Identification vector s** (eq. 3.1), from the maps of two paths parallel to the taught one
  on its left (l m) and right (r m), threshold m_t = 0.01 G: :func:`identification_vector`.
  The text prints ``s_k = 1 if l m_k + m_t > m_k > r m_k - m_t``, which holds wherever the three
  are equal, yet "where s is all zero the field is stable" (sec. 3.3.4); we read it as the
  monotonic step with margins: ``1 if l m_k - m_t > m_k > r m_k + m_t`` (the field falls from
  left to right), ``-1 if l m_k + m_t < m_k < r m_k - m_t``, else 0.
* **Weight vector w** (sec. 3.3.2): the thesis sets w by trial runs, lowering it where the robot
  snakes, and lowers w_theta where the azimuth changes a lot with place (sec. 3.4.2, point A).
  kiseki's rule from the map (:func:`weight_vector`): w_k = ``field_gain`` (rad/G) where
  s_k != 0; w_theta = ``theta_gain / (1 + (spread / spread0)^2)`` with spread the range of the
  (1 m averaged) taught azimuth within +-1 m.
* **Deviation vector e** (eq. 3.2): :func:`deviation_vector`; its components are summed to the
  steering error that :class:`kiseki.control.PdSteering` drives to zero (sec. 3.3.4; how the
  four are combined is not printed: the weights carry the units). Sign: sensor y points right,
  ``m_theta = atan2(m_y, m_x)`` grows as the robot turns left, so ``m_theta,i - m_theta,t > 0``
  means "turn left"; with s as above a robot right of the path also gets e > 0.

Methods take readings and travel distances; nothing here knows the simulator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number

__all__ = [
    "CHECK_AFTER",
    "PEAK_WINDOW",
    "S_THRESHOLD",
    "PeakCorrection",
    "RahokNavigator",
    "TaughtPeak",
    "deviation_vector",
    "identification_vector",
    "moving_average",
    "taught_peaks",
    "weight_vector",
]

PEAK_WINDOW = 6.0
"""m of m_z kept during travel (sec. 3.3.3)."""
CHECK_AFTER = 3.0
"""m past a taught peak at which the window is compared (sec. 3.3.3)."""
S_THRESHOLD = 0.01
"""G: m_t of eq. 3.1 (sec. 3.3.2)."""


def _finite(value: Any, name: str, ndim: int) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be numbers") from None
    if a.ndim != ndim or a.size == 0:
        raise ValueError(f"{name} must be a non-empty {ndim}-d array, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} holds NaN or infinity")
    return a


def moving_average(values: Any, cells: int) -> np.ndarray:
    """Centred moving average over ``cells`` samples along axis 0 (shorter at the ends)."""
    a = np.asarray(values, dtype=np.float64)
    cells = check_count(cells, "moving_average: cells", 1)
    if cells == 1 or a.size == 0:  # nothing to average: [] was numpy's "cannot reshape"
        return a.copy()
    a2 = a.reshape(len(a), -1)
    c = np.vstack([np.zeros((1, a2.shape[1])), np.cumsum(a2, axis=0)])
    i = np.arange(len(a))
    lo = np.clip(i - cells // 2, 0, len(a))
    hi = np.clip(i - cells // 2 + cells, 0, len(a))
    return ((c[hi] - c[lo]) / (hi - lo)[:, None]).reshape(a.shape)


@dataclass(frozen=True)
class TaughtPeak:
    """A landmark of sec. 3.3.3: taught at travel distance ``s`` (m), ``height`` G of
    ``sign (m_z - reference)`` there."""

    s: float
    height: float
    sign: int
    reference: float


def taught_peaks(
    s: Any, mz: Any, threshold: float = 0.04, min_separation: float = PEAK_WINDOW
) -> list[TaughtPeak]:
    """The peaks of a taught m_z profile (node distances ``s`` m, ``mz`` G): the extremes of
    ``|m_z - median(m_z)|`` above ``threshold`` G, each the largest within ``min_separation``
    m (a peak nearer a larger one than one window would share its window)."""
    s = _finite(s, "taught_peaks: s", 1)
    mz = _finite(mz, "taught_peaks: mz", 1)
    if s.shape != mz.shape:
        raise ValueError(f"taught_peaks: s {s.shape} and mz {mz.shape} differ in length")
    threshold = check_number(threshold, "taught_peaks: threshold", 0.0, low_open=True)
    min_separation = check_number(
        min_separation, "taught_peaks: min_separation", 0.0, low_open=True
    )
    reference = float(np.median(mz))
    dev = np.abs(mz - reference)
    peaks: list[TaughtPeak] = []
    for i in np.argsort(-dev, kind="stable"):
        if dev[i] <= threshold:
            break
        if all(abs(s[i] - p.s) >= min_separation for p in peaks):
            sign = 1 if mz[i] >= reference else -1
            peaks.append(TaughtPeak(float(s[i]), float(dev[i]), sign, reference))
    return sorted(peaks, key=lambda p: p.s)


class PeakCorrection:
    """The travel-distance correction of sec. 3.3.3 (see the module text). Feed it every
    reading with :meth:`update` (estimated travel distance d, m_z G); it returns the correction
    (m, a multiple of ``spacing``, 0 mostly) to add to d. ``log`` holds (peak s, d before,
    correction, window height) of each peak checked; correction None: not matched."""

    def __init__(
        self,
        peaks: list[TaughtPeak],
        spacing: float = 0.1,
        window: float = PEAK_WINDOW,
        check_after: float = CHECK_AFTER,
        tolerance: float = 0.02,
    ) -> None:
        if not isinstance(peaks, list | tuple) or not all(isinstance(p, TaughtPeak) for p in peaks):
            raise ValueError("PeakCorrection: peaks must be a list of TaughtPeak")
        self.spacing = check_number(spacing, "PeakCorrection: spacing", 0.0, low_open=True)
        self.window = check_number(window, "PeakCorrection: window", 0.0, low_open=True)
        self.check_after = check_number(
            check_after, "PeakCorrection: check_after", 0.0, low_open=True
        )
        self.tolerance = check_number(tolerance, "PeakCorrection: tolerance", 0.0, low_open=True)
        if self.check_after >= self.window:
            raise ValueError(
                f"PeakCorrection: check_after ({check_after} m) must be shorter than the window"
                f" ({window} m)"
            )
        self.peaks = sorted(peaks, key=lambda p: p.s)
        self._next = 0
        self._cells: dict[int, list[float]] = {}  # cell -> [sum, count] of m_z
        self.log: list[tuple[float, float, float | None, float]] = []

    def _cell(self, d: float) -> int:
        return math.floor(d / self.spacing + 0.5)

    def update(self, d: float, mz: float) -> float:
        d = check_number(d, "PeakCorrection.update: d")
        mz = check_number(mz, "PeakCorrection.update: mz")
        c = self._cell(d)
        entry = self._cells.setdefault(c, [0.0, 0])
        entry[0] += mz
        entry[1] += 1
        keep = int(round(self.window / self.spacing))
        for old in [k for k in self._cells if k <= c - keep]:
            del self._cells[old]
        total = 0.0
        while self._next < len(self.peaks) and d >= self.peaks[self._next].s + self.check_after:
            total += self._check(self.peaks[self._next], d + total)
            self._next += 1
        return total

    def _check(self, peak: TaughtPeak, d: float) -> float:
        cells = np.array(sorted(self._cells))
        means = np.array([self._cells[k][0] / self._cells[k][1] for k in cells])
        heights = peak.sign * (means - peak.reference)
        best = int(np.argmax(heights))
        height = float(heights[best])
        if abs(height - peak.height) > self.tolerance:
            self.log.append((peak.s, d, None, height))
            return 0.0
        shift = self._cell(peak.s) - int(cells[best])  # whole cells: sec. 3.3.3's 10 cm steps
        self._cells = {k + shift: v for k, v in self._cells.items()}
        correction = shift * self.spacing
        self.log.append((peak.s, d, correction, height))
        return correction


def identification_vector(
    center: Any, left: Any, right: Any, threshold: float = S_THRESHOLD
) -> np.ndarray:
    """s of eq. 3.1 (as read in the module text) per node and axis: (n, 3) int8 in {1, -1, 0}
    from the taught path's field ``center`` and its left and right parallel paths' (n, 3) G."""
    c = _finite(center, "identification_vector: center", 2)
    lm = _finite(left, "identification_vector: left", 2)
    rm = _finite(right, "identification_vector: right", 2)
    if not (c.shape == lm.shape == rm.shape) or c.shape[1] != 3:
        raise ValueError(
            f"identification_vector: center {c.shape}, left {lm.shape} and right {rm.shape}"
            " must all be (n, 3)"
        )
    t = check_number(threshold, "identification_vector: threshold", 0.0, low_open=True)
    s = np.zeros(c.shape, dtype=np.int8)
    s[(lm - t > c) & (c > rm + t)] = 1
    s[(lm + t < c) & (c < rm - t)] = -1
    return s


def weight_vector(
    s_vec: Any,
    m_theta: Any,
    spacing: float = 0.1,
    field_gain: float = 20.0,
    theta_gain: float = 1.0,
    spread0: float = 0.05,
    reach: float = 1.0,
) -> np.ndarray:
    """w per node, (n, 4): (w_x, w_y, w_z) rad/G and dimensionless w_theta (module text).
    ``m_theta`` (n,) rad is the taught azimuth; it is averaged over ``reach`` m (as unit
    vectors) before its range within +-``reach`` m is taken."""
    sv = _finite(s_vec, "weight_vector: s", 2)
    mt = _finite(m_theta, "weight_vector: m_theta", 1)
    if sv.shape != (len(mt), 3):
        raise ValueError(f"weight_vector: s {sv.shape} must be (n, 3) with n = {len(mt)}")
    spacing = check_number(spacing, "weight_vector: spacing", 0.0, low_open=True)
    field_gain = check_number(field_gain, "weight_vector: field_gain", 0.0, low_open=True)
    theta_gain = check_number(theta_gain, "weight_vector: theta_gain", 0.0, low_open=True)
    spread0 = check_number(spread0, "weight_vector: spread0", 0.0, low_open=True)
    reach = check_number(reach, "weight_vector: reach", 0.0, low_open=True)
    cells = max(1, int(round(reach / spacing)))
    unit = moving_average(np.column_stack([np.cos(mt), np.sin(mt)]), cells)
    smooth = np.unwrap(np.arctan2(unit[:, 1], unit[:, 0]))
    n = len(mt)
    spread = np.array([np.ptp(smooth[max(0, i - cells) : min(n, i + cells + 1)]) for i in range(n)])
    w = np.zeros((n, 4))
    w[:, :3] = np.where(sv != 0, field_gain, 0.0)
    w[:, 3] = theta_gain / (1.0 + (spread / spread0) ** 2)
    return w


def deviation_vector(
    node_field: Any, node_theta: float, s_i: Any, w_i: Any, field: Any, theta: float
) -> np.ndarray:
    """e of eq. 3.2: (s_x w_x (m_x,i - m_x,t), s_y w_y (..), s_z w_z (..),
    w_theta (m_theta,i - m_theta,t)); the angle difference wrapped to (-pi, pi]."""
    mi = _finite(node_field, "deviation_vector: node field", 1)
    mt = _finite(field, "deviation_vector: reading", 1)
    si = _finite(s_i, "deviation_vector: s", 1)
    wi = _finite(w_i, "deviation_vector: w", 1)
    if mi.shape != (3,) or mt.shape != (3,) or si.shape != (3,) or wi.shape != (4,):
        raise ValueError(
            f"deviation_vector: node field {mi.shape}, reading {mt.shape} and s {si.shape} must"
            f" be (3,), w {wi.shape} (4,)"
        )
    d_theta = check_number(node_theta, "deviation_vector: node theta") - check_number(
        theta, "deviation_vector: theta"
    )
    d_theta = math.atan2(math.sin(d_theta), math.cos(d_theta))
    return np.concatenate([si * wi[:3] * (mi - mt), [wi[3] * d_theta]])


class RahokNavigator:
    """Rahok's navigation step by step: travel distance from odometry increments, corrected at
    the taught peaks (``peaks``; None: no correction), and the angular velocity from the PD
    control of the summed deviation vector at the node of the travel distance. ``s_vec`` (n, 3)
    and ``w_vec`` (n, 4) per node of ``lmap`` (a LinearMagneticMap). ``average``: how many of
    the latest readings are averaged before use (1: the reading as it is). ``done`` turns True
    at the map's last node."""

    def __init__(
        self,
        lmap: Any,
        s_vec: Any,
        w_vec: Any,
        steering: Any,
        peaks: PeakCorrection | None = None,
        speed: float = 0.6,
        average: int = 1,
    ) -> None:
        n = len(lmap)
        self.s_vec = np.asarray(s_vec)
        self.w_vec = _finite(w_vec, "RahokNavigator: w", 2)
        if self.s_vec.shape != (n, 3) or self.w_vec.shape != (n, 4):
            raise ValueError(
                f"RahokNavigator: s {self.s_vec.shape} and w {self.w_vec.shape} must be (n, 3)"
                f" and (n, 4) for the map's {n} nodes"
            )
        average = check_count(average, "RahokNavigator: average", 1)
        self.lmap, self.steering, self.peaks = lmap, steering, peaks
        self.speed = check_number(speed, "RahokNavigator: speed", 0.0, low_open=True)
        self.average = average
        self.d = float(lmap.s[0])
        self.done = False
        self._recent: list[np.ndarray] = []

    def step(self, travelled: float, reading: Any | None, dt: float) -> tuple[float, float]:
        """(v, w) for the step after odometry moved ``travelled`` m; ``reading`` (3,) G, or
        None when the magnetometer gave nothing new."""
        self.d += check_number(travelled, "RahokNavigator.step: travelled")
        if reading is not None:
            m = _finite(reading, "RahokNavigator.step: reading", 1)
            if m.shape != (3,):
                raise ValueError(f"RahokNavigator.step: reading must be (3,), got {m.shape}")
            self._recent = [*self._recent[-(self.average - 1) :], m] if self.average > 1 else [m]
            if self.peaks is not None:
                self.d += self.peaks.update(self.d, float(m[2]))
        if self.d >= self.lmap.s[-1]:
            self.done = True
        if not self._recent or self.done:
            return (0.0 if self.done else self.speed), 0.0
        mean = np.mean(self._recent, axis=0)
        i = self.lmap.index(self.d)
        e = deviation_vector(
            self.lmap.field[i],
            self.lmap.m_theta[i],
            self.s_vec[i],
            self.w_vec[i],
            mean,
            math.atan2(mean[1], mean[0]),
        )
        return self.speed, self.steering.update(float(e.sum()), dt)
