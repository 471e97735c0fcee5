# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The cells of a magnetic field map over a box: which cell indices it spans along each axis and
how many cells that is, counted one way by the map (``MagneticFieldMap.from_gp``) and by the
command that checks a fit's box before fitting (``kiseki magnetic fit``)."""

from __future__ import annotations

import numpy as np

__all__ = ["MAX_CELLS", "cell_span"]

MAX_CELLS = 20_000_000  # 6 float64 layers: about 1 GB in memory


def cell_span(lower: np.ndarray, upper: np.ndarray, resolution: float) -> tuple[np.ndarray, ...]:
    """The first and last cell indices (int64, per axis) of a map of cells of ``resolution``
    metres over ``lower``..``upper`` (a bound within 1e-9 of a cell edge stays on its side), and
    the cell counts (at least 1 a side). A ValueError when the indices pass int64 (a resolution
    of 1e-300 wrapped to a 1 x 1 map)."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    if not np.all(np.abs(np.concatenate([lower, upper]) / resolution) < 2.0**62):
        raise ValueError(
            f"the box {lower}..{upper} at {resolution:g} m is beyond any grid's cell indices"
        )
    first = np.floor(lower / resolution + 1e-9).astype(np.int64)
    last = np.ceil(upper / resolution - 1e-9).astype(np.int64)
    return first, last, np.maximum(last - first, 1)
