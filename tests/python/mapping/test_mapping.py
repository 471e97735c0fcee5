# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Map building from logs with known poses, judged by where the scan endpoints land."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from kiseki import OccupancyGrid, Pose2, load_map
from kiseki.datasets import read_carmen_log
from kiseki.grid import beam_angles
from kiseki.mapping import (
    MapBuildConfig,
    build_map,
    endpoint_agreement,
    scan_local_builder,
    scan_local_map,
)
from kiseki.mapping.build import check_map_size


def test_intel_map_from_the_cli_holds_ninety_percent_of_endpoints(shared_data, tmp_path):
    log = shared_data / "carmen" / "intel-corrected.log.gz"
    out = tmp_path / "intel.yaml"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "kiseki.cli",
            "map",
            "from-log",
            str(log),
            "-o",
            str(out),
            "--render",
            str(tmp_path / "intel.png"),
        ],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    saved = load_map(out)  # judged on the map as saved and reloaded, not the in-memory one
    scans = read_carmen_log(log).scans
    share = endpoint_agreement(saved, scans.poses, scans.ranges, scans.angles, scans.max_range)
    assert share >= 0.90
    # the building is ~30 m x 30 m; the map covers it at 0.05 m cells
    assert 25 < saved.width * saved.resolution < 50 and 25 < saved.height * saved.resolution < 50
    cells = saved.cells
    assert 0.02 < np.mean(cells == 100) < 0.2 and np.mean(cells == 0) > 0.3
    # a map built from poses shifted by 0.5 m must fail the same test: it can fail
    shifted = scans.poses + [0.5, 0.0, 0.0]
    assert endpoint_agreement(saved, shifted, scans.ranges, scans.angles, scans.max_range) < 0.6


@pytest.mark.parametrize("name", ["aces-corrected", "csail-corrected", "freiburg-079-corrected"])
def test_other_carmen_logs_fit_their_poses_far_better_than_perturbed_ones(shared_data, name):
    """No absolute threshold is claimed for these logs (cluttered, people walking); the map
    built from the corrected poses must explain the scans far better than those poses
    perturbed by 0.2 m and 2 deg, which a broken mapper or reader would not show."""
    scans = read_carmen_log(shared_data / "carmen" / f"{name}.log.gz").scans
    grid = build_map(scans.poses, scans.ranges, scans.angles, scans.max_range)
    share = endpoint_agreement(grid, scans.poses, scans.ranges, scans.angles, scans.max_range)
    rng = np.random.default_rng(0)
    noisy = scans.poses + rng.normal(0, [0.2, 0.2, np.deg2rad(2)], scans.poses.shape)
    control = endpoint_agreement(grid, noisy, scans.ranges, scans.angles, scans.max_range)
    assert share > 0.8 and share > control + 0.25, (share, control)


def test_build_map_of_a_simulated_room_recovers_its_walls():
    cells = np.zeros((80, 120), dtype=np.int8)
    cells[[0, -1], :] = 100
    cells[:, [0, -1]] = 100
    truth = OccupancyGrid(cells, 0.05, Pose2())
    poses = np.column_stack([np.linspace(1, 5, 30), np.full(30, 2.0), np.linspace(0, 3, 30)])
    angles = beam_angles(361, np.pi)
    ranges = truth.cast_scans(poses, angles, max_range=10.0)
    grid = build_map(poses, ranges, angles, 10.0, MapBuildConfig(margin=0.5))
    assert endpoint_agreement(grid, poses, ranges, angles, 10.0, neighbourhood=0) > 0.97
    centre = grid.world_to_cell(np.array([[3.0, 2.0]]))[0]
    assert grid.cells[centre[1], centre[0]] == 0


@pytest.mark.parametrize(
    ("poses", "ranges", "match"),
    [
        (np.zeros((3, 2)), np.ones((3, 4)), "poses"),
        (np.zeros((3, 3)), np.ones((2, 4)), "one row per pose"),
        (np.zeros((3, 3)), np.ones((3, 5)), "ranges"),
        (np.full((3, 3), np.nan), np.ones((3, 4)), "NaN"),
        (np.zeros((0, 3)), np.ones((0, 4)), "non-empty"),
    ],
)
def test_build_map_rejects_bad_arrays(poses, ranges, match):
    with pytest.raises(ValueError, match=match):
        build_map(poses, ranges, np.zeros(4), 10.0)


