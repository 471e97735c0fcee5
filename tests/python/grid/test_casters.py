# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The ray casters on the Intel Research Lab map (built from its corrected log at 0.05 m): the
swept-sector caster equals the cell walk (cast_scans) and the distance-field caster, and the
beam model weighs a log's scans the same with either."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from kiseki import FREE, OccupancyGrid
from kiseki.datasets import read_carmen_log
from kiseki.filters import LocalizeConfig, localize, scan_model
from kiseki.grid import DEFAULT_RAY_CASTER, RAY_CASTERS, RangeCaster, SectorCaster
from kiseki.mapping import MapBuildConfig, map_of_log


@pytest.fixture(scope="module")
def intel(shared_data):
    scans = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz").scans
    return scans, map_of_log(scans, MapBuildConfig(resolution=0.05))


def free_poses(grid: OccupancyGrid, n: int, seed: int) -> np.ndarray:
    """n poses uniform over the free cells (uniform inside each cell), uniform headings."""
    rng = np.random.default_rng(seed)
    free = np.argwhere(np.asarray(grid.cells) == FREE)[:, ::-1]  # (x, y)
    cells = free[rng.integers(0, len(free), n)].astype(float) + rng.random((n, 2))
    origin = np.array([grid.origin.x, grid.origin.y])  # the map is not rotated
    xy = origin + cells * grid.resolution
    return np.column_stack([xy, rng.uniform(-np.pi, np.pi, n)])


@pytest.mark.parametrize("unknown_stops", [True, False])
def test_swept_sector_equals_the_cell_walk_on_the_intel_map(intel, unknown_stops):
    scans, grid = intel
    poses = free_poses(grid, 300, 1)
    angles = np.linspace(-np.pi, np.pi, 360, endpoint=False)
    reach = float(scans.max_range)  # 81.83 m
    want = grid.cast_scans(poses, angles, max_range=reach, unknown_is_obstacle=unknown_stops)
    sector = SectorCaster(grid, unknown_stops=unknown_stops)
    np.testing.assert_allclose(sector.scans(poses, angles, reach), want, rtol=0, atol=1e-9)
    np.testing.assert_allclose(sector.ranges(poses, angles, reach), want, rtol=0, atol=1e-9)
    field = RangeCaster(grid, unknown_stops=unknown_stops)
    np.testing.assert_allclose(field.ranges(poses, angles, reach), want, rtol=0, atol=1e-9)
    assert (want < reach).mean() > 0.9  # the rays end at walls, not at their reach


def test_the_beam_model_weighs_a_log_the_same_with_either_caster(intel):
    scans, grid = intel
    rng = np.random.default_rng(2)
    weights = {}
    for caster in RAY_CASTERS:
        config = LocalizeConfig(method="beam", beams=180, caster=caster, combination="nav2")
        model = scan_model("beam", grid, config)
        got = []
        for k in range(0, len(scans), 90):
            poses = scans.poses[k] + rng.normal(0, [0.3, 0.3, 0.1], (500, 3))
            model.set_scan(scans.angles, scans.ranges[k], scans.max_range)
            got.append(model.log_likelihoods(poses))
        rng = np.random.default_rng(2)  # the same poses for the next caster
        weights[caster] = np.concatenate(got)
    np.testing.assert_allclose(weights["swept-sector"], weights["distance-field"], rtol=1e-9)
    assert np.ptp(weights["swept-sector"]) > 1.0  # the poses are told apart


def test_casters_refuse_bad_input(intel):
    _, grid = intel
    assert DEFAULT_RAY_CASTER in RAY_CASTERS
    with pytest.raises(ValueError, match="sectors_per_octant"):
        SectorCaster(grid, sectors_per_octant=0)
    with pytest.raises(ValueError, match="occupied_threshold"):
        RangeCaster(grid, occupied_threshold=200)
    sector = SectorCaster(grid, sectors_per_octant=1)
    assert sector.sectors == 8 and sector.memory_bytes == 8 * grid.width * grid.height
    with pytest.raises(ValueError, match="poses"):
        sector.ranges(np.zeros((2, 2)), np.zeros(3), 10.0)
    with pytest.raises(ValueError, match="max_range"):
        sector.ranges(np.zeros((2, 3)), np.zeros(3), -1.0)
    with pytest.raises(ValueError, match="reach"):
        sector.scans(np.zeros((2, 3)), np.zeros(3), np.nan)
    with pytest.raises(ValueError, match="caster must be one of"):
        LocalizeConfig(method="beam", caster="lookup-table")


def test_beam_tracking_with_the_swept_sector_caster_is_the_same_on_any_thread_count(intel):
    scans, grid = intel
    n = 40
    part = dataclasses.replace(
        scans,
        times=scans.times[:n],
        poses=scans.poses[:n],
        odometry=scans.odometry[:n],
        ranges=scans.ranges[:n],
    )
    config = LocalizeConfig(method="beam", particles=300, seed=3, caster="swept-sector")
    runs = [localize(part, grid, dataclasses.replace(config, threads=t)) for t in (1, 2)]
    np.testing.assert_array_equal(runs[0].estimates, runs[1].estimates)
