# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A magnetic field map whose field and variance are linear in the coordinates: what the map's
(bi/tri)linear interpolation reproduces exactly, for the map and map-folder tests."""

from __future__ import annotations

import numpy as np

from kiseki.gp import SquaredExponential
from kiseki.magnetic.field_map import MagneticFieldMap, TrainingData

KERNEL = SquaredExponential(2.0, 0.5, 0.1)


def linear_field(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A field and a variance linear in the coordinates: what (bi/tri)linear interpolation
    reproduces exactly."""
    p = np.asarray(points)
    a = np.array([[1.5, -0.5, 2.0], [0.25, 3.0, -1.0], [-0.75, 0.5, 0.125]])[: p.shape[1]]
    mean = np.array([10.0, -20.0, 45.0]) + p @ a
    var = 0.5 + p @ np.abs(a) * 0.1
    return mean, var


def linear_map(dimension: int, cells=(7, 5, 4), origin=(-1.0, 2.0, 0.5), resolution=0.25):
    shape = tuple(reversed(cells[:dimension]))
    index = np.indices(shape).reshape(dimension, -1)[::-1].T  # x, y[, z] of each cell
    centres = np.asarray(origin[:dimension]) + (index + 0.5) * resolution
    mean, var = linear_field(centres)
    return MagneticFieldMap(
        origin=origin[:dimension],
        resolution=resolution,
        mean=mean.reshape(*shape, 3),
        variance=var.reshape(*shape, 3),
        prior_mean=[1.0, 2.0, 3.0],
        prior_variance=[4.0, 4.0, 4.0],
        kernel=KERNEL,
        units="uT",
        height=0.2 if dimension == 2 else None,
        provenance={"data": {"sources": ["run/1"], "points": 12}},
        training=TrainingData(np.zeros((3, dimension)) + [[0], [1], [2]], np.ones((3, 3))),
    )
