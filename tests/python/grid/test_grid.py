# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Occupancy grid: numpy view, transforms, ray casting, distance field, local windows."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, Pose2
from kiseki.grid import beam_angles, grid_summary


def random_grid(seed: int, p: float = 0.05, origin: Pose2 | None = None) -> OccupancyGrid:
    rng = np.random.default_rng(seed)
    cells = np.where(rng.random((30, 40)) < p, OCCUPIED, FREE).astype(np.int8)
    return OccupancyGrid(cells, 0.1, origin or Pose2(-1.0, 0.5, 0.3))


def march(grid: OccupancyGrid, x: float, y: float, heading: float, max_range: float) -> float:
    """Reference: walk in 1e-4 m steps and return where the first occupied cell starts."""
    t = np.arange(0.0, max_range, 1e-4)
    pts = np.column_stack([x + t * np.cos(heading), y + t * np.sin(heading)])
    cells = grid.world_to_cell(pts)
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < grid.width)
    inside &= (cells[:, 1] >= 0) & (cells[:, 1] < grid.height)
    occupied = np.zeros(len(t), dtype=bool)
    occupied[inside] = grid.cells[cells[inside, 1], cells[inside, 0]] >= 65
    return float(t[np.argmax(occupied)]) if occupied.any() else max_range


def test_cells_is_a_writable_view_without_copy():
    grid = OccupancyGrid(5, 4, 0.1, Pose2(), FREE)
    view = grid.cells
    assert view.dtype == np.int8 and view.shape == (4, 5)
    view[2, 3] = OCCUPIED
    assert grid.cells[2, 3] == OCCUPIED
    assert np.shares_memory(view, grid.cells)
    assert grid.cast_ray(0.05, 0.25, 0.0, 5.0)[2] == (3, 2)
    del grid  # the view keeps the grid alive
    assert view[2, 3] == OCCUPIED


def test_construction_copies_cells_and_transforms_round_trip():
    cells = np.full((3, 4), UNKNOWN, dtype=np.int8)
    grid = OccupancyGrid(cells, 0.25, Pose2(1.0, 2.0, np.pi / 2))
    cells[0, 0] = OCCUPIED
    assert grid.cells[0, 0] == UNKNOWN
    ij = np.array([[x, y] for y in range(3) for x in range(4)])
    world = grid.cell_to_world(ij)
    np.testing.assert_array_equal(grid.world_to_cell(world), ij)
    # yaw 90 deg: the grid's x axis points along world +y
    np.testing.assert_allclose(world[0], [1.0 - 0.125, 2.0 + 0.125])


def test_cast_scans_match_marching_reference():
    grid = random_grid(2)
    rng = np.random.default_rng(3)
    poses = np.column_stack([rng.uniform(-1, 3, 20), rng.uniform(0, 4, 20), rng.uniform(-3, 3, 20)])
    angles = np.linspace(-np.pi, np.pi, 16, endpoint=False)
    ranges = grid.cast_scans(poses, angles, max_range=3.0)
    assert ranges.shape == (20, 16)
    for i, (x, y, th) in enumerate(poses):
        for j, a in enumerate(angles):
            assert ranges[i, j] == pytest.approx(march(grid, x, y, th + a, 3.0), abs=2e-4)


def test_cells_on_ray_ends_at_the_hit_cell():
    grid = random_grid(4, p=0.1)
    rng = np.random.default_rng(5)
    for _ in range(50):
        x, y, h = rng.uniform(0, 2), rng.uniform(1, 3), rng.uniform(-np.pi, np.pi)
        rng_, hit, cell = grid.cast_ray(x, y, h, 4.0)
        cells = grid.cells_on_ray(x, y, h, 4.0)
        if hit:
            assert tuple(cells[-1]) == cell
            assert (grid.cells[cells[:-1, 1], cells[:-1, 0]] < 65).all()
        steps = np.abs(np.diff(cells, axis=0)).sum(axis=1)
        assert (steps == 1).all()


