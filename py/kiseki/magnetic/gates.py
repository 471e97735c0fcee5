# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The magnetic navigators' validity gate set from the sensor's noise (kiseki's rule, beside the
thesis' fixed r_z >= 0.998 of sec. 4.3.2, which stays the reproduction's setting).

The thesis' gate passes a step when ``|m_z,n - m_z,t| <= (1 - 0.998) * dm_z,max = 0.002 G``.
With its own sensor's noise of about 0.01 G per reading (sec. 6.3.2) an unchanged field fails
that gate on most steps (magnav-navigators: valid on 11-12 % of steps). kiseki's rule asks the
gate to pass an unchanged field and to stop a changed one, at a stated false-alarm rate:

* the difference of a reading (noise SD sigma) and the map's node that averaged c readings
  (noise sigma / sqrt(c)) is N(0, sigma^2 (1 + 1/c)) where nothing changed;
* the gate passes it when ``|m_z,n - m_z,t| <= z sigma sqrt(1 + 1/c_n)``, z = 3: an unchanged
  field passes 99.7 % of steps, a change of more than about 3.5 sigma is stopped.

sigma comes from the data, not from a datasheet: :func:`reading_noise_sd` reads it from the
taught map itself (the nodes' second differences, which remove a field that is smooth over
the 0.1 m spacing; a median, so that the few sharp anomalies a route passes do not count as
noise).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number

__all__ = ["GATE_Z", "gate_limits", "reading_noise_sd"]

GATE_Z = 3.0
"""Standard deviations of an unchanged field's difference that the gate passes."""
MAD_TO_SD = 1.482602218505602
"""SD of a Gaussian per median absolute deviation (1 / Phi^-1(3/4))."""


def reading_noise_sd(node_values: Any, counts: Any) -> float:
    """SD of one reading estimated from a linear map's node values (n,) and the readings each
    node averaged (n,; 0: an interpolated node, left out). A node's second difference
    ``v_{i-1} - 2 v_i + v_{i+1}`` of independent node noises sigma / sqrt(c) has variance
    sigma^2 (1/c_{i-1} + 4/c_i + 1/c_{i+1}); sigma is the median of |second difference| /
    sqrt(that sum), times 1.4826 (a Gaussian's SD per median absolute value). Sharp anomalies
    (a pipe's 0.3 G over 0.3 m) lift it where the noise is small beside them (by up to about
    20 % at 0.002 G with one pipe every 10 m): the gate is then wider, never narrower."""
    v = np.asarray(node_values, dtype=np.float64)
    c = np.asarray(counts, dtype=np.float64)
    if v.ndim != 1 or c.shape != v.shape:
        raise ValueError(f"gates: node values {v.shape} and counts {c.shape} must be (n,) alike")
    if not (np.all(np.isfinite(v)) and np.all(np.isfinite(c)) and np.all(c >= 0)):
        raise ValueError("gates: node values must be finite and counts >= 0")
    seen = c > 0
    triple = seen[:-2] & seen[1:-1] & seen[2:]
    if triple.sum() < 10:
        raise ValueError(
            f"gates: {int(triple.sum())} runs of three measured nodes; at least 10 are needed "
            "to estimate the sensor's noise"
        )
    d2 = v[:-2] - 2.0 * v[1:-1] + v[2:]
    scale = np.sqrt(
        1.0 / np.maximum(c[:-2], 1) + 4.0 / np.maximum(c[1:-1], 1) + 1.0 / np.maximum(c[2:], 1)
    )
    return float(MAD_TO_SD * np.median(np.abs(d2[triple]) / scale[triple]))


def gate_limits(noise_sd: float, counts: Any, z: float = GATE_Z) -> np.ndarray:
    """Per node: the largest |m_z,n - m_z,t| the gate passes, ``z sigma sqrt(1 + 1/c_n)``
    (an interpolated node, c = 0, counts as one reading)."""
    for name, value in (("noise_sd", noise_sd), ("z", z)):
        check_number(value, f"gates: {name}", 0.0, low_open=True)
    c = np.maximum(np.asarray(counts, dtype=np.float64), 1.0)
    if c.ndim != 1:
        raise ValueError(f"gates: counts must be (n,), got {c.shape}")
    return z * noise_sd * np.sqrt(1.0 + 1.0 / c)
