# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A synthetic hand-held walk in the Kok-Solin .mat layout: laps of a circle at constant speed
through a known field, so the true travel distance is the arc."""

from __future__ import annotations

import numpy as np
import scipy.io

from kiseki.datasets.kok import SENSOR_TO_BODY

RADIUS = 4.0  # m: a circular loop of 25.1 m
STEP = 0.1  # m per sample: 1 m/s at 10 Hz


def loop_field(angle: np.ndarray) -> np.ndarray:
    """World field (uT, z up) along the loop: -45 uT vertical with 10 uT anomalies."""
    bumps = sum(10.0 * np.exp(-0.5 * ((angle - c) / 0.08) ** 2) for c in (0.7, 2.0, 3.6, 5.1))
    return np.column_stack([np.full_like(angle, 15.0), np.zeros_like(angle), -45.0 - bumps])


def write_walk(path, laps=3.0, detour=None, **override) -> None:
    """A walk of ``laps`` laps of a circle at constant speed; ``detour=(lap, metres)`` pushes
    that lap outwards by up to that many metres."""
    angle = np.arange(0.0, laps * 2 * np.pi, STEP / RADIUS)
    r = np.full_like(angle, RADIUS)
    if detour is not None:
        lap, metres = detour
        inside = (angle > (lap - 1) * 2 * np.pi) & (angle < lap * 2 * np.pi)
        r[inside] += metres * np.sin((angle[inside] % (2 * np.pi)) / 2) ** 2
    xyz = np.column_stack([r * np.cos(angle) - RADIUS, r * np.sin(angle), np.zeros_like(angle)])
    world = loop_field(angle % (2 * np.pi))
    m = world @ SENSOR_TO_BODY  # identity orientation: world = SENSOR_TO_BODY @ m
    data = {
        "t": (np.arange(len(angle)) * 0.1)[:, None],
        "dPos": np.diff(xyz, axis=0),
        "quat": np.tile([1.0, 0.0, 0.0, 0.0], (len(angle), 1)),
        "m": m,
    }
    data.update(override)
    scipy.io.savemat(path, data)
