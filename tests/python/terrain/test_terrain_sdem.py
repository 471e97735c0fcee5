# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The S-DEM of paper 003 (eqs. 2-3) and its correlation search (eq. 4), against numpy
references: the round trip exact to the cell, eq. 4 by brute force, and a known offset found
exactly by both searches."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.terrain import (
    PAPER_GRID,
    attitude_matrix,
    correlation_search,
    sdem_from_points,
    sdem_from_ranges,
    sdem_median,
    search_grid,
    sphere_grid,
)

DEG = math.pi / 180


def eq2(r, th, ph):
    """Eq. 2 with sin(phi) for y (the printed sin(theta) is a typo)."""
    return np.stack([r * np.cos(th) * np.cos(ph), r * np.sin(ph), r * np.sin(th) * np.cos(ph)], -1)


def rubble_points(seed: int, n: int = 6000) -> np.ndarray:
    """Points on an irregular floor 0.5 m below the sensor and on scattered blocks: a scene
    with features in every direction of motion."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform([-2.5, -3.0], [3.5, 3.0], size=(n, 2))
    z = (
        -0.5
        + 0.08 * np.sin(2.7 * xy[:, 0]) * np.cos(1.9 * xy[:, 1])
        + 0.04 * np.sin(5.1 * xy[:, 1])
    )
    blocks = rng.uniform([-2, -2.5, -0.5], [3, 2.5, 0.3], size=(n // 4, 3))
    return np.concatenate([np.column_stack([xy, z]), blocks])


def test_paper_grid_shape_and_centres():
    assert (PAPER_GRID.rows, PAPER_GRID.cols) == (151, 181)
    assert PAPER_GRID.theta(0) == pytest.approx(-120 * DEG)
    assert PAPER_GRID.theta(150) == pytest.approx(30 * DEG)
    assert PAPER_GRID.phi(90) == pytest.approx(0.0)


def test_round_trip_ranges_points_ranges_is_exact():
    rng = np.random.default_rng(1)
    ranges = rng.uniform(0.3, 4.99, size=(151, 181))
    ranges[rng.random(ranges.shape) < 0.2] = np.nan
    m = sdem_from_ranges(ranges)
    points, cells = m.to_points()
    th = np.radians(np.arange(-120, 31))[cells // 181]
    ph = np.radians(np.arange(-90, 91))[cells % 181]
    np.testing.assert_allclose(points, eq2(ranges.reshape(-1)[cells], th, ph), atol=1e-12)
    back = sdem_from_points(points)
    np.testing.assert_array_equal(np.isnan(back.ranges), np.isnan(ranges))
    np.testing.assert_allclose(back.ranges, ranges, atol=1e-12)


def test_round_trip_points_sdem_points_within_the_cell():
    """Any point comes back on its cell's centre ray: same range, direction within half a cell."""
    rng = np.random.default_rng(2)
    th = rng.uniform(-120, 30, 3000) * DEG
    ph = rng.uniform(-89.5, 89.5, 3000) * DEG
    r = rng.uniform(0.2, 4.9, 3000)
    m = sdem_from_points(eq2(r, th, ph))
    back, cells = m.to_points()
    row, col = cells // 181, cells % 181
    # each kept point is the nearest of its cell: compare with a brute-force binning
    rows = np.floor((th / DEG + 120) + 0.5).astype(int)
    cols = np.floor((ph / DEG + 90) + 0.5).astype(int)
    nearest = np.full((151, 181), np.inf)
    np.minimum.at(nearest, (rows, cols), r)
    np.testing.assert_allclose(np.linalg.norm(back, axis=1), nearest[row, col], rtol=1e-12)
    assert m.valid_cells == np.isfinite(nearest).sum()
    # the direction of a cell's point is within half a cell (0.5 deg per axis) of the original
    i = np.flatnonzero(np.isclose(r[:, None], nearest[row, col][None, :], rtol=0, atol=0).any(1))
    assert len(i) == m.valid_cells
    assert np.all(np.abs(th[i] / DEG - (rows[i] - 120)) <= 0.5 + 1e-9)


