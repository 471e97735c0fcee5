# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki.plots: what the PNGs show, read back pixel by pixel. Blocks of known size and place
are found by colour; their sizes and the distances between them give the picture's scale, which
must be the same along x and y, and everything else must sit where that scale puts it (y up)."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib import colormaps

from _helpers.pixels import blobs, largest_blob, rgb
from kiseki.core import Pose2
from kiseki.grid import OccupancyGrid
from kiseki.plots import render_distance_field, render_map


def blocks_grid() -> OccupancyGrid:
    """4 m x 2 m at 0.1 m from (1, 2): free, with an occupied 0.6 x 0.4 m block at x 1.3-1.9,
    y 2.2-2.6, an unknown 1.0 x 0.6 m block at x 3.5-4.5, y 3.2-3.8 and a 50 % block of
    0.4 x 0.4 m at x 1.5-1.9, y 3.2-3.6."""
    cells = np.zeros((20, 40), dtype=np.int8)
    cells[2:6, 3:9] = 100
    cells[12:18, 25:35] = -1
    cells[12:16, 5:9] = 50
    return OccupancyGrid(cells, 0.1, Pose2(1.0, 2.0, 0.0))


def test_render_map_draws_cells_trajectory_and_start_where_they_are(tmp_path):
    # a trajectory along y = 3.0 from x = 2.2 to x = 4.6: blue, its start a green dot
    track = np.array([[2.2, 3.0, 0.0], [3.4, 3.0, 0.0], [4.6, 3.0, 0.0]])
    image = rgb(render_map(blocks_grid(), tmp_path / "m.png", trajectory=track))
    black, black_size = largest_blob(image, (0, 0, 0))
    grey, grey_size = largest_blob(image, (199, 199, 199), tol=3)  # unknown: shade 0.78
    half, half_size = largest_blob(image, (128, 128, 128), tol=3)  # 50 %: shade 0.5
    # the blocks' centres are 2.4 m apart along x and 1.1 m along y: the same scale both ways,
    # y pointing up (the unknown block, further north, higher in the picture)
    scale = (grey[0] - black[0]) / 2.4  # pixels per metre
    assert scale > 100 and (black[1] - grey[1]) / 1.1 == pytest.approx(scale, rel=0.01)
    # every block is as large as it is (3 pixels for the edges)
    for size, *metres in ((black_size, 0.6, 0.4), (grey_size, 1.0, 0.6), (half_size, 0.4, 0.4)):
        np.testing.assert_allclose(size, scale * np.array(metres), atol=3)

    def pixel(x, y):  # world -> pixel, from the occupied block's centre (1.6, 2.4); y up
        return black + scale * np.array([x - 1.6, -(y - 2.4)])

    np.testing.assert_allclose(half, pixel(1.7, 3.4), atol=2)
    line, line_size = largest_blob(image, (31, 119, 180), tol=40)  # tab:blue
    assert line_size[0] == pytest.approx(2.4 * scale, abs=8) and line_size[1] <= 5
    np.testing.assert_allclose(line, pixel(3.4, 3.0), atol=4)
    # the start: a green dot (the legend has another one)
    starts = [c for c, _ in blobs(image, (44, 160, 44), tol=40)]  # tab:green
    assert min(np.abs(c - pixel(2.2, 3.0)).max() for c in starts) <= 3, starts


def test_render_distance_field_colours_the_brute_force_distance(tmp_path):
    grid = blocks_grid()
    grid.cells[grid.cells != 100] = 0  # only the occupied block is an obstacle
    clip = 2.0
    image = rgb(render_distance_field(grid, tmp_path / "d.png", clip=clip))
    lut = (np.asarray(colormaps["viridis"](np.linspace(0, 1, 256)))[:, :3] * 255).round()
    block, size = largest_blob(image, lut[0], tol=2)  # distance 0: the obstacle itself
    scale = size[0] / 0.6
    np.testing.assert_allclose(size, scale * np.array([0.6, 0.4]), atol=2)
    # brute force: distance from each cell centre to the nearest occupied cell centre (m)
    ys, xs = np.nonzero(grid.cells == 100)
    occupied = np.column_stack([1.05 + 0.1 * xs, 2.05 + 0.1 * ys])
    checked = 0
    for cx in range(0, 40, 3):
        for cy in range(0, 20, 3):
            x, y = 1.05 + 0.1 * cx, 2.05 + 0.1 * cy
            d = min(np.hypot(*(occupied - [x, y]).T).min(), clip)
            col, row = np.round(block + scale * np.array([x - 1.6, -(y - 2.4)])).astype(int)
            drawn = np.argmin(np.abs(lut - image[row, col]).sum(axis=1)) / 255 * clip
            assert drawn == pytest.approx(d, abs=0.02), (x, y)
            checked += 1
    assert checked == 98
