# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki terrain run``: the rubble paper's loop (S-DEM, plane removal, correlation search,
OctoMap global map) run as a user would, in the rubble scene and in a real building's octree,
with its outputs read back by independent readers."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from _helpers.scene_boxes import near_small_boxes
from kiseki import _core
from kiseki.sim.terrain_moves import terrain_stops
from kiseki.terrain import remove_planes, sdem_from_ranges
from kiseki.terrain.mapper import MapperConfig, SdemMapper

ROOT = Path(__file__).resolve().parents[3]
RUBBLE_A = ROOT / "data" / "worlds" / "rubble_a.yaml"
GEB079 = ROOT.parent / "shared" / "data" / "octomap" / "geb079.bt"


def run(*args) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "terrain", "run", *map(str, args)],
        capture_output=True,
        text=True,
    )


def read_trajectory(path: Path) -> np.ndarray:
    lines = path.read_text().splitlines()
    assert lines[0] == "move,x_true,y_true,z_true,x_est,y_est,z_est"
    return np.array([[float(v) for v in line.split(",")] for line in lines[1:]])


@pytest.fixture(scope="module")
def rubble_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("terrain") / "run"
    done = run(RUBBLE_A, "--moves", 3, "-o", out, "--seed", 4)
    assert done.returncode == 0, done.stderr
    return out, done


def test_run_in_the_rubble_tracks_the_sensor_within_centimetres(rubble_run):
    out, done = rubble_run
    table = read_trajectory(out / "trajectory.csv")
    assert table.shape == (4, 7) and list(table[:, 0]) == [0, 1, 2, 3]
    true, est = table[:, 1:4], table[:, 4:7]
    np.testing.assert_allclose(est[0], true[0])  # the start is given
    steps_true = np.linalg.norm(np.diff(true, axis=0), axis=1)
    np.testing.assert_allclose(steps_true[:2], 0.35, atol=0.03)  # stops every 0.35 m
    # each move is found to within 10 cm (measured 5-7 cm: the 2 cm grid, the gyro's 0.5 deg and
    # the laser's noise); standing still (the zero motion) would be 35 cm off
    step_err = np.linalg.norm(np.diff(est, axis=0) - np.diff(true, axis=0), axis=1)
    assert step_err.max() < 0.10, step_err
    assert "4 stops" in done.stdout


def test_run_outputs_read_back_with_independent_readers(rubble_run):
    out, _ = rubble_run
    for k in range(4):
        points, width, height, dropped = _core.read_pcd(str(out / f"sdem_{k:03d}.pcd"))
        assert len(points) == width * height > 1000 and dropped == 0
        assert np.linalg.norm(points, axis=1).max() < 5.0  # the paper's 5 m cut
    tree = _core.OctreeWorld.read_binary(str(out / "global_map.bt"))
    assert tree.resolution == pytest.approx(0.05)
    # the floor under the route is in the map: a ray straight down from above the first stop
    table = read_trajectory(out / "trajectory.csv")
    x, y = table[0, 1:3]
    down = tree.cast_many(np.array([[x, y, 0.4]]), np.array([[0.0, 0.0, -1.0]]), 2.0)[0]
    assert 0.3 < down < 0.5  # the floor's voxel (0..0.05 m) below z = 0.4
    config = (out / "config.yaml").read_text()
    assert "removal: hough" in config and "seed: 4" in config
    assert (out / "trajectory.png").stat().st_size > 10_000


