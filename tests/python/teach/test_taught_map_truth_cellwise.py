# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""`kiseki.teach.map_truth.taught_map_truth`'s two measures, the forgiving one (a taught cell counts
only with all 8 neighbours agreeing) and the cell-by-cell one, against counts written out as
plain loops over small synthetic maps: a one-cell-wide false wall that the forgiving measure
hides and the cell-by-cell one counts, a one-cell-deep hole in a thick wall, and random maps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki import _core
from kiseki.teach.map_truth import taught_map_truth

RES = 0.1
POSE = (0.55, 2.0, 0.0)  # x, y, yaw: on a cell border in y, looking east
HFOV = math.radians(100.0)


def _grid(cells: np.ndarray):
    return _core.OccupancyGrid(np.asarray(cells, np.int8), RES, _core.Pose2(0.0, 0.0, 0.0))


def _in_reach(i: int, j: int, reach: float) -> bool:
    """Cell (column i, row j): its centre within `reach` and the half field of view."""
    dx, dy = (i + 0.5) * RES - POSE[0], (j + 0.5) * RES - POSE[1]
    bearing = math.atan2(dy, dx) - POSE[2]
    return math.hypot(dx, dy) <= reach and abs(bearing) <= HFOV / 2


def _agrees_all_nine(taught: np.ndarray, i: int, j: int, test) -> bool:
    h, w = taught.shape
    if not (0 < i < w - 1 and 0 < j < h - 1):
        return False  # a border cell lacks neighbours
    return all(test(taught[j + b, i + a]) for a in (-1, 0, 1) for b in (-1, 0, 1))


def _brute_force_false_occupied(taught: np.ndarray, reach: float) -> tuple[int, int, int]:
    """With an all-free truth every free cell in reach is visible: (visible free cells,
    forgiving count, cell-by-cell count)."""
    h, w = taught.shape
    visible = forgiving = cellwise = 0
    for j in range(h):
        for i in range(w):
            if not _in_reach(i, j, reach):
                continue
            visible += 1
            cellwise += int(taught[j, i] >= 65)
            forgiving += int(_agrees_all_nine(taught, i, j, lambda v: v >= 65))
    return visible, forgiving, cellwise


def test_a_one_cell_wide_false_wall_is_hidden_by_the_forgiving_measure_only():
    truth = np.zeros((40, 40), np.int8)  # 4 x 4 m, all free
    taught = truth.copy()
    taught[8:32, 20] = 100  # a false wall one cell wide across the view, 24 cells long
    reach = 2.37  # off every cell centre's distance
    m = taught_map_truth(_grid(taught), _grid(truth), np.array([POSE]), HFOV, reach)
    visible, forgiving, cellwise = _brute_force_false_occupied(taught, reach)
    assert forgiving == 0 and cellwise > 15  # the wall is in view, the forgiving measure blind
    assert m.visible_free_cells == visible
    assert m.false_occupied_cells == forgiving == 0
    assert m.false_occupied_cells_cellwise == cellwise
    assert m.false_occupied_share_cellwise == pytest.approx(cellwise / visible)
    # three cells wide: the middle column has all 8 neighbours occupied and counts in both
    taught[8:32, 19:22] = 100
    m = taught_map_truth(_grid(taught), _grid(truth), np.array([POSE]), HFOV, reach)
    visible, forgiving, cellwise = _brute_force_false_occupied(taught, reach)
    assert 0 < forgiving < cellwise
    assert (m.false_occupied_cells, m.false_occupied_cells_cellwise) == (forgiving, cellwise)


def test_a_one_cell_deep_hole_in_a_thick_wall_counts_cell_by_cell():
    """A wall 0.5 m thick 2.5 m ahead; the taught map frees its first column only (a beam
    that reached one cell too far), and elsewhere frees all five columns."""
    truth = np.zeros((40, 40), np.int8)
    truth[:, 30:35] = 100
    taught = truth.copy()
    taught[15:25, 30] = 0  # one cell deep: the cell behind it is still a wall
    taught[28:34, 30:35] = 0  # erased through
    taught[28:34, 35] = 0  # ... and the free space behind it (hidden in the truth)
    reach = 3.03
    m = taught_map_truth(_grid(taught), _grid(truth), np.array([POSE]), HFOV, reach)
    h, w = truth.shape
    obstacles = forgiving = cellwise = 0
    for j in range(h):
        for i in range(w):
            if truth[j, i] < 65 or not _in_reach(i, j, reach):
                continue
            obstacles += 1
            cellwise += int(taught[j, i] == 0)
            forgiving += int(_agrees_all_nine(taught, i, j, lambda v: v == 0))
    assert cellwise > forgiving > 0
    assert m.obstacle_cells == obstacles
    assert (m.erased_cells, m.erased_cells_cellwise) == (forgiving, cellwise)
    assert m.erased_share_cellwise == pytest.approx(cellwise / obstacles)
    assert m.false_occupied_cells == m.false_occupied_cells_cellwise == 0


@pytest.mark.parametrize("draw", range(3))
def test_random_taught_maps_over_free_space_match_the_loops(draw):
    """Random taught maps (free, occupied, unknown at random, occupied in clumps) over an
    all-free truth: both counts as the loops give them; unknown cells count in neither."""
    rng = np.random.default_rng(draw)
    taught = rng.choice(np.array([0, 100, -1], np.int8), size=(30, 30), p=[0.5, 0.3, 0.2])
    for _ in range(4):  # clumps, so that some cells have 8 occupied neighbours
        i, j = rng.integers(3, 27, 2)
        taught[j - 2 : j + 2, i - 2 : i + 2] = 100
    truth = np.zeros_like(taught)
    reach = 2.13
    m = taught_map_truth(_grid(taught), _grid(truth), np.array([POSE]), HFOV, reach)
    visible, forgiving, cellwise = _brute_force_false_occupied(taught, reach)
    assert cellwise > forgiving > 0
    assert m.visible_free_cells == visible
    assert (m.false_occupied_cells, m.false_occupied_cells_cellwise) == (forgiving, cellwise)