def test_the_printed_eq2_sin_theta_for_y_would_not_round_trip():
    """The typo check: with y = r sin(theta) the points do not come back to their cells."""
    rng = np.random.default_rng(3)
    th, ph = rng.uniform(-100, 20, 500) * DEG, rng.uniform(-80, 80, 500) * DEG
    r = rng.uniform(1, 4, 500)
    typo = np.stack([r * np.cos(th) * np.cos(ph), r * np.sin(th), r * np.sin(th) * np.cos(ph)], -1)
    m_typo, m_right = sdem_from_points(typo), sdem_from_points(eq2(r, th, ph))
    _, cells_right = m_right.to_points()
    rows = np.floor(th / DEG + 120 + 0.5).astype(int)
    cols = np.floor(ph / DEG + 90 + 0.5).astype(int)
    assert set(cells_right) == set(rows * 181 + cols)
    _, cells_typo = m_typo.to_points()
    assert len(set(cells_typo) & set(rows * 181 + cols)) < 0.2 * len(set(cells_typo))


def test_range_cut_and_median_of_three():
    ranges = np.full((151, 181), 2.0)
    ranges[0, :10] = 5.0  # at the cut: dropped
    ranges[1, :10] = 7.9
    assert sdem_from_ranges(ranges).valid_cells == 151 * 181 - 20
    a, b, c = (np.full((151, 181), v) for v in (1.0, 3.0, 2.0))
    b[5, 5] = c[5, 5] = np.nan  # data in 1 of 3: empty
    c[6, 6] = np.nan  # 2 of 3: the mean of the two
    med = sdem_median([sdem_from_ranges(x) for x in (a, b, c)]).ranges
    assert med[0, 0] == 2.0 and np.isnan(med[5, 5]) and med[6, 6] == 2.0


def test_attitude_compensation_levels_a_tilted_sweep():
    """A floor seen by a sensor pitched 10 deg and rolled -2 deg: compensated with the gyro's
    attitude, the S-DEM equals the level sensor's."""
    pts = rubble_points(4)
    rot = attitude_matrix(-2 * DEG, -10 * DEG, 0.0)
    level = sdem_from_points(pts)
    tilted = pts @ rot  # rot^T p: the points in the tilted sensor's frame
    compensated = sdem_from_points(tilted, attitude=rot)
    same = np.isclose(compensated.ranges, level.ranges, atol=1e-9) | (
        np.isnan(compensated.ranges) & np.isnan(level.ranges)
    )
    assert same.mean() > 0.999
    uncompensated = sdem_from_points(tilted)
    assert np.isclose(uncompensated.ranges, level.ranges, atol=1e-6).mean() < 0.2


def brute_force_eq4(prev_points, current, rot, t, cost="mean", min_overlap=50):
    """Eq. 4 in numpy, double precision: q = rot^T (p - t), nearest per cell, cos(phi) weight."""
    q = (prev_points.astype(np.float32).astype(float) - t) @ rot
    r = np.linalg.norm(q, axis=1)
    th = np.arctan2(q[:, 2], q[:, 0])
    ph = np.arctan2(q[:, 1], np.hypot(q[:, 0], q[:, 2]))
    row = np.floor((th / DEG + 120) + 0.5).astype(int)
    col = np.floor((ph / DEG + 90) + 0.5).astype(int)
    ok = (r > 0) & (r < 5) & (row >= 0) & (row < 151) & (col >= 0) & (col < 181)
    virtual = np.full((151, 181), np.inf)
    np.minimum.at(virtual, (row[ok], col[ok]), r[ok])
    cur = current.ranges
    both = np.isfinite(virtual) & ~np.isnan(cur)
    w = np.cos(np.radians(np.arange(-90, 91)))[None, :].repeat(151, 0)[both]
    d = (virtual[both] - cur[both]) ** 2 * w
    if both.sum() < min_overlap:
        return math.inf, int(both.sum())
    return (d.sum() if cost == "sum" else d.sum() / w.sum()), int(both.sum())


