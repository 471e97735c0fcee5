# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The likelihood field's beam skipping (nav2's idea) against a brute-force numpy count over
every particle and beam, on a real scan and map (Intel Research Lab), for any thread count."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from kiseki import _core
from kiseki.datasets import read_carmen_log
from kiseki.mapping import build_map

SKIP_DISTANCE, THRESHOLD, ERROR_THRESHOLD = 0.5, 0.3, 0.9  # nav2's defaults, the model's


@pytest.fixture(scope="module")
def intel(shared_data):
    scans = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz").scans
    grid = build_map(scans.poses, scans.ranges, scans.angles, scans.max_range)
    return scans, grid


def reference(grid, scans, k, poses):
    """The beams used, counted particle by particle and beam by beam, and the log-likelihood
    of each pose summed over them from the model's table."""
    ranges = scans.ranges[k].astype(np.float64)
    returns = np.isfinite(ranges) & (ranges > 0) & (ranges < scans.max_range)
    r, a = ranges[returns], scans.angles[returns]
    distance = grid.distance_field()
    o = grid.origin
    ends = []
    for x, y, theta in poses:
        # the end in the world, then in the grid's frame, then in cells
        wx, wy = x + r * np.cos(theta + a), y + r * np.sin(theta + a)
        dx, dy = wx - o.x, wy - o.y
        gx = (np.cos(o.theta) * dx + np.sin(o.theta) * dy) / grid.resolution
        gy = (-np.sin(o.theta) * dx + np.cos(o.theta) * dy) / grid.resolution
        ends.append((gx, gy))
    near = np.zeros(len(r), dtype=int)
    for gx, gy in ends:
        inside = (gx >= 0) & (gy >= 0) & (gx < grid.width) & (gy < grid.height)
        cx, cy = np.floor(gx).astype(int), np.floor(gy).astype(int)
        hit = np.zeros(len(r), dtype=bool)
        hit[inside] = distance[cy[inside], cx[inside]] <= np.float32(SKIP_DISTANCE)
        near += hit
    used = np.flatnonzero(near >= THRESHOLD * len(poses))
    if len(r) - len(used) > ERROR_THRESHOLD * len(r):
        used = np.arange(len(r))
    return used, ends


def log_likelihood_reference(model, grid, ends, used):
    """Per pose: the table's term at the end cell of each kept beam (the outside term off the
    map), summed (the product combination: log pz)."""
    table = model.table()
    sums = []
    for gx, gy in ends:
        gx, gy = gx[used], gy[used]
        inside = (gx >= 0) & (gy >= 0) & (gx < grid.width) & (gy < grid.height)
        terms = np.full(len(gx), model.outside, dtype=np.float64)
        terms[inside] = table[np.floor(gy[inside]).astype(int), np.floor(gx[inside]).astype(int)]
        sums.append(terms.sum())
    return np.array(sums)


# (scan, cloud spread, beams 60-89 cut to half their reading: something the map does not hold,
# so that some beams are skipped; uncut, every beam ends near a wall of this map, made
# from these scans)
@pytest.mark.parametrize(
    ("k", "spread", "cut"),
    [(100, 0.05, False), (400, 0.3, True), (700, 0.8, True), (700, 1.5, False)],
)
def test_beam_skipping_matches_a_brute_force_count(intel, k, spread, cut):
    scans, grid = intel
    ranges = scans.ranges.copy()
    if cut:
        ranges[k, 60:90] *= 0.5
    scans = dataclasses.replace(scans, ranges=ranges)
    rng = np.random.default_rng(k)
    truth = scans.poses[k]
    poses = truth + rng.normal(0.0, 1.0, (400, 3)) * (spread, spread, spread / 4)
    model = _core.LikelihoodFieldModel(grid, beam_skip=True)
    model.set_scan(scans.angles, scans.ranges[k], scans.max_range)
    assert model.used_beams == list(range(model.beams))  # every beam until a cloud is seen
    plain = model.log_likelihoods(poses)
    used, ends = reference(grid, scans, k, poses)
    for threads in (1, 2, 3):
        model.select_readings(poses, threads)
        assert model.used_beams == used.tolist()
    assert model.readings == len(used)
    # the weighing uses the kept beams only
    expected = log_likelihood_reference(model, grid, ends, used)
    np.testing.assert_allclose(model.log_likelihoods(poses), expected, rtol=1e-6)
    assert (len(used) < model.beams) == cut  # the cut beams, and only then, are skipped
    if cut:
        assert (model.log_likelihoods(poses) != plain).all()


def test_a_cloud_that_sees_no_wall_uses_every_beam(intel):
    scans, grid = intel
    k = 300
    # 1 km away: no end is near a wall, every beam would be skipped, so every beam is used
    poses = np.tile(scans.poses[k] + (1000.0, 0.0, 0.0), (50, 1))
    model = _core.LikelihoodFieldModel(grid, beam_skip=True)
    model.set_scan(scans.angles, scans.ranges[k], scans.max_range)
    used, _ = reference(grid, scans, k, poses)
    model.select_readings(poses, 2)
    assert model.used_beams == used.tolist() == list(range(model.beams))
    # without beam skipping the beams never change
    off = _core.LikelihoodFieldModel(grid)
    off.set_scan(scans.angles, scans.ranges[k], scans.max_range)
    off.select_readings(scans.poses[k][None, :], 1)
    assert off.used_beams == list(range(off.beams))


def test_every_pose_gets_its_brute_force_likelihood_wherever_it_falls_in_the_batch(intel):
    """The model places the laser once per pose with the map's rotation taken once per call,
    and (with AVX2) weighs poses four (then two) at a time, four beams at a time: each pose's
    value must be the numpy reference's, with a laser mounted off the robot's centre, and the
    same bits whether the pose is evaluated alone (one at a time) or with others."""
    scans, grid = intel
    k = 500
    sensor = _core.Pose2(0.12, -0.04, 0.03)
    rng = np.random.default_rng(7)
    poses = scans.poses[k] + rng.normal(0.0, 1.0, (23, 3)) * (0.4, 0.4, 0.2)
    poses[-1] = (-30.0, 0.0, 0.0)  # every end off the map
    model = _core.LikelihoodFieldModel(grid, sensor=sensor)
    model.set_scan(scans.angles, scans.ranges[k], scans.max_range)
    # the reference takes the laser's pose in the world
    c, s = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    lasers = np.column_stack(
        (
            poses[:, 0] + c * sensor.x - s * sensor.y,
            poses[:, 1] + s * sensor.x + c * sensor.y,
            poses[:, 2] + sensor.theta,
        )
    )
    _, ends = reference(grid, scans, k, lasers)
    expected = log_likelihood_reference(model, grid, ends, np.arange(model.beams))
    together = model.log_likelihoods(poses)
    np.testing.assert_allclose(together, expected, rtol=1e-9)
    assert together[-1] == pytest.approx(model.beams * model.outside, rel=1e-12)
    for start in range(6):
        np.testing.assert_array_equal(model.log_likelihoods(poses[start:]), together[start:])
        alone = model.log_likelihoods(poses[start : start + 1])
        np.testing.assert_array_equal(alone, together[start])
