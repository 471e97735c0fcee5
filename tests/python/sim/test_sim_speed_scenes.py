# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The speed-control scenes (paper 004) measured against the numbers their files state: clear
widths, the unknown box, the corner and its sweep of poses, all read off the ground-truth grid
at the laser's height (0.05 m cells, faces on cell edges, so the widths are exact)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from kiseki.sim.scene import load_scene

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"
LASER_Z = 0.3  # the scenes' laser mount height
RES = 0.05


def grid_of(scene, z_lo=LASER_Z - 0.02, z_hi=LASER_Z + 0.02):
    grid = scene.ground_truth(z_lo, z_hi, RES)
    return grid.cells.copy(), np.asarray(scene.bounds[0][:2], dtype=float)


def occupied(cells, origin, x, y) -> bool:
    i, j = int(math.floor((x - origin[0]) / RES)), int(math.floor((y - origin[1]) / RES))
    if not (0 <= j < cells.shape[0] and 0 <= i < cells.shape[1]):
        return True  # outside the scene
    return bool(cells[j, i] == 100)


def free_run(cells, origin, x, y, axis: int) -> tuple[float, float]:
    """(lo, hi) world coordinates of the free cells through (x, y) along x (0) or y (1), ended by
    an occupied cell or the scene's edge."""
    i, j = int(math.floor((x - origin[0]) / RES)), int(math.floor((y - origin[1]) / RES))
    line = cells[j, :] if axis == 0 else cells[:, i]
    k = i if axis == 0 else j
    assert line[k] != 100, f"({x}, {y}) is not free"
    lo = k
    while lo > 0 and line[lo - 1] != 100:
        lo -= 1
    hi = k
    while hi < line.size - 1 and line[hi + 1] != 100:
        hi += 1
    return origin[axis] + lo * RES, origin[axis] + (hi + 1) * RES


def route_x(scene) -> set[float]:
    return {round(float(p[0]), 9) for p in scene.route["waypoints"]}


def test_corridor_is_1_5_m_wide_and_opens_into_a_6_m_hall():
    scene = load_scene(WORLDS / "speed_corridor.yaml")
    cells, origin = grid_of(scene)
    for y in (-0.9, 0.0, 2.5, 5.95):
        lo, hi = free_run(cells, origin, 0.0, y, 0)
        assert (lo, hi) == pytest.approx((-0.75, 0.75), abs=1e-9), y
    for y in (6.05, 10.0, 13.95):
        assert free_run(cells, origin, 0.0, y, 0) == pytest.approx((-3.0, 3.0), abs=1e-9), y
    assert free_run(cells, origin, 2.0, 10.0, 1) == pytest.approx((6.0, 14.0), abs=1e-9)
    # the route runs on the corridor's centre line, straight, and ends inside the hall
    assert route_x(scene) == {0.0}
    assert 6.0 + 0.35 < scene.route["waypoints"][-1][1] < 14.0 - 0.35


def test_crossroad_arms_are_2_3_m_and_the_box_stands_in_the_left_arm():
    teach = load_scene(WORLDS / "speed_crossroad.yaml", "teach")
    playback = load_scene(WORLDS / "speed_crossroad.yaml", "playback")
    cells, origin = grid_of(teach)
    for y in (-1.5, 0.0, 3.8, 6.2, 11.5):
        assert free_run(cells, origin, 0.0, y, 0) == pytest.approx((-1.15, 1.15), abs=1e-9), y
    for x in (-5.5, -3.0, 3.0, 5.5):
        assert free_run(cells, origin, x, 5.0, 1) == pytest.approx((3.85, 6.15), abs=1e-9), x
    assert free_run(cells, origin, 0.0, 4.5, 0) == pytest.approx((-6.0, 6.0), abs=1e-9)
    assert route_x(teach) == {0.0}
    # the unknown box: 0.60 m (x) x 0.80 m (y) centred at (-1.45, 4.5), only in playback
    box, _ = grid_of(playback)
    added = np.argwhere((box == 100) & (cells != 100))  # (row j, column i)
    xs = origin[0] + RES * np.array([added[:, 1].min(), added[:, 1].max() + 1])
    ys = origin[1] + RES * np.array([added[:, 0].min(), added[:, 0].max() + 1])
    assert xs == pytest.approx([-1.75, -1.15], abs=1e-9)
    assert ys == pytest.approx([4.1, 4.9], abs=1e-9)
    assert len(added) == 12 * 16  # 0.60 / 0.05 columns x 0.80 / 0.05 rows, all of them
    # in the left arm: right face on the main corridor's left face, 0.25 m past the entry
    assert free_run(box, origin, 0.0, 4.5, 0) == pytest.approx((-1.15, 6.0), abs=1e-9)
    assert free_run(box, origin, -1.45, 3.9, 1) == pytest.approx((3.85, 4.1), abs=1e-9)
    assert free_run(box, origin, -1.45, 5.5, 1) == pytest.approx((4.9, 6.15), abs=1e-9)


