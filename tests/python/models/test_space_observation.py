# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The space observation model against a numpy version written from the thesis' definition
(its own heading bins, rotation and windows, nothing taken from the model), and its local-map
rotation against an independent numpy resampling, cell for cell."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from kiseki import Pose2
from kiseki.grid import OccupancyGrid, beam_angles
from kiseki.models import (
    LocalMapBuilder,
    SpaceObservationModel,
    likelihood_reference,
    visibility_reference,
)
from kiseki.sim.scene import load_scene


@pytest.fixture(scope="module")
def corridor(project_root):
    scene = load_scene(project_root / "data" / "worlds" / "factory_corridor.yaml")
    grid = scene.ground_truth(0.35, 0.45)
    angles = beam_angles(1081, np.radians(270))
    ranges = grid.cast_scans(np.array([[7.4, 0.0, 0.0]]), angles, max_range=30.0)[0]
    builder = LocalMapBuilder(8.0, 0.1)
    builder.add_scan(Pose2(), angles, ranges.astype(np.float32), 30.0)
    model = SpaceObservationModel(grid)
    model.set_local_map(builder.build())
    return grid, model


def independent_counts(local, grid, pose, occlusion_aware=False) -> tuple:
    """(penetrating, map_occupied, intruding, map_free) from the thesis' definition, sharing
    nothing with the model (not its heading bins, rotated maps or windows): the heading rounded
    to a whole degree, the local map (robot at its centre) turned to it by nearest-neighbour
    resampling of every window cell's centre, the span x span window of map cells read cell by
    cell around the grid corner nearest the particle (span = L's diagonal in map cells, odd)."""
    x, y, theta = (float(v) for v in pose)
    turn = np.radians(int(np.floor(np.degrees(np.arctan2(np.sin(theta), np.cos(theta))) + 0.5)))
    res, size = grid.resolution, local.width * local.resolution
    span = int(np.ceil(size * np.sqrt(2) / res)) | 1
    jj, ii = np.mgrid[0:span, 0:span]
    dx, dy = (ii - span // 2 + 0.5) * res, (jj - span // 2 + 0.5) * res
    lx = np.floor((np.cos(turn) * dx + np.sin(turn) * dy + size / 2) / local.resolution)
    ly = np.floor((-np.sin(turn) * dx + np.cos(turn) * dy + size / 2) / local.resolution)
    lx, ly = lx.astype(int), ly.astype(int)
    inside = (lx >= 0) & (lx < local.width) & (ly >= 0) & (ly < local.height)
    seen = np.full((span, span), -1)
    seen[inside] = local.cells[ly[inside], lx[inside]]
    wx = int(np.floor((x - grid.origin.x) / res + 0.5)) - span // 2 + ii
    wy = int(np.floor((y - grid.origin.y) / res + 0.5)) - span // 2 + jj
    on_map = (wx >= 0) & (wx < grid.width) & (wy >= 0) & (wy < grid.height)
    window = np.full((span, span), -1)
    window[on_map] = grid.cells[wy[on_map], wx[on_map]]
    occupied, free = window >= 65, (window >= 0) & (window <= 19)
    if occlusion_aware:
        centre = (int(wx[span // 2, span // 2]), int(wy[span // 2, span // 2]))
        hidden = free & (visibility_reference(grid, centre, span) == 0)
        occupied, free = occupied | hidden, free & ~hidden
    l_free, l_occ = seen == 0, seen >= 65
    view = l_free | l_occ
    return (
        int((l_free & occupied).sum()),
        int((view & occupied).sum()),
        int((l_occ & free).sum()),
        int((view & free).sum()),
    )


def test_cpp_equals_an_independent_numpy_version(corridor):
    grid, model = corridor
    local = plain_local(grid)  # the model's local map
    rng = np.random.default_rng(0)
    poses = np.column_stack(
        [rng.uniform(-1, 15, 300), rng.uniform(-2, 2, 300), rng.uniform(-np.pi, np.pi, 300)]
    )
    expected = []
    for pose in poses:  # the counts are identical...
        counts = independent_counts(local, grid, pose)
        assert tuple(model.counts(Pose2(*pose))) == counts, pose
        pen, m_occ, intr, m_free = counts
        pen, intr = 100.0 * pen / max(m_occ, 1), 100.0 * intr / max(m_free, 1)
        expected.append(np.exp(-0.5 * ((pen / 10.0) ** 2 + (intr / 130.0) ** 2)))
    # ...and so the likelihoods, up to the last bit of exp()
    np.testing.assert_allclose(model.likelihoods(poses), expected, rtol=1e-13, atol=0)
    # the packaged reference (the model's own rotation, numpy counting) agrees as well
    np.testing.assert_allclose(
        likelihood_reference(model, grid, poses[:30]), expected[:30], rtol=1e-13, atol=0
    )


def test_rotation_matches_an_independent_resampling(corridor):
    grid, model = corridor
    local = LocalMapBuilder(8.0, 0.1)  # the same local map, rebuilt for its cells
    angles = beam_angles(1081, np.radians(270))
    ranges = grid.cast_scans(np.array([[7.4, 0.0, 0.0]]), angles, max_range=30.0)[0]
    local.add_scan(Pose2(), angles, ranges.astype(np.float32), 30.0)
    cells = local.build().cells
    for bin_ in (0, 37, 90, 200, 333):
        rotated = model.rotated_local_map(bin_).cells
        span = rotated.shape[0]
        theta = np.radians(bin_)
        jj, ii = np.mgrid[0:span, 0:span]
        # cell centres relative to the window's corner, where the particle is
        dx, dy = (ii - span // 2 + 0.5) * grid.resolution, (jj - span // 2 + 0.5) * grid.resolution
        lx = np.cos(theta) * dx + np.sin(theta) * dy + 4.0
        ly = -np.sin(theta) * dx + np.cos(theta) * dy + 4.0
        cx, cy = np.floor(lx / 0.1).astype(int), np.floor(ly / 0.1).astype(int)
        inside = (cx >= 0) & (cx < 80) & (cy >= 0) & (cy < 80)
        expected = np.full((span, span), -1, dtype=np.int8)
        expected[inside] = cells[cy[inside], cx[inside]]
        np.testing.assert_array_equal(rotated, expected, err_msg=f"heading bin {bin_}")


def test_likelihood_prefers_the_true_pose_and_errors_run_along_the_corridor(corridor):
    _, model = corridor
    xs = np.linspace(-0.5, 0.5, 21)
    along = model.likelihoods(np.column_stack([7.4 + xs, np.zeros(21), np.zeros(21)]))
    across = model.likelihoods(np.column_stack([np.full(21, 7.4), xs, np.zeros(21)]))
    assert np.argmax(along) == 10 and np.argmax(across) == 10
    # sideways offsets are punished far harder than offsets along the corridor
    assert across[[0, 20]].max() < 0.01 < along[[0, 20]].min()


@pytest.mark.parametrize("heading_deg", [0.0, 90.0, 180.0, -90.0])
def test_no_half_cell_bias(heading_deg):
    """True poses spread evenly over a map cell, particles on a 1 cm lattice around each: the
    centroid of the best-scoring particles is the truth on average. L has the robot on a cell
    corner; the window was anchored on the map cell containing the particle, which treated every
    particle as sitting on its cell's lower-left corner: for axis-aligned headings the estimate
    ran half a cell (0.05 m) forward and to the left of the truth."""
    rng = np.random.default_rng(3)
    cells = np.where(rng.random((120, 120)) < 0.08, 100, 0).astype(np.int8)
    cells[[0, -1], :] = cells[:, [0, -1]] = 100
    grid = OccupancyGrid(cells, 0.1, Pose2(-6.0, -6.0, 0.0))
    theta = np.radians(heading_deg)
    angles = beam_angles(2000, 2 * np.pi)
    model = SpaceObservationModel(grid)
    offsets = np.arange(-0.2, 0.2001, 0.01)
    ox, oy = (a.ravel() for a in np.meshgrid(offsets, offsets))
    sub = [-0.03, -0.01, 0.01, 0.03]  # true positions within the cell, symmetric about its corner
    bias = []
    for tx, ty in [(a, b) for a in sub for b in sub]:
        ranges = grid.cast_scans(np.array([[tx, ty, theta]]), angles, max_range=4.0)[0]
        builder = LocalMapBuilder(8.0, 0.1)
        builder.add_scan(Pose2(), angles, ranges.astype(np.float32), 4.0)
        model.set_local_map(builder.build())
        like = model.likelihoods(np.column_stack([tx + ox, ty + oy, np.full(ox.size, theta)]))
        best = like >= like.max() * (1 - 1e-9)
        bias.append((ox[best].mean(), oy[best].mean()))
    forward, left = np.array(bias).mean(axis=0) @ np.array(
        [[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]]
    )
    assert abs(forward) < 0.01 and abs(left) < 0.01, (forward, left)


def test_bad_input(corridor):
    grid, model = corridor
    with pytest.raises(ValueError, match="poses"):
        model.likelihoods(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="NaN"):
        model.likelihoods(np.array([[np.nan, 0.0, 0.0]]))
    with pytest.raises(ValueError):
        SpaceObservationModel(grid, sigma_penetration=-1.0)
    # one pre-rotated local map per heading bin: 1e-9 deg asked for 3.6e11 of them
    with pytest.raises(ValueError, match="heading_step_deg must be >= 0.1"):
        SpaceObservationModel(grid, heading_step_deg=1e-9)
    for span in (10**5, 0, True):
        with pytest.raises(ValueError, match="span must be an integer in 1..1,001"):
            visibility_reference(grid, (5, 5), span)
    with pytest.raises(RuntimeError, match="local map first"):
        SpaceObservationModel(grid).counts(Pose2())
    with pytest.raises(ValueError, match="float32 of the camera"):
        LocalMapBuilder().add_depth_band(
            np.ones((5, 5), np.float32), np.eye(4), 160, 120, 100, 100, 80, 60, 0.5, 10.0, 0.4, 1.0
        )


def test_occlusion_aware_counts_equal_the_reference_and_hide_behind_walls(corridor):
    grid, plain = corridor
    model = SpaceObservationModel(grid, occlusion_aware=True)
    local = plain_local(grid)
    model.set_local_map(local)
    rng = np.random.default_rng(1)
    for x, y, th in np.column_stack(
        [rng.uniform(1, 13, 40), rng.uniform(-1, 1, 40), rng.uniform(-np.pi, np.pi, 40)]
    ):
        pose = Pose2(x, y, th)
        expected = independent_counts(local, grid, (x, y, th), occlusion_aware=True)
        assert tuple(model.counts(pose)) == expected
    seen = model.visible_from(Pose2(7.4, 0.0, 0.0)).cells
    span = seen.shape[0]
    assert seen[span // 2, span // 2] == 1  # its own cell
    assert seen[span // 2, span // 2 + 40] == 1  # 2 m along the corridor (0.05 m cells)
    assert seen[span // 2 + 45, span // 2] == 0  # 2.25 m to the left, behind the north wall


def walled_rooms():
    """12 m x 8 m at 0.1 m: outer walls, a partition with a doorway, a diagonal wall whose cells
    touch only at corners, pillars, and a patch of unknown cells."""
    cells = np.zeros((80, 120), dtype=np.int8)
    cells[[0, -1], :] = 100
    cells[:, [0, -1]] = 100
    cells[:, 60] = 100  # the partition...
    cells[30:38, 60] = 0  # ...and its doorway
    for k in range(25):  # a staircase wall, 8-connected only
        cells[50 + k, 15 + k] = 100
    cells[20, 30] = cells[21, 31] = cells[60, 90] = 100  # a diagonal pair, a lone pillar
    cells[10:14, 80:84] = 100
    cells[65:70, 100:110] = -1
    return OccupancyGrid(cells, 0.1, Pose2(0.0, 0.0, 0.0))


def test_visibility_equals_the_reference_cell_for_cell():
    grid = walled_rooms()
    model = SpaceObservationModel(grid, occlusion_aware=True)
    model.set_local_map(LocalMapBuilder(4.0, 0.1).build())  # a window of 57 x 57 cells
    rng = np.random.default_rng(2)
    cells = [(35, 33), (59, 34), (61, 20), (20, 70), (30, 20), (1, 1), (118, 78), (60, 5)]
    cells += [tuple(c) for c in rng.integers([-5, -5], [125, 85], (40, 2))]
    for cx, cy in cells:
        # the window is anchored on the map cell whose lower-left corner is nearest the pose
        seen = model.visible_from(Pose2(cx * 0.1 + 0.02, cy * 0.1 - 0.03, 0.3)).cells
        assert seen.shape == (57, 57)
        np.testing.assert_array_equal(seen, visibility_reference(grid, (cx, cy), 57))
    # and what it means: from (50, 34), in the left room's doorway row
    seen = model.visible_from(Pose2(5.0, 3.4, 0.0)).cells  # [row, column], centre (28, 28)
    assert seen[28, 28 + 10] == 1  # the partition cell itself is seen...
    assert seen[28, 28 + 15] == 1  # ...and the next room, through the doorway
    assert seen[28 - 20, 28 + 15] == 0  # but not behind the partition
    seen = model.visible_from(Pose2(2.0, 7.0, 0.0)).cells  # (20, 70), above the staircase
    assert seen[28 - 20, 28 + 20] == 0  # below it, behind cells touching only at corners
    seen = model.visible_from(Pose2(2.7, 2.4, 0.0)).cells  # (27, 24), below the diagonal pair
    assert seen[28 - 4, 28 + 3] == 1 and seen[28 - 3, 28 + 4] == 1  # sees the pair
    assert seen[28 - 2, 28 + 2] == 1  # and the cell before the corner they share,
    assert seen[28 - 4, 28 + 4] == 0  # but not through it


def plain_local(grid):
    angles = beam_angles(1081, np.radians(270))
    ranges = grid.cast_scans(np.array([[7.4, 0.0, 0.0]]), angles, max_range=30.0)[0]
    builder = LocalMapBuilder(8.0, 0.1)
    builder.add_scan(Pose2(), angles, ranges.astype(np.float32), 30.0)
    return builder.build()


def test_fig_3_14_claims_hold(tmp_path):
    """Five trials (the fewest with an interval): both claims decided, and the checks that no
    control can fail (table rows) as the thesis draws them."""
    from kiseki_experiments.harness.runner import run_experiment

    result = run_experiment("fig-3-14", runs=5, out=tmp_path / "f", progress=False)
    claims = pd.read_csv(result.run_dir / "claims.csv")
    assert len(claims) == 2 and (claims["verdict"] == "holds").all(), claims.to_string()
    checks = pd.read_csv(result.run_dir / "tables" / "checks.csv")
    peaks, far = checks.iloc[0], checks.iloc[1]
    assert max(abs(peaks["raw"]), abs(peaks["occlusion"])) <= 0.1 + 1e-9  # at x = 0
    assert max(far["raw"], far["occlusion"]) < 0.5  # fallen off on the other side