@pytest.mark.parametrize("cost", ["mean", "sum"])
def test_eq4_cost_matches_a_brute_force_reference(cost):
    from kiseki import _core

    pts = rubble_points(5)
    prev = sdem_from_points(pts)
    prev_points, _ = prev.to_points()
    rot = attitude_matrix(0.01, -0.03, 0.05)
    true_t = np.array([0.3, 0.2, 0.04])
    current = sdem_from_points((pts - true_t) @ rot)
    search = _core.CorrelationSearch(prev_points, current, rot, cost, 50, 1)
    rng = np.random.default_rng(6)
    for t in [true_t, *rng.uniform([-0.1, -0.5, -0.3], [0.7, 0.5, 0.3], size=(6, 3))]:
        got, overlap = search.cost(t)
        want, want_overlap = brute_force_eq4(prev_points, current, rot, t, cost)
        assert abs(overlap - want_overlap) <= 2
        assert got == pytest.approx(want, rel=2e-3, abs=1e-9)


def test_the_default_cost_is_eq4_as_printed_a_sum():
    """correlation_search and the mapper without a cost score eq. 4 as the paper prints it
    (the sum over the shared cells), not kiseki's mean: the cost surface against numpy."""
    from kiseki.terrain.mapper import MapperConfig

    pts = rubble_points(9, 3000)
    prev = sdem_from_points(pts)
    prev_points, _ = prev.to_points()
    current = sdem_from_points(pts - [0.2, 0.1, 0.0])
    grid = search_grid((0.1, 0.3), (0.0, 0.2), (-0.04, 0.04), 0.1)
    found = correlation_search(prev, current, None, grid)
    eye = np.eye(3)
    for (i, j, k), got in np.ndenumerate(found.costs):
        t = np.array([0.1 + 0.1 * i, 0.1 * j, -0.04 + 0.1 * k])
        want, _ = brute_force_eq4(prev_points, current, eye, t, "sum")
        assert got == pytest.approx(want, rel=2e-3, abs=1e-9)
    assert MapperConfig().cost == "sum"


@pytest.mark.parametrize("true_t", [(0.30, 0.20, 0.04), (0.56, -0.34, -0.12)])
def test_both_searches_find_a_known_offset_exactly(true_t):
    pts = rubble_points(7)
    rot = attitude_matrix(-2 * DEG, -10 * DEG, 15 * DEG)  # environment A's attitude
    prev = sdem_from_points(pts)
    prev_points, _ = prev.to_points()
    current = sdem_from_points((prev_points - np.array(true_t)) @ rot)
    grid = search_grid()
    exhaustive = correlation_search(prev, current, rot, grid, "exhaustive")
    np.testing.assert_allclose(exhaustive.translation, true_t, atol=1e-9)
    assert exhaustive.evaluated == 56916 and exhaustive.costs.shape == (36, 51, 31)
    assert exhaustive.cost == exhaustive.costs.min()
    fine = correlation_search(prev, current, rot, grid, "coarse-to-fine")
    np.testing.assert_allclose(fine.translation, true_t, atol=1e-9)
    assert fine.evaluated < 56916 / 10


def test_search_is_the_same_for_any_thread_count():
    pts = rubble_points(8, 3000)
    prev = sdem_from_points(pts)
    current = sdem_from_points(pts - [0.2, 0.1, 0.0])
    grid = search_grid((0.0, 0.3), (-0.1, 0.3), (-0.1, 0.1), 0.04)
    one = correlation_search(prev, current, None, grid, threads=1)
    two = correlation_search(prev, current, None, grid, threads=2)
    np.testing.assert_array_equal(one.costs, two.costs)