def test_corner_geometry_and_its_sweep_of_thirteen_poses():
    scene = load_scene(WORLDS / "speed_corner.yaml")
    cells, origin = grid_of(scene)
    cx, cy = 1.15, 0.0  # the inner corner C the file states
    for y in (-3.9, -2.0, -0.05):
        assert free_run(cells, origin, 0.0, y, 0) == pytest.approx((-1.15, 1.15), abs=1e-9), y
    assert free_run(cells, origin, 0.0, 1.0, 0) == pytest.approx((-1.15, 6.0), abs=1e-9)
    for x in (1.2, 3.0, 5.9):
        assert free_run(cells, origin, x, 1.0, 1) == pytest.approx((0.0, 2.3), abs=1e-9), x
    assert free_run(cells, origin, 0.0, 0.0, 1) == pytest.approx((-4.0, 2.3), abs=1e-9)
    # C is the convex corner of the solid: occupied below-right of it, free elsewhere around
    assert occupied(cells, origin, cx + 0.025, cy - 0.025)
    assert not occupied(cells, origin, cx - 0.025, cy - 0.025)
    assert not occupied(cells, origin, cx + 0.025, cy + 0.025)
    assert not occupied(cells, origin, cx - 0.025, cy + 0.025)
    # the route: up the approach corridor's centre, then along the side corridor's centre
    assert [list(p) for p in scene.route["waypoints"]][1:] == [[0.0, 1.15], [5.0, 1.15]]
    poses = np.array(scene.poses)
    assert poses.shape == (13, 3)
    assert np.abs(np.hypot(poses[:, 0] - cx, poses[:, 1] - cy) - 1.5).max() < 1e-3
    phi = np.degrees(np.arctan2(cy - poses[:, 1], cx - poses[:, 0]))
    np.testing.assert_allclose(phi, np.arange(0, 61, 5), atol=1e-9)
    np.testing.assert_allclose(poses[:, 2], math.pi / 2)
    # every 0.70 m footprint (square, heading +y) covers only free cells up to the robot's top
    body, _ = grid_of(scene, 0.05, 1.2)
    for x, y, _ in poses:
        i0, i1 = (math.floor((v - origin[0]) / RES) for v in (x - 0.35, x + 0.35))
        j0, j1 = (math.floor((v - origin[1]) / RES) for v in (y - 0.35, y + 0.35))
        assert (body[j0 : j1 + 1, i0 : i1 + 1] != 100).all(), (x, y)


@pytest.mark.parametrize(
    "poses, field",
    [
        ({"corner": [1, 0], "distance": 1.5, "phi_deg": [0, 60], "heading_deg": 90}, "phi_deg"),
        ({"corner": [1, 0], "distance": -1, "phi_deg": [0, 60, 5], "heading_deg": 90}, "distance"),
        ({"corner": [1, "a"], "distance": 1, "phi_deg": [0, 60, 5], "heading_deg": 90}, "corner"),
        ({"corner": [1, 0], "distance": 1, "phi_deg": [0, 60, 0], "heading_deg": 90}, "phi_deg"),
        ({"corner": [1, 0], "distance": 1, "phi_deg": [0, 60, 5]}, "poses"),
    ],
)
def test_bad_poses_name_the_file_and_the_field(tmp_path, poses, field):
    doc = yaml.safe_load((WORLDS / "speed_corner.yaml").read_text())
    doc["poses"] = poses
    path = tmp_path / "bad_poses.yaml"
    path.write_text(yaml.safe_dump(doc))
    with pytest.raises(ValueError, match=field) as info:
        load_scene(path)
    assert "bad_poses.yaml" in str(info.value)


def test_scenes_without_poses_have_none():
    assert load_scene(WORLDS / "speed_corridor.yaml").poses is None
