# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Paper 004's limit along recorded logs: the direction of motion from the poses, eq. 1's ratio
and the passage width on the Intel lab's real scans against numpy counts of the definitions,
and the ``kiseki speed limits`` command with its bad input."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from _helpers.speed_reference import reference_ratio, reference_width
from kiseki.datasets import read_carmen_log
from kiseki.mapping import MapBuildConfig, map_of_log
from kiseki.speed import SpeedLimiterConfig, limits_along_log, motion_headings


def test_motion_headings_follow_the_displacement():
    poses = np.array(
        [[0, 0, 1.0], [1, 0, 1.0], [1, 0, 1.0], [1, 1, 2.0], [1, 1, 2.0], [1, 1, 2.5]], float
    )
    # toward the next pose that moved at least 1 cm; the own heading once it never moves again
    np.testing.assert_allclose(motion_headings(poses), [0, math.pi / 2, math.pi / 2, 2.5, 2.5, 2.5])
    np.testing.assert_allclose(motion_headings(poses[:1]), [1.0])


@pytest.mark.parametrize("min_step", [math.nan, -1.0, math.inf, "0.1", True])
def test_motion_headings_refuse_a_bad_min_step(min_step):
    """NaN or -1 gave the poses' own headings without a word."""
    with pytest.raises(ValueError, match="motion_headings: min_step must be a finite number"):
        motion_headings(np.zeros((3, 3)), min_step)
    with pytest.raises(ValueError, match=r"poses must be \(n, 3\)"):
        motion_headings(np.zeros((3, 2)))


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_motion_headings_refuse_a_pose_that_is_not_finite(bad):
    """[[0, 0, 0], [nan, 0, 0]] gave headings [0, 0] without a word."""
    poses = np.array([[0, 0, 0], [1, 0, 0], [bad, 0, 0.0]])
    with pytest.raises(ValueError) as caught:
        motion_headings(poses)
    assert (
        str(caught.value) == f"motion_headings: poses must be finite, pose 2 is [{bad}, 0.0, 0.0]"
    )
    poses[2] = [0.0, 0.0, bad]
    with pytest.raises(ValueError, match=r"motion_headings: poses must be finite, pose 2 is"):
        motion_headings(poses)


@pytest.fixture(scope="module")
def intel(shared_data):
    scans = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz").scans
    return scans, map_of_log(scans, MapBuildConfig(0.05))


def test_limits_on_real_scans_match_the_definitions(intel):
    scans, grid = intel
    part = scans.first(300)
    limits = limits_along_log(part, grid, SpeedLimiterConfig(), reach=4.0, heading="motion")
    laser = limits_along_log(part, grid, SpeedLimiterConfig(), reach=4.0)
    np.testing.assert_array_equal(laser.headings, part.poses[:, 2])
    assert np.all((limits.ratio >= 0) & (limits.ratio <= 1))
    clipped = np.minimum(part.ranges, np.float32(4.0))
    for i in range(0, 300, 37):
        pose, heading = part.poses[i], limits.headings[i]
        want = reference_ratio(grid, pose, part.angles, clipped[i], 4.0, math.pi / 2, heading)
        assert limits.ratio[i] == pytest.approx(want, abs=3e-3), i
        w = reference_width(part.angles, clipped[i], 4.0, heading - pose[2])
        assert limits.width[i] == pytest.approx(w, abs=1e-5), i
    f = 1 / (1 + np.exp(-4.9 * (limits.width - 1.3)))
    np.testing.assert_allclose(limits.v_ref, 0.5 * limits.ratio * f, rtol=1e-9)


def test_speed_limits_command_writes_the_csv_and_refuses_bad_input(intel, shared_data, tmp_path):
    from kiseki.io.ros_map import save_map

    scans, grid = intel
    map_yaml = save_map(grid, tmp_path / "intel.yaml")
    log = shared_data / "carmen" / "intel-corrected.log.gz"
    kiseki = [sys.executable, "-m", "kiseki.cli"]

    def run(*args):
        return subprocess.run([*kiseki, *map(str, args)], capture_output=True, text=True)

    out = tmp_path / "limits.csv"
    done = run("speed", "limits", log, "--map", map_yaml, "-o", out, "--plot", tmp_path / "l.png")
    assert done.returncode == 0, done.stderr
    table = pd.read_csv(out)
    assert len(table) == len(scans)
    assert list(table.columns) == [
        "t", "x", "y", "theta", "heading", "ratio", "width", "width_factor", "v_ref"
    ]  # fmt: skip
    np.testing.assert_allclose(table[["x", "y"]], scans.poses[:, :2], atol=1e-5)
    assert (tmp_path / "limits.config.yaml").is_file()
    assert (tmp_path / "l.png").stat().st_size > 20_000
    before = (tmp_path / "intel.pgm").read_bytes()
    for args, message in [
        (("--method", "fast"), "--method"),
        (("--reach", "-1"), "--reach"),
        (("--half-angle", "0"), "--half-angle"),
        (("--heading", "north"), "heading"),
    ]:
        bad = run("speed", "limits", log, "--map", map_yaml, "-o", tmp_path / "x.csv", *args)
        assert bad.returncode == 1 and message in bad.stderr, bad.stderr
        assert len(bad.stderr.strip().splitlines()) == 1
    bad = run("speed", "limits", log, "--map", map_yaml, "-o", tmp_path / "intel.pgm")
    assert bad.returncode == 1 and "intel.pgm" in bad.stderr
    assert (tmp_path / "intel.pgm").read_bytes() == before  # the map's image is untouched
    wean = shared_data / "cmu_wean" / "robotdata1.log.gz"
    bad = run("speed", "limits", wean, "--map", map_yaml, "-o", tmp_path / "w.csv")
    assert bad.returncode == 1 and "reference poses" in bad.stderr


@pytest.mark.parametrize("reach", [0.0, math.nan, True])  # True was a reach of 1 m
def test_limits_along_a_log_refuse_a_bad_reach(intel, reach):
    scans, grid = intel
    with pytest.raises(ValueError) as caught:
        limits_along_log(scans.first(3), grid, reach=reach)
    assert str(caught.value) == f"reach must be a finite number > 0 m, got {reach!r}"