def test_build_map_rejects_bad_parameters():
    poses, ranges = np.zeros((1, 3)), np.ones((1, 4))
    with pytest.raises(ValueError, match="resolution"):
        build_map(poses, ranges, np.zeros(4), 10.0, MapBuildConfig(resolution=-1))
    with pytest.raises(ValueError, match="prob_miss"):
        build_map(poses, ranges, np.zeros(4), 10.0, MapBuildConfig(prob_hit=0.3))
    with pytest.raises(ValueError, match="unknown"):
        MapBuildConfig.from_dict({"resolutoin": 0.1})
    # -1 scans per pass gave a map of unknown cells only; one per pass, the same map as 100
    for chunk in (-1, 0, 2.5, True):
        with pytest.raises(ValueError, match="chunk must be an integer >= 1"):
            build_map(poses, ranges, np.zeros(4), 10.0, chunk=chunk)
    np.testing.assert_array_equal(
        build_map(poses, ranges, np.zeros(4), 10.0, chunk=1).cells,
        build_map(poses, ranges, np.zeros(4), 10.0).cells,
    )


def test_build_map_refuses_negative_ranges_and_skips_nan_readings():
    poses, angles = np.zeros((2, 3)), np.linspace(-0.5, 0.5, 5)
    ranges = np.full((2, 5), 1.0)
    ranges[1, 2] = -2.0
    with pytest.raises(ValueError, match=r"ranges: scan 1 has a negative reading \(-2 m"):
        build_map(poses, ranges, angles, 10.0)
    ranges[1, 2] = np.nan  # no measurement: says nothing, the other beams map as before
    with_nan = build_map(poses, ranges, angles, 10.0)
    without = build_map(poses[:1], ranges[:1], angles, 10.0)
    np.testing.assert_array_equal(with_nan.cells, without.cells)


@pytest.mark.parametrize(
    ("resolution", "needle"),
    [
        (1e308, "makes a map of 1 x 1 cells .* at least 2 cells across"),
        (1e-9, "more than the limit of 1e\\+08 cells"),
    ],
)
def test_build_map_states_its_cell_limits(resolution, needle):
    poses, ranges = np.zeros((1, 3)), np.ones((1, 4))
    with pytest.raises(ValueError, match=needle):
        build_map(poses, ranges, np.linspace(-1, 1, 4), 10.0, MapBuildConfig(resolution))


def test_map_from_log_refuses_a_resolution_giving_a_one_cell_map(tmp_path):
    rows = [
        f"FLASER 180 {' '.join(['1.5', '3.0'] * 90)} {0.1 * k} 0 0 {0.1 * k} 0 0 {k} host {k}"
        for k in range(5)
    ]
    (tmp_path / "tiny.log").write_text("\n".join(rows) + "\n")
    args = [sys.executable, "-m", "kiseki.cli", "map", "from-log", "tiny.log", "-o", "m.yaml"]
    done = subprocess.run(
        [*args, "--resolution", "10"], cwd=tmp_path, capture_output=True, text=True
    )
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "at least 2 cells across" in lines[-1], done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.log"]  # no map written
    done = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr  # the same log at the default resolution maps


