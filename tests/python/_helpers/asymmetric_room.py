# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A room without symmetry for global localization tests: one pose explains a scan best."""

from __future__ import annotations

import numpy as np

from kiseki import OccupancyGrid, Pose2

RES = 0.05  # m per cell


def room() -> OccupancyGrid:
    """A 12 x 9 m room with walls, a pillar, a box and a shelf placed without symmetry."""
    cells = np.zeros((180, 240), np.int8)
    cells[[0, -1], :] = 100
    cells[:, [0, -1]] = 100
    cells[60, 0:100] = 100
    cells[100:180, 150] = 100
    cells[30:50, 180:200] = 100
    cells[120:130, 40:60] = 100
    cells[140, 160:220] = 100
    return OccupancyGrid(cells, RES, Pose2(0.0, 0.0, 0.0))