def test_exhaustive_costs_equal_one_candidates_cost_and_numpy_on_a_sparse_rotated_scene():
    """The exhaustive search leaves out, per block of candidates, the points that cannot land in
    a cell with data (most, when the current map keeps only the mounds, as after plane removal):
    every candidate's cost equals the single-candidate cost from every point bit for bit, and
    numpy's eq. 4; one thread and two give the same surface."""
    from kiseki import _core

    pts = rubble_points(12, 4000)
    rot = attitude_matrix(-2 * DEG, -10 * DEG, 15 * DEG)
    true_t = np.array([0.36, 0.30, 0.06])
    prev = sdem_from_points(pts)
    prev_points, _ = prev.to_points()
    blocks = prev_points[prev_points[:, 2] > -0.42]  # the scattered blocks, not the floor
    current = sdem_from_points((blocks - true_t) @ rot)
    grid = search_grid((0.30, 0.42), (0.20, 0.36), (0.0, 0.12), 0.02)  # 7 x 9 x 7
    search = _core.CorrelationSearch(prev_points, current, rot, "sum", 50, 1)
    found = correlation_search(prev, current, rot, grid, threads=2)
    np.testing.assert_allclose(found.translation, true_t, atol=1e-9)
    one = correlation_search(prev, current, rot, grid, threads=1)
    np.testing.assert_array_equal(one.costs, found.costs)
    for (i, j, k), got in np.ndenumerate(found.costs):
        t = np.array([0.30 + 0.02 * i, 0.20 + 0.02 * j, 0.02 * k])
        assert got == search.cost(t)[0]
        want, _ = brute_force_eq4(prev_points, current, rot, t, "sum")
        assert got == pytest.approx(want, rel=2e-3, abs=1e-9)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: sdem_from_ranges(np.full((151, 181), np.nan)), "no range within"),
        (lambda: sdem_from_ranges(np.full((151, 181), 6.0)), "all out of limits"),
        (lambda: sdem_from_ranges(np.ones((10, 10))), "expected shape"),
        (lambda: sdem_from_points(np.zeros((0, 3))), "non-empty"),
        (lambda: sdem_from_points([[1, 0, math.nan]]), "NaN"),
        (lambda: sdem_from_points([[1, 0, 0]], attitude=np.full((3, 3), math.nan)), "NaN"),
        (lambda: attitude_matrix(math.nan, 0.0, 0.0), "^attitude: roll must be a finite number, "),
        (
            lambda: attitude_matrix(0.0, 0.0, True),
            "^attitude: yaw must be a finite number, got True",
        ),
        (lambda: search_grid(step=0.0), "zero steps"),
        (lambda: search_grid(x=(0.5, 0.1)), "min <= max"),
        (lambda: sphere_grid(step_deg=0.0), "step_deg"),
        (lambda: sphere_grid(theta_deg=(30, -120)), "theta_min_deg"),
        (lambda: sphere_grid(max_range=-1), "max_range"),
    ],
)
def test_bad_input_raises_a_clear_error(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_search_refuses_an_empty_map_and_a_non_rotation():
    from kiseki import _core

    m = sdem_from_points(rubble_points(9, 500))
    empty = _core.SphereElevationMap(PAPER_GRID)
    with pytest.raises(ValueError, match="current S-DEM is empty"):
        correlation_search(m, empty)
    with pytest.raises(ValueError, match="not a rotation"):
        correlation_search(m, m, np.eye(3) * 2)
    with pytest.raises(ValueError, match="method"):
        correlation_search(m, m, method="annealing")
    # a million threads went straight to OpenMP (a crash under a memory limit)
    for threads in (10**6, -1, True, 2.0):
        with pytest.raises(ValueError, match="threads must be an integer in 0..1,024"):
            correlation_search(m, m, threads=threads)
    with pytest.raises(ValueError, match="threads must be in 0..1024"):
        _core.CorrelationSearch(m.to_points()[0], m, None, "sum", 50, 10**6)


def test_hough_removal_refuses_a_vote_table_beyond_memory():
    """angle_step_deg 1e-6 asked for std::bad_alloc (60 G cells); the default's table is
    180 x 135 cells."""
    from kiseki.terrain import HoughParams, remove_planes

    m = sdem_from_points(rubble_points(3, 500))
    with pytest.raises(ValueError, match="would hold 60300000000 cells, more than 50,000,000"):
        remove_planes(m, "hough", hough=HoughParams(angle_step_deg=1e-6))
    done = remove_planes(m, "hough")  # the default still runs: kept and removed add up
    assert done.kept.valid_cells + int(done.removed.sum()) == m.valid_cells