def test_map_from_log_without_a_return_names_the_log_and_writes_nothing(tmp_path):
    """A log whose every reading is at or beyond its max range (here a PARAM of 1 mm) has no
    endpoint to map: the map was written, then an error named no file ("no scan endpoint below
    max_range: agreement is undefined")."""
    rows = [
        f"FLASER 180 {' '.join(['1.5', '3.0'] * 90)} {0.1 * k} 0 0 {0.1 * k} 0 0 {k} host {k}"
        for k in range(5)
    ]
    (tmp_path / "short.log").write_text(
        "PARAM robot_front_laser_max 0.001 nohost 0\n" + "\n".join(rows) + "\n"
    )
    args = [sys.executable, "-m", "kiseki.cli", "map", "from-log", "short.log", "-o", "m.yaml"]
    done = subprocess.run(args, cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 1
    assert done.stderr.strip().splitlines() == [
        "kiseki: error: short.log: no range reading below the max range of 0.001 m (a reading at "
        "or beyond it is no return): nothing to map"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["short.log"]  # no map written


def test_check_map_size_refuses_what_it_cannot_divide():
    """resolution 0 was a ZeroDivisionError, NaN "cannot convert float NaN to integer", inf an
    OverflowError; a good extent gives the ceiling of each side over the resolution."""
    assert check_map_size(10.0, 4.01, 0.5) == (20, 9)
    for bad in (0.0, float("nan"), float("inf"), -0.1, True):  # True was taken as 1 m
        with pytest.raises(
            ValueError, match="^check_map_size: resolution must be a finite number > 0 m, got "
        ):
            check_map_size(10.0, 10.0, bad)
    for name, sides in (("width", (True, 10.0)), ("height", (10.0, True))):  # 1 m: 2 cells
        with pytest.raises(ValueError) as caught:
            check_map_size(*sides, 0.5)
        assert (
            str(caught.value) == f"check_map_size: {name} must be a finite number > 0 m, got True"
        )


def test_scan_local_map_takes_readings_at_or_below_zero_as_no_reading():
    """A negative or zero reading is no reading, as a NaN one: the local map and its hit cells
    are those of the scan without those beams."""
    angles = np.linspace(-np.pi, np.pi, 180, endpoint=False)
    ranges = np.full(180, 2.0)
    bad, none = ranges.copy(), ranges.copy()
    bad[::3], bad[1::3] = -1.5, 0.0
    none[::3], none[1::3] = np.nan, np.nan
    with_bad, without = scan_local_builder(angles, bad, 5.0), scan_local_builder(angles, none, 5.0)
    np.testing.assert_array_equal(with_bad.build().cells, without.build().cells)
    np.testing.assert_array_equal(with_bad.hits(), without.hits())
    assert np.asarray(without.hits()).size > 0  # the remaining beams did map something


@pytest.mark.parametrize("bad", [np.nan, np.inf, 0.0, -5.0, 1e300, True, "5", None])
def test_a_max_range_that_is_no_length_is_refused(bad):
    """A NaN max range counted every reading as an endpoint (agreement 1.0); "5" was a numpy
    ufunc error in the local map, 1e300 an overflow warning; a string was taken by build_map."""
    angles = np.linspace(-1.0, 1.0, 9)
    poses, ranges = np.zeros((1, 3)), np.full((1, 9), 2.0)
    grid = build_map(poses, ranges, angles, 10.0)
    needle = r"max_range must be a finite number in \(0, 1e\+09\] m, got "
    with pytest.raises(ValueError, match="endpoint_agreement: " + needle):
        endpoint_agreement(grid, poses, ranges, angles, bad)
    with pytest.raises(ValueError, match="local map: " + needle):
        scan_local_map(angles, ranges[0], bad)
    with pytest.raises(ValueError, match="build_map: " + needle):
        build_map(poses, ranges, angles, bad)
    assert endpoint_agreement(grid, poses, ranges, angles, np.float32(10.0)) == 1.0


def test_endpoint_agreement_counts_no_reading_at_or_below_zero_and_says_so():
    """All readings negative said "no scan endpoint below max_range", as if they were too long."""
    angles = np.linspace(-1.0, 1.0, 9)
    poses, ranges = np.zeros((1, 3)), np.full((1, 9), 2.0)
    grid = build_map(poses, ranges, angles, 10.0)
    some_bad = ranges.copy()
    some_bad[0, ::2] = -2.0
    assert endpoint_agreement(grid, poses, some_bad, angles, 10.0) == 1.0  # 4 good endpoints
    for bad in (-ranges, 0 * ranges):
        with pytest.raises(ValueError, match=r"no scan endpoint \(a reading > 0 and below max_ra"):
            endpoint_agreement(grid, poses, bad, angles, 10.0)
    for neighbourhood in (1.5, True, -1, 11):
        with pytest.raises(ValueError, match="neighbourhood must be an integer in 0..10"):
            endpoint_agreement(grid, poses, ranges, angles, 10.0, neighbourhood)
    with pytest.raises(TypeError, match="grid must be a kiseki OccupancyGrid, got NoneType"):
        endpoint_agreement(None, poses, ranges, angles, 10.0)
