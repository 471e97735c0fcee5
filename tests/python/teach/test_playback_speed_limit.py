# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Route playback under a speed limit (paper 004 in playback): the follower's cap, the limiter
fed with the laser at the true pose and the sensor pose of the estimate, the true speed within
the limits, and the MCAP log's /speed_limit messages with nav2_msgs/SpeedLimit's fields."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from kiseki import load_map
from kiseki.apps.teach import PlaybackConfig, playback, teach
from kiseki.apps.teach.taught_route import load_taught
from kiseki.control import PurePursuit, SpeedLimit
from kiseki.io.runlog import read_run
from kiseki.sim.scene import load_scene

LASER_X = 0.45  # m, the corridor AGV's laser mount ahead of its centre (factory_corridor.yaml)


def test_pure_pursuit_speed_cap_by_hand():
    # straight route along x; route speed 0.5 m/s, a_max 0.5 m/s^2, braking cap
    # sqrt(2 * 0.8 * 0.5 * d) = sqrt(0.8 d)
    def follower():
        return PurePursuit([[0.0, 0.0], [10.0, 0.0]], 0.5, 0.6, 0.1, 0.5)

    assert follower().command((0.0, 0.0, 0.0)) == (0.5, 0.0, 0.0)
    assert follower().command((0.0, 0.0, 0.0), max_speed=0.2) == (0.2, 0.0, 0.0)
    assert follower().command((0.0, 0.0, 0.0), max_speed=0.7) == (0.5, 0.0, 0.0)
    # 0.3 m left of the path: goal point (0.6, 0) is at l_x = 0.6, l_y = -0.3 in the body,
    # curvature 2 * -0.3 / 0.45 = -4/3 1/m, yaw rate -4/3 * 0.2
    v, _, w = follower().command((0.0, 0.3, 0.0), max_speed=0.2)
    assert v == pytest.approx(0.2) and w == pytest.approx(-0.8 / 3)
    # 0.5 m before the goal the braking cap is sqrt(0.4) = 0.632: the route speed or the cap
    assert follower().command((9.5, 0.0, 0.0))[0] == pytest.approx(0.5)
    assert follower().command((9.5, 0.0, 0.0), max_speed=0.3)[0] == pytest.approx(0.3)
    # 0.15 m before it the braking cap sqrt(0.12) = 0.3464 is below a 0.4 m/s limit
    assert follower().command((9.85, 0.0, 0.0), max_speed=0.4)[0] == pytest.approx(0.12**0.5)
    assert follower().command((0.0, 0.0, 0.0), max_speed=0.0) == (0.0, 0.0, 0.0)
    # a goal point behind: the turn on the spot is not a forward speed, a 0 limit keeps it
    assert follower().command((5.0, 0.1, math.pi), max_speed=0.0) == (0.0, 0.0, 1.0)
    for bad in (-0.1, math.nan, math.inf):
        with pytest.raises(ValueError, match="max_speed"):
            follower().command((0.0, 0.0, 0.0), max_speed=bad)


class StepLimiter:
    """40 % of 0.5 m/s for the first `switch` seconds, then 0.3 m/s; records what it is given."""

    def __init__(self, switch: float = 5.0) -> None:
        self.switch, self.t, self.calls = switch, 0.0, []

    def update(self, sensor_pose, angles, ranges, max_range, dt, heading=None) -> SpeedLimit:
        self.calls.append((np.array(sensor_pose, float), np.array(ranges), max_range, dt, heading))
        limit = SpeedLimit(40.0, True, 0.5) if self.t < self.switch - 1e-9 else SpeedLimit(0.3)
        self.t += dt
        return limit


@pytest.fixture(scope="module")
def taught(tmp_path_factory, project_root):
    scene_file = project_root / "data" / "worlds" / "factory_corridor.yaml"
    out = tmp_path_factory.mktemp("taught")
    teach(load_scene(scene_file), out, seed=5)
    map_path, marks = load_taught(out, "band", ["P0", "P1", "P2"])
    return scene_file, out, load_map(map_path), marks


def _xy_theta(message) -> tuple[float, float, float]:
    p, q = message["pose"]["position"], message["pose"]["orientation"]
    return p["x"], p["y"], 2.0 * math.atan2(q["z"], q["w"])


