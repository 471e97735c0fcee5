# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The grid's own methods refuse what they cannot answer in one line: a fill of 200 or 2**31
cells across were pybind11's list of constructor signatures, a negative or NaN window resolution
took the map's own without a word, and a NaN cell gave a NaN point."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.core import Pose2
from kiseki.grid import OccupancyGrid


def test_the_constructor_names_a_bad_fill_or_size():
    with pytest.raises(ValueError, match=r"cell values must lie in -1\.\.100 .*, got 200$"):
        OccupancyGrid(5, 5, 0.1, Pose2(), 200)
    with pytest.raises(ValueError, match=r"more than 1e9 cells requested \(2147483648 x 1\)$"):
        OccupancyGrid(2**31, 1, 0.1)
    assert (OccupancyGrid(5, 4, 0.1, Pose2(), 100).cells == 100).all()


def test_a_window_resolution_is_zero_for_the_map_s_or_a_positive_number():
    grid = OccupancyGrid(20, 20, 0.05)
    assert grid.extract_window(Pose2(0.5, 0.5, 0.0), 0.4, 0.4).resolution == 0.05
    assert grid.extract_window(Pose2(0.5, 0.5, 0.0), 0.4, 0.4, 0.1).resolution == 0.1
    for bad in (-0.1, math.nan, math.inf):
        with pytest.raises(
            ValueError, match=r"resolution must be 0 \(the map's\) or finite and > 0"
        ):
            grid.extract_window(Pose2(0.5, 0.5, 0.0), 0.4, 0.4, bad)


def test_cell_indices_are_exact_or_outside_and_cells_finite():
    grid = OccupancyGrid(20, 20, 0.05, Pose2(-1.0, 2.0, 0.0))
    far = np.array([[1e7, 2.0], [-1.0, -4e7]])  # 2e8 and 8e8 cells away: exact in int
    np.testing.assert_array_equal(grid.world_to_cell(far), [[200_000_020, 0], [0, -800_000_040]])
    # beyond 1e9 cells an index is clamped there: outside any map, which is what callers ask
    clamped = grid.world_to_cell(np.array([[1e8, 2.0]]))
    assert clamped[0, 0] == 1_000_000_000 and clamped[0, 0] >= grid.width
    np.testing.assert_allclose(grid.cell_to_world(np.array([[0, 0]])), [[-0.975, 2.025]])
    with pytest.raises(ValueError, match=r"cells: contains NaN or infinite values"):
        grid.cell_to_world(np.array([[np.nan, 0.2]]))