@pytest.mark.skipif(shutil.which("bt2vrml") is None, reason="octomap-tools is not installed")
def test_octomaps_own_tool_reads_the_global_map(rubble_run, tmp_path):
    """octomap-tools' bt2vrml (the library's own reader, as octovis uses) reads every occupied
    voxel that kiseki's reader sees."""
    out, _ = rubble_run
    copy = tmp_path / "map.bt"
    copy.write_bytes((out / "global_map.bt").read_bytes())
    done = subprocess.run(["bt2vrml", str(copy)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    found = re.search(r"Finished writing (\d+) voxels", done.stdout + done.stderr)
    assert found, done.stdout
    assert int(found.group(1)) == _core.OctreeWorld.read_binary(str(copy)).occupied_leaves > 1000


def test_the_same_seed_gives_the_same_run(tmp_path, rubble_run):
    out, _ = rubble_run
    again = run(RUBBLE_A, "--moves", 3, "-o", tmp_path / "again", "--seed", 4)
    assert again.returncode == 0, again.stderr
    assert (tmp_path / "again" / "trajectory.csv").read_text() == (
        out / "trajectory.csv"
    ).read_text()


def test_mapper_levels_each_sweep_with_the_gyro():
    """The levelled S-DEM of a stop on the slope equals the level one the sensor would see
    after turning by the true roll and pitch: the floor's rows stay in place."""
    stops = terrain_stops(RUBBLE_A, 1, seed=5)
    mapper = SdemMapper(MapperConfig(search="coarse-to-fine"), start=stops[0].sensor[:3, 3])
    for s in stops:
        mapper.add(s.ranges, s.gyro_rpy)
    assert len(mapper.sweeps) == 2 and mapper.sweeps[0].search is None
    result = mapper.sweeps[1].search
    true_move = stops[1].sensor[:3, 3] - stops[0].sensor[:3, 3]
    yaw0 = stops[0].gyro_rpy[2]
    c, s = np.cos(yaw0), np.sin(yaw0)
    in_frame = np.array([c * true_move[0] + s * true_move[1], -s * true_move[0] + c * true_move[1]])
    np.testing.assert_allclose(result.translation[:2], in_frame, atol=0.06)


@pytest.mark.parametrize("voxel", [0.001, 10.5, float("nan")])
def test_a_voxel_outside_its_range_is_refused(voxel):
    with pytest.raises(
        ValueError, match=r"^voxel must be a finite number in \[0.005, 10\] m, got "
    ):
        MapperConfig(voxel=voxel)


@pytest.mark.skipif(not GEB079.exists(), reason="the recorded Freiburg 079 octree is absent")
def test_run_in_a_real_building_finds_its_own_start(tmp_path):
    done = run(GEB079, "--moves", 2, "-o", tmp_path / "bt", "--seed", 1)
    assert done.returncode == 0, done.stderr
    table = read_trajectory(tmp_path / "bt" / "trajectory.csv")
    world = _core.OctreeWorld.read_binary(str(GEB079))
    lo, hi = world.bounds
    assert np.all(table[:, 1:3] > lo[:2]) and np.all(table[:, 1:3] < hi[:2])
    # the start is free: nothing within 0.5 m around the sensor at its height
    o = np.tile(table[0, 1:4], (8, 1))
    a = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    d = np.column_stack([np.cos(a), np.sin(a), np.zeros(8)])
    assert world.cast_many(o, d, 0.5).min() >= 0.5


@pytest.mark.skipif(not GEB079.exists(), reason="the recorded Freiburg 079 octree is absent")
def test_an_octree_header_with_absurd_voxels_is_refused_in_one_line(tmp_path):
    """The header's voxel size scales the whole tree: 1e9 m voxels asked numpy for terabytes
    (a traceback); kiseki reads 0.1 mm to 10 m voxels and refuses others naming the file."""
    data = GEB079.read_bytes()
    assert b"\nres 0.08\n" in data
    bad = tmp_path / "huge.bt"
    bad.write_bytes(data.replace(b"\nres 0.08\n", b"\nres 1e9\n", 1))
    done = run(bad, "--moves", 1, "-o", tmp_path / "out")
    assert done.returncode == 1, done.stderr
    assert f"kiseki: error: {bad}: voxels of 1e+09 m: kiseki reads 0.0001-10 m" in done.stderr
    assert "Traceback" not in done.stderr
    assert not any((tmp_path / "out").glob("*"))  # nothing written (the folder is made first)


@pytest.mark.skipif(not GEB079.exists(), reason="the recorded Freiburg 079 octree is absent")
def test_an_octree_too_small_to_stand_in_names_its_file(tmp_path):
    """0.2 mm voxels (a header edited within kiseki's limits) shrink the building to 8 cm: the
    run found no free start and said so naming no file."""
    small = tmp_path / "small.bt"
    small.write_bytes(GEB079.read_bytes().replace(b"\nres 0.08\n", b"\nres 0.0002\n", 1))
    with pytest.raises(ValueError, match=f"^{re.escape(str(small))}: free_start: the world is"):
        terrain_stops(small, 1, 0)


@pytest.mark.skipif(not GEB079.exists(), reason="the recorded Freiburg 079 octree is absent")
def test_a_run_whose_search_fails_names_its_world(tmp_path):
    """5 m voxels (within kiseki's limits): the second sweep shares no cells with the first, and
    the one line named the sweep but not the world."""
    big = tmp_path / "big.bt"
    big.write_bytes(GEB079.read_bytes().replace(b"\nres 0.08\n", b"\nres 5\n", 1))
    done = run(big, "--moves", 1, "-o", tmp_path / "out")
    assert done.returncode == 1, done.stderr
    assert done.stderr.strip().splitlines()[-1] == (
        f"kiseki: error: {big}: sweep 1: no candidate shares enough cells with sweep 0"
    )


@pytest.mark.skipif(not GEB079.exists(), reason="the recorded Freiburg 079 octree is absent")
def test_a_truncated_octree_is_one_line_with_octomaps_reason(tmp_path):
    """OctoMap reports a damaged tree on stderr, not to its caller: its line came above
    kiseki's one-line error. Now its reason is part of that line, and nothing else is printed."""
    cut = tmp_path / "cut.bt"
    cut.write_bytes(GEB079.read_bytes()[:100_000])
    done = run(cut, "--moves", 1, "-o", tmp_path / "out")
    assert done.returncode == 1, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    # the nodes read before the cut are OctoMap's count (248,160 with Debian 12's 1.9.7); the
    # expected count is the header's
    assert re.fullmatch(
        rf"kiseki: error: {re.escape(str(cut))}: corrupt or truncated OctoMap binary file "
        r"\(OctoMap: Tree size mismatch: # read nodes \(\d+\) != # expected nodes \(532566\)\)",
        lines[0],
    ), lines[0]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--moves", 0), "moves must be an integer in 1..200"),
        (("--moves", 100), "the route is"),
        (("--moves", 1, "--step", 0.9), "step must be"),
        (("--moves", 1, "--removal", "magic"), "removal must be"),
        (("--moves", 1, "--search", "annealing"), "search must be"),
        (("--moves", 1, "--seed", -1), "--seed"),
    ],
)
def test_bad_input_exits_1_with_one_line(tmp_path, args, message):
    done = run(RUBBLE_A, *args, "-o", tmp_path / "bad")
    assert done.returncode == 1, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and message in lines[0], done.stderr


