# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Unknown obstacles cut a recorded log's beams where a laser would have met them: the closed
form of a disc ahead, and random discs and rotated boxes against marching each beam in 1 mm
steps and asking the obstacles whether the point lies inside."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.datasets import LaserScans, UnknownObstacles, occlude_scans

MAX_RANGE = 8.0
STEP = 1e-3  # m, the marching reference's step


def _scans(poses, ranges=None, beams=181):
    poses = np.asarray(poses, dtype=float).reshape(-1, 3)
    n = len(poses)
    angles = np.linspace(-np.pi / 2, np.pi / 2, beams)
    if ranges is None:
        ranges = np.full((n, beams), MAX_RANGE, dtype=np.float32)
    return LaserScans(np.arange(n, dtype=float), poses, poses.copy(), ranges, angles, MAX_RANGE)


def _discs(centres, radii):
    return UnknownObstacles(centres, radii, np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0))


def _marched(scans, obstacles):
    """The reference: each beam walked in STEP increments up to its recorded reading."""
    t = np.arange(STEP, MAX_RANGE, STEP)
    out = np.array(scans.ranges, dtype=float)
    for k, (x, y, theta) in enumerate(scans.poses):
        for j, a in enumerate(scans.angles):
            pts = np.column_stack([x + t * np.cos(theta + a), y + t * np.sin(theta + a)])
            inside = np.flatnonzero(obstacles.contains(pts))
            if inside.size and t[inside[0]] < out[k, j]:
                out[k, j] = t[inside[0]]
    return out


def test_a_disc_ahead_cuts_the_beams_that_meet_it_at_the_closed_form_distance():
    scans = _scans([(0.0, 0.0, 0.0)])
    out, share = occlude_scans(scans, _discs([(5.0, 0.0)], [1.0]))
    b = 5.0 * np.cos(scans.angles)
    disc = b * b - 24.0
    want = np.where(disc >= 0, b - np.sqrt(np.clip(disc, 0, None)), MAX_RANGE)
    np.testing.assert_allclose(out.ranges[0], want, atol=1e-5)
    assert out.ranges[0, 90] == pytest.approx(4.0)
    # the beams within asin(1/5) of straight ahead meet it
    assert share == pytest.approx(np.mean(np.abs(scans.angles) <= np.arcsin(0.2) + 1e-12))
    assert scans.ranges.max() == MAX_RANGE  # the input is not changed


@pytest.mark.parametrize("seed", range(4))
def test_random_discs_and_rotated_boxes_equal_marching_every_beam(seed):
    rng = np.random.default_rng(seed)
    obstacles = UnknownObstacles(
        rng.uniform(-5, 5, (4, 2)),
        rng.uniform(0.2, 0.6, 4),
        rng.uniform(-5, 5, (4, 2)),
        rng.uniform(0.15, 0.8, (4, 2)),
        rng.uniform(-np.pi, np.pi, 4),
    )
    poses = []
    while len(poses) < 3:
        p = (*rng.uniform(-3, 3, 2), rng.uniform(-np.pi, np.pi))
        if not obstacles.contains(np.array([p[:2]])).any():
            poses.append(p)
    ranges = rng.uniform(0.5, MAX_RANGE, (3, 61)).astype(np.float32)
    ranges[:, ::5] = MAX_RANGE  # no returns
    ranges[:, 1::7] = np.nan  # invalid readings
    scans = _scans(poses, ranges, beams=61)
    out, _ = occlude_scans(scans, obstacles)
    want = _marched(scans, obstacles)
    valid = np.isfinite(want)
    assert np.isnan(out.ranges[~valid]).all()  # invalid stays invalid
    np.testing.assert_allclose(out.ranges[valid], want[valid], atol=2 * STEP)
    assert (out.ranges[valid] <= scans.ranges[valid]).all()
    assert (out.ranges[valid] < scans.ranges[valid]).any()  # the case cuts some beams


def test_a_box_seen_edge_on_and_a_beam_along_its_side():
    # a beam parallel to a box side: inside the slab it meets the near face, outside it misses
    box = UnknownObstacles(
        np.zeros((0, 2)), np.zeros(0), np.array([[3.0, 0.0]]), np.array([[0.5, 0.5]]), np.zeros(1)
    )
    scans = _scans([(0.0, 0.0, 0.0), (0.0, 0.49, 0.0), (0.0, 0.51, 0.0)], beams=3)
    out, _ = occlude_scans(scans, box)
    assert out.ranges[:, 1].tolist() == pytest.approx([2.5, 2.5, MAX_RANGE])


def test_refused_inputs_name_the_problem():
    inside = _discs([(0.0, 0.0)], [0.5])
    with pytest.raises(ValueError, match="laser of scan 1 lies inside an obstacle"):
        occlude_scans(_scans([(3.0, 3.0, 0.0), (0.1, 0.0, 0.0)]), inside)
    no_poses = _scans([(np.nan, np.nan, np.nan)])
    with pytest.raises(ValueError, match="no reference poses"):
        occlude_scans(no_poses, inside)
    with pytest.raises(ValueError, match="radii and half sizes must be positive"):
        _discs([(0.0, 0.0)], [0.0])
    with pytest.raises(ValueError, match="one radius per disc centre"):
        _discs([(0.0, 0.0), (1.0, 1.0)], [0.3])
    with pytest.raises(ValueError, match="must be finite"):
        _discs([(np.nan, 0.0)], [0.3])
