# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Averaging magnetometer readings per cell before a GP fit.

The thesis stores its 3-D survey as one value per measured 20 cm voxel (chapter 6.6: "values
are stored in the voxels where the field was measured, and used as the training data"). A
robot sampling at 50 Hz also records many nearly identical readings within a centimetre; their
errors are correlated in time, which a GP with independent noise reads as fine-scale field and
answers with a too-short length scale. Averaging per cell gives one reading per place.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number

__all__ = ["bin_readings"]


def bin_readings(
    positions: Any, field: Any, size: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(positions, field, counts): per occupied cube (square) of `size` metres, the mean position
    of the readings in it, their mean field and how many there were; cells in the order of
    their first reading."""
    x = np.asarray(positions, dtype=float)
    y = np.asarray(field, dtype=float)
    if x.ndim != 2 or y.ndim != 2 or len(x) != len(y) or len(x) == 0:
        raise ValueError(
            f"positions (n, d) and field (n, k) must have the same n >= 1, got {x.shape}, {y.shape}"
        )
    size = check_number(size, "the bin size", 0.0, low_open=True, unit="m")
    if not (np.isfinite(x).all() and np.isfinite(y).all()):
        raise ValueError("positions and field must be finite")
    keys = np.floor(x / size).astype(np.int64)
    _, first, inverse, counts = np.unique(
        keys, axis=0, return_index=True, return_inverse=True, return_counts=True
    )
    inverse = inverse.reshape(-1)
    order = np.argsort(first, kind="stable")  # cells in the order the robot reached them
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    cell = rank[inverse]
    sums_x = np.zeros((len(order), x.shape[1]))
    sums_y = np.zeros((len(order), y.shape[1]))
    np.add.at(sums_x, cell, x)
    np.add.at(sums_y, cell, y)
    n = counts[order][:, None]
    return sums_x / n, sums_y / n, counts[order]