def test_playback_keeps_to_the_limits_and_logs_them(taught, tmp_path):
    scene_file, _, environment, marks = taught
    limiter, log = StepLimiter(), tmp_path / "run.mcap"
    config = PlaybackConfig(particles=200, seed=3, max_duration=12.0)
    scene = load_scene(scene_file, "playback")
    result = playback(scene, environment, marks, config, speed_limiter=limiter, log=log)
    n = result.steps
    assert n == 120 and not result.reached  # 12 s at <= 0.3 m/s end short of P2
    np.testing.assert_allclose(result.times, 0.1 * np.arange(n))
    expected = np.where(np.arange(n) < 50, 0.2, 0.3)
    np.testing.assert_allclose(result.speed_limits, expected)
    # the limiter gets the laser pose of the ESTIMATE, its heading, dt and the laser's scan
    assert len(limiter.calls) == n
    est = result.estimates
    laser_of_estimate = est + LASER_X * np.column_stack(
        [np.cos(est[:, 2]), np.sin(est[:, 2]), 0 * est[:, 2]]
    )
    np.testing.assert_allclose([c[0] for c in limiter.calls], laser_of_estimate, atol=1e-9)
    assert [c[4] for c in limiter.calls] == pytest.approx(est[:, 2].tolist(), abs=1e-12)
    assert {c[3] for c in limiter.calls} == {0.1} and {c[2] for c in limiter.calls} == {30.0}
    assert {c[1].size for c in limiter.calls} == {1081}

    run = read_run(log)
    topics = run.topics()
    assert set(topics) == {
        "/ground_truth",
        "/estimate",
        "/odom",
        "/scan",
        "/cmd_vel",
        "/speed_limit",
    }
    assert topics["/speed_limit"] == ("kiseki.SpeedLimit", n) and topics["/cmd_vel"][1] == n
    # the log's poses are the result's
    truth = np.array([_xy_theta(m) for _, m in run.messages("/ground_truth")])
    np.testing.assert_allclose(truth, result.truth, atol=1e-9)
    estimates = np.array([_xy_theta(m) for _, m in run.messages("/estimate")])
    np.testing.assert_allclose(estimates, result.estimates, atol=1e-9)
    assert {m["frame_id"] for _, m in run.messages("/estimate")} == {"map"}
    # /speed_limit: nav2_msgs/SpeedLimit's fields, as the limiter said them, at every step
    limits = run.messages("/speed_limit")
    assert [t for t, _ in limits] == pytest.approx(result.times.tolist())
    first, last = limits[0][1], limits[-1][1]
    assert (first["percentage"], first["speed_limit"], first["max_speed"]) == (True, 40.0, 0.5)
    assert (last["percentage"], last["speed_limit"]) == (False, 0.3)
    assert not any(m["stop"] for _, m in limits)
    applied = [
        m["speed_limit"] * m["max_speed"] / 100 if m["percentage"] else m["speed_limit"]
        for _, m in limits
    ]
    np.testing.assert_allclose(applied, result.speed_limits, atol=1e-12)
    # the true speed (ground-truth chords over dt) never exceeds the limit of the step that
    # commanded the motion, and the robot does reach each limit (it is not trivially slow)
    speed = np.hypot(*np.diff(truth[:, :2], axis=0).T) / 0.1
    assert np.all(speed <= np.array(applied[:-1]) + 1e-9), speed.max()
    assert speed[:50].max() > 0.19 and speed[50:].max() > 0.29
    commands = run.velocities("/cmd_vel")[1][:, 0]
    assert len(commands) == n and np.all(np.array(commands) <= np.array(applied) + 1e-12)
    # /scan: the scan the limiter got, taken at the TRUE laser pose
    scans = run.laser_scans()
    np.testing.assert_allclose(scans.ranges, [c[1] for c in limiter.calls], atol=1e-6)
    laser_of_truth = result.truth[:, :2] + LASER_X * np.column_stack(
        [np.cos(result.truth[:, 2]), np.sin(result.truth[:, 2])]
    )
    np.testing.assert_allclose(scans.poses[:, :2], laser_of_truth, atol=1e-6)


