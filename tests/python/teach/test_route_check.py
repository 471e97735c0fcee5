# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The route check: a leg through an occupied cell is refused unless the robot's body covered
that cell while it was taught; against a sampled walk along each leg, the footprint's closed
form, and a generated layout whose thesis map blocks its own taught route."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from kiseki.apps.teach import PlaybackConfig, playback
from kiseki.core import Pose2
from kiseki.errors import LogFormatError
from kiseki.grid import OccupancyGrid
from kiseki.io.ros_map import load_map
from kiseki.sim.scene import load_scene
from kiseki.teach.route_check import check_route, read_travelled, travelled_poses

FOOTPRINT = (1.05, 0.58)  # the thesis' AGV (length, width)


def _refused(grid: OccupancyGrid, a, b) -> bool:
    """Brute force: the leg a -> b walked in 0.5 mm steps meets an occupied cell before the
    last cell's width of it (the check forgives the goal's own cell)."""
    length = math.hypot(b[0] - a[0], b[1] - a[1])
    s = np.arange(0.0, length - grid.resolution, 0.0005)
    x = a[0] + s * (b[0] - a[0]) / length
    y = a[1] + s * (b[1] - a[1]) / length
    cx = np.floor((x - grid.origin.x) / grid.resolution).astype(int)
    cy = np.floor((y - grid.origin.y) / grid.resolution).astype(int)
    return bool(np.any(grid.cells[cy, cx] == 100))


def _marks(*points):
    return [{"name": f"W{i}", "x": p[0], "y": p[1], "theta": 0.0} for i, p in enumerate(points)]


def test_without_a_travelled_path_a_leg_is_refused_where_a_walk_along_it_meets_a_wall():
    rng = np.random.default_rng(0)
    cells = np.where(rng.random((40, 40)) < 0.04, 100, 0).astype(np.int8)
    grid = OccupancyGrid(cells, 0.1, Pose2(-2.0, -2.0, 0.0))
    compared = refusals = 0
    for _ in range(300):
        a, b = rng.uniform(-1.9, 1.9, 2), rng.uniform(-1.9, 1.9, 2)
        if math.hypot(*(b - a)) < 0.3:
            continue
        try:
            check_route(grid, _marks(a, b))
            refused = False
        except ValueError as err:
            refused = True
            assert "W0 -> W1 crosses occupied space at" in str(err)
        assert refused == _refused(grid, a, b), (a, b)
        compared, refusals = compared + 1, refusals + refused
    assert compared > 250 and 0.2 * compared < refusals < 0.8 * compared


def test_a_cell_under_the_taught_footprint_does_not_block_and_one_beside_it_does():
    grid = OccupancyGrid(np.zeros((30, 60), np.int8), 0.1)  # 6 m x 3 m, free
    grid.cells[15, 30] = 100  # the cell (3.05, 1.55): a shadow on the leg y = 1.55
    marks = _marks((0.55, 1.55), (5.55, 1.55))
    with pytest.raises(ValueError, match=r"crosses occupied space at \(3.05, 1.55\)"):
        check_route(grid, marks)
    # the robot turned there, 40 deg: the cell's centre 0.5 m ahead of its centre
    theta = math.radians(40.0)
    at = np.array([[3.05 - 0.5 * math.cos(theta), 1.55 - 0.5 * math.sin(theta), theta]])
    check_route(grid, marks, at, FOOTPRINT)
    # 0.03 m further back the centre is 0.53 m ahead, past the half length 0.525 m
    back = at - [[0.03 * math.cos(theta), 0.03 * math.sin(theta), 0.0]]
    with pytest.raises(ValueError, match=r"at \(3.05, 1.55\)"):
        check_route(grid, marks, back, FOOTPRINT)
    # a second occupied cell further along the leg that the robot never covered still blocks
    grid.cells[15, 45] = 100
    with pytest.raises(ValueError, match=r"at \(4.55, 1.55\)"):
        check_route(grid, marks, at, FOOTPRINT)
    assert grid.cells[15, 30] == 100  # the map given is not changed
    with pytest.raises(ValueError, match="footprint"):
        check_route(grid, marks, at, None)
    for bad in (0.0, math.nan, True):  # True was taken as a length of 1 m
        with pytest.raises(
            ValueError, match="^footprint: length must be a finite number > 0 m, got "
        ):
            check_route(grid, marks, at, (bad, FOOTPRINT[1]))
    with pytest.raises(ValueError) as caught:  # True was taken as a width of 1 m
        check_route(grid, marks, at, (FOOTPRINT[0], True))
    assert str(caught.value) == "footprint: width must be a finite number > 0 m, got True"
    with pytest.raises(ValueError, match="travelled"):
        check_route(grid, marks, at[:, :2], FOOTPRINT)


def test_a_layout_whose_thesis_map_blocks_its_own_taught_route_plays_back(tmp_path):
    """Generated layout 17909611376780542444 of layouts-exp2-exp3 (its first teaching run):
    the plane map keeps a cell occupied 0.04 m from T2, where the robot turned; refused
    before the teaching run's poses were used (about 8 s)."""
    from kiseki.core import derive_seed
    from kiseki.sim.layouts import generate_layout, write_layout
    from kiseki_experiments.teach import teach_playback as tp
    from kiseki_experiments.teach.layouts_config import LayoutsConfig, experiment_configs

    seed = 17909611376780542444
    scene_file = write_layout(generate_layout(seed), tmp_path / "layout.yaml")
    config = experiment_configs(LayoutsConfig(), scene_file)["exp2"]
    taught = tp.teach_route(config, derive_seed(seed, 10), tmp_path / "taught")
    plane = load_map(taught.maps["plane"])
    with pytest.raises(ValueError, match="T2 -> G crosses occupied space at"):
        check_route(plane, taught.marks)
    travelled = read_travelled(taught.waypoints)
    assert np.array_equal(travelled, travelled_poses(taught.log))
    assert len(travelled) == taught.steps
    play = PlaybackConfig(method="conventional", particles=50, max_duration=0.5)
    scene = load_scene(scene_file, "playback")
    with pytest.raises(ValueError, match="crosses occupied space"):
        playback(scene, plane, taught.marks, play, taught_scene=taught.scene)
    result = playback(
        scene, plane, taught.marks, play, taught_scene=taught.scene, travelled=travelled
    )
    assert result.steps == 5  # it drives (0.5 s at 10 Hz)
    # a waypoint file without its log: no poses, the map alone decides
    doc = yaml.safe_load(taught.waypoints.read_text())
    taught.log.rename(tmp_path / "elsewhere.mcap")
    assert read_travelled(taught.waypoints) is None and doc["log"] == taught.log.name


def test_a_log_that_is_not_a_teaching_log_is_named(tmp_path):
    bad = tmp_path / "teach.mcap"
    bad.write_bytes(b"not an mcap")
    with pytest.raises(LogFormatError, match="teach.mcap"):
        travelled_poses(bad)