def test_distance_field_matches_brute_force():
    grid = random_grid(6, p=0.02)
    field = grid.distance_field()
    occ = np.argwhere(grid.cells >= 65)
    yy, xx = np.mgrid[0 : grid.height, 0 : grid.width]
    d = np.sqrt((yy[..., None] - occ[:, 0]) ** 2 + (xx[..., None] - occ[:, 1]) ** 2).min(axis=2)
    np.testing.assert_allclose(field, d * grid.resolution, atol=1e-4)
    assert np.isinf(OccupancyGrid(3, 3, 0.1, Pose2(), FREE).distance_field()).all()


def test_extract_window_matches_pointwise_lookup():
    grid = random_grid(7, p=0.3)
    pose = Pose2(1.0, 2.0, -0.7)
    win = grid.extract_window(pose, 8.0, 8.0)
    assert (win.width, win.height) == (80, 80)
    ij = np.array([[x, y] for y in range(80) for x in range(80)])
    centres = win.cell_to_world(ij)
    src = grid.world_to_cell(centres)
    inside = (src[:, 0] >= 0) & (src[:, 0] < grid.width) & (src[:, 1] >= 0)
    inside &= src[:, 1] < grid.height
    expected = np.full(len(ij), UNKNOWN, dtype=np.int8)
    expected[inside] = grid.cells[src[inside, 1], src[inside, 0]]
    np.testing.assert_array_equal(win.cells[ij[:, 1], ij[:, 0]], expected)
    assert 0 < inside.mean() < 1  # part of the window lies outside the map
    # the window's centre is the pose
    np.testing.assert_allclose(win.cell_to_world(np.array([[40, 40]]))[0], [1.0, 2.0], atol=0.08)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((5, 100.0), r"field of view must be in \(0, 2 pi\]"),  # 16 turns of beams
        ((5, 1.0, math.nan), "start must be a finite angle"),  # NaN angles
        ((2.5, 1.0), "beam count must be an integer"),
        ((True, 1.0), "beam count must be an integer"),
        ((10**9, 1.0), "beam count must be an integer in 1..100,000, got 1000000000"),
    ],
)
def test_beam_angles_refuse_what_no_scanner_has(args, match):
    with pytest.raises(ValueError, match=match):
        beam_angles(*args)
    # a whole turn is a scanner's largest field of view
    np.testing.assert_allclose(np.diff(beam_angles(5, 2 * math.pi)), math.pi / 2)


def test_beam_angles_and_summary():
    a = beam_angles(1081, np.deg2rad(270))
    assert a[0] == pytest.approx(-np.deg2rad(135)) and a[-1] == pytest.approx(np.deg2rad(135))
    s = grid_summary(random_grid(1))
    assert s["free"] + s["occupied"] == 1200 and s["unknown"] == 0
    with pytest.raises(ValueError):
        beam_angles(0, 1.0)


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda: OccupancyGrid(np.zeros((3, 3)), 0.1), "int8"),
        (lambda: OccupancyGrid(np.zeros(3, dtype=np.int8), 0.1), "shape"),
        (lambda: OccupancyGrid(np.zeros((0, 3), dtype=np.int8), 0.1), "empty"),
        (lambda: OccupancyGrid(3, 3, -0.1), "resolution"),
        (lambda: OccupancyGrid(3, 3, float("nan")), "resolution"),
        (lambda: OccupancyGrid(0, 3, 0.1), "positive"),
        (lambda: random_grid(1).cast_scans(np.zeros((2, 2)), np.zeros(3)), "poses"),
        (lambda: random_grid(1).cast_scans(np.full((2, 3), np.nan), np.zeros(3)), "NaN"),
        (lambda: random_grid(1).cast_scans(np.zeros((2, 3)), np.array(["a"])), "numeric"),
        (lambda: random_grid(1).cast_ray(0, 0, 0, max_range=-1.0), "max_range"),
        (lambda: random_grid(1).cast_ray(float("nan"), 0, 0), "finite"),
        (lambda: random_grid(1).world_to_cell(np.array([[np.inf, 0.0]])), "NaN"),
        (lambda: random_grid(1).extract_window(Pose2(), -1.0, 1.0), "positive"),
    ],
)
def test_bad_input_raises_value_error(make, match):
    with pytest.raises(ValueError, match=match):
        make()