def test_missing_world_and_occupied_output(tmp_path, rubble_run):
    done = run(tmp_path / "nowhere.yaml", "--moves", 1, "-o", tmp_path / "x")
    assert done.returncode == 1 and "no such file" in done.stderr
    out, _ = rubble_run
    done = run(RUBBLE_A, "--moves", 1, "-o", out)
    assert done.returncode == 1 and "already holds a run" in done.stderr


@pytest.mark.parametrize("name", ["config.yaml", "trajectory.png", "sdem_000.pcd"])
def test_a_folder_of_the_users_files_is_refused_and_kept(tmp_path, name):
    """-o . in a folder holding the user's config.yaml or trajectory.png replaced them (only
    trajectory.csv was looked for); every file the run writes is looked for now."""
    (tmp_path / name).write_text("the user's own")
    (tmp_path / "notes.txt").write_text("not the run's")
    done = run(RUBBLE_A, "--moves", 1, "-o", tmp_path)
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert done.returncode == 1 and lines == [
        f"kiseki: error: -o {tmp_path} holds {name}, which this command would replace: "
        "choose another folder (an unfinished run leaves its sdem_*.pcd: remove them)"
    ]
    assert (tmp_path / name).read_text() == "the user's own"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([name, "notes.txt"])


def test_plane_removal_keeps_the_rubble_and_drops_the_walls():
    stops = terrain_stops(RUBBLE_A, 1, seed=6)
    sdem = sdem_from_ranges(stops[0].ranges)
    hough = remove_planes(sdem, "hough")
    pcl = remove_planes(sdem, "pcl", seed=1)
    # Each map point labelled by brute force: on a heap's box (within 3 cm) or not (floor,
    # walls). Both removals take out at least 80 % of the room and at most 10 % of the heaps.
    points, cells = sdem.to_points()
    sensor = np.asarray(stops[0].sensor)
    heap = near_small_boxes(RUBBLE_A, points @ sensor[:3, :3].T + sensor[:3, 3], 0.03)
    assert heap.sum() > 500 and (~heap).sum() > 500
    for removal in (hough, pcl):
        removed = removal.removed.reshape(-1)[cells]
        assert removed[~heap].mean() >= 0.8 and removed[heap].mean() <= 0.1, removal.method
    assert 0.05 < hough.kept_share < 0.9 and 0.05 < pcl.kept_share < 0.95
    assert pcl.found >= 2  # the floor and at least one wall
    normals = pcl.planes[:, :3]
    assert np.any(np.abs(normals[:, 2]) > 0.99)  # a horizontal plane: the floor
    assert np.any(np.abs(normals[:, 2]) < 0.05)  # a vertical one: a wall