def test_without_a_limiter_nothing_changes_and_the_log_has_no_limit(taught, tmp_path):
    scene_file, _, environment, marks = taught
    config = PlaybackConfig(particles=100, seed=4, max_duration=3.0)
    plain = playback(load_scene(scene_file, "playback"), environment, marks, config)
    logged = playback(
        load_scene(scene_file, "playback"), environment, marks, config, log=tmp_path / "r.mcap"
    )
    assert plain.speed_limits is None and plain.duration == pytest.approx(2.9)
    np.testing.assert_array_equal(plain.truth, logged.truth)
    np.testing.assert_array_equal(plain.estimates, logged.estimates)
    run = read_run(tmp_path / "r.mcap")
    assert set(run.topics()) == {"/ground_truth", "/estimate", "/odom", "/cmd_vel"}
    assert run.metadata["speed_limiter"] == "none"
    with pytest.raises(FileExistsError):  # a log is never overwritten
        playback(
            load_scene(scene_file, "playback"), environment, marks, config, log=tmp_path / "r.mcap"
        )


class StopLimiter:
    def update(self, sensor_pose, angles, ranges, max_range, dt, heading=None) -> SpeedLimit:
        return SpeedLimit(0.0)


def test_a_zero_limit_holds_the_robot_and_says_stop(taught, tmp_path):
    scene_file, _, environment, marks = taught
    config = PlaybackConfig(particles=50, seed=2, max_duration=1.0)
    scene = load_scene(scene_file, "playback")
    result = playback(scene, environment, marks, config, StopLimiter(), tmp_path / "s.mcap")
    np.testing.assert_array_equal(result.truth, np.repeat(result.truth[:1], result.steps, 0))
    limits = [m for _, m in read_run(tmp_path / "s.mcap").messages("/speed_limit")]
    assert len(limits) == 10 and all(m["stop"] and m["speed_limit"] == 0.0 for m in limits)


def test_refusals(taught, tmp_path):
    scene_file, folder, environment, marks = taught
    text = scene_file.read_text().replace("  - {type: laser", "  # - {type: laser")
    blind = tmp_path / "blind.yaml"
    blind.write_text(text)
    config = PlaybackConfig(particles=10)
    with pytest.raises(ValueError, match=r"scene factory_corridor .*blind.yaml.* has no laser"):
        playback(load_scene(blind, "playback"), environment, marks, config, StepLimiter())
    with pytest.raises(TypeError, match="update"):
        playback(load_scene(scene_file, "playback"), environment, marks, config, object())
    cli = [
        sys.executable,
        "-m",
        "kiseki.cli",
        "playback",
        "--route",
        "P0,P2",
        "--taught",
        str(folder),
    ]
    cases = [
        ([str(blind), "--speed-limit", "occlusion", "--variant", "no-laser"], "has no laser"),
        ([str(scene_file), "--speed-limit", "fast"], "--speed-limit must be none, occlusion"),
        ([str(scene_file), "--log", str(scene_file)], "would overwrite the input SCENE"),
        ([str(scene_file), "--log", str(folder / "map_band.pgm")], "would overwrite the input"),
        ([str(scene_file), "--log", str(folder / "teach.mcap")], "exists"),
    ]
    for args, message in cases:
        done = subprocess.run([*cli, *args], capture_output=True, text=True)
        assert done.returncode == 1 and message in done.stderr, (args, done.stderr)
        assert len(done.stderr.strip().splitlines()) == 1


def test_cli_plays_back_under_the_occlusion_limit(taught, tmp_path):
    scene_file, folder, _, _ = taught
    log = tmp_path / "run.mcap"
    cli = [sys.executable, "-m", "kiseki.cli", "playback", str(scene_file), "--route", "P0,P1"]
    cli += ["--taught", str(folder), "--speed-limit", "occlusion", "--log", str(log)]
    done = subprocess.run(cli, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert "speed limit (occlusion)" in done.stdout and "goal reached: True" in done.stdout
    run = read_run(log)
    assert run.metadata["speed_limiter"] == "SpeedLimiter"
    _, truth = run.poses("/ground_truth")
    limits = [m for _, m in run.messages("/speed_limit")]
    assert len(limits) == len(truth) and not any(m["percentage"] for m in limits)
    speed = np.hypot(*np.diff(truth[:, :2], axis=0).T) / 0.1
    assert np.all(speed <= np.array([m["speed_limit"] for m in limits[:-1]]) + 1e-9)
