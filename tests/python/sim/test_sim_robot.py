# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulated robots' true motion against closed forms and fine references (their parameters:
test_sim_robot_params.py; their odometry: test_sim_odometry.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _helpers.sim_robot import FAST, NONE, angle_diff, pose_array
from kiseki.core import Random
from kiseki.sim.motion import WheelMotion
from kiseki.sim.odometry import WheelOdometry
from kiseki.sim.robot import DiffDriveRobot, OmniRobot
from kiseki.sim.robot_params import (
    DiffDriveParams,
    OmniParams,
)

# ---------------------------------------------------------------------- differential drive


def euler(pose, v: float, w: float, duration: float, n: int) -> np.ndarray:
    x, y, th = pose
    h = duration / n
    for _ in range(n):
        x += v * math.cos(th) * h
        y += v * math.sin(th) * h
        th += w * h
    return np.array([x, y, th])


def test_arc_step_matches_fine_euler_reference():
    start = (0.3, -1.2, 2.5)
    v, w, duration = 0.8, 0.9, 2.0
    robot = DiffDriveRobot(DiffDriveParams(), start, velocity=(v, w))
    robot.step(v, w, duration)  # one long step
    got = pose_array(robot.pose)
    fine = euler(start, v, w, duration, 200_000)  # O(h) error ~ v w h T / 2 ~ 1e-5
    np.testing.assert_allclose(got[:2], fine[:2], atol=1e-4)
    assert abs(angle_diff(got[2], fine[2])) < 1e-9
    coarse = euler(start, v, w, duration, 1)  # the test can tell Euler from the arc
    assert np.linalg.norm(coarse[:2] - got[:2]) > 0.1


def test_full_circle_returns_to_start_on_the_closed_form_circle():
    v, w = 0.5, 0.5  # radius v / w = 1 m
    x0, y0, th0 = 1.0, 2.0, 0.3
    cx, cy = x0 - (v / w) * math.sin(th0), y0 + (v / w) * math.cos(th0)
    robot = DiffDriveRobot(DiffDriveParams(), (x0, y0, th0), velocity=(v, w))
    n = 37
    for k in range(1, n + 1):
        robot.step(v, w, (2 * math.pi / w) / n)
        p = robot.pose
        assert math.hypot(p.x - cx, p.y - cy) == pytest.approx(v / w, abs=1e-12)
        assert angle_diff(p.theta, th0 + 2 * math.pi * k / n) == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(pose_array(robot.pose), [x0, y0, th0], atol=1e-12)


def test_wheel_travel_is_the_true_ground_travel():
    robot = DiffDriveRobot(FAST)
    m = robot.step(0.6, -0.8, 0.1)
    b = FAST.track_width
    assert m.left == pytest.approx((0.6 + 0.8 * b / 2) * 0.1, abs=1e-15)
    assert m.right == pytest.approx((0.6 - 0.8 * b / 2) * 0.1, abs=1e-15)
    assert m.dt == 0.1
    assert (m.right - m.left) / b == pytest.approx(robot.pose.theta, abs=1e-15)


def test_acceleration_then_velocity_limits_hold_every_step():
    p = DiffDriveParams()
    robot = DiffDriveRobot(p)
    rng = Random(5)
    hit_accel = hit_speed = 0
    for k in range(3000):
        dt = float(rng.uniform(0.005, 0.2, 1)[0])
        if k % 40 == 0:  # hold each command for a while so that the speed limits are reached
            v_cmd, w_cmd = rng.uniform(-3.0, 3.0, 2)
        v0, w0 = robot.velocity
        robot.step(v_cmd, w_cmd, dt)
        v1, w1 = robot.velocity
        assert abs(v1 - v0) <= p.max_accel * dt * (1 + 1e-12)
        assert abs(w1 - w0) <= p.max_yaw_accel * dt * (1 + 1e-12)
        assert abs(v1) <= p.max_speed and abs(w1) <= p.max_yaw_rate
        hit_accel += abs(v1 - v0) > p.max_accel * dt * (1 - 1e-9)
        hit_speed += abs(v1) == p.max_speed
    assert hit_accel > 100 and hit_speed > 100  # both limits were exercised


def test_ramp_from_rest_takes_vmax_over_amax():
    p = DiffDriveParams()
    robot = DiffDriveRobot(p)
    speeds = []
    for _ in range(30):
        robot.step(5.0, 0.0, 0.1)
        speeds.append(robot.velocity[0])
    expected = [min((k + 1) * p.max_accel * 0.1, p.max_speed) for k in range(30)]
    np.testing.assert_allclose(speeds, expected, atol=1e-12)
    # distance while ramping: sum of (k a dt) dt for 20 steps, then v_max for 10 steps
    assert robot.pose.x == pytest.approx(sum(expected) * 0.1, abs=1e-12)


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        ((float("nan"), 0.0, 0.1), "v_cmd must be a finite number"),
        ((0.0, float("inf"), 0.1), "w_cmd must be a finite number"),
        ((0.1, 0.0, 0.0), "dt must be a finite number > 0 s, got 0.0"),
        ((0.1, 0.0, -0.1), "dt must be a finite number > 0 s, got -0.1"),
        ((0.1, 0.0, float("nan")), "dt must be a finite number"),
    ],
)
def test_diff_drive_rejects_bad_commands(args, needle):
    robot = DiffDriveRobot()
    with pytest.raises(ValueError, match=needle):
        robot.step(*args)
    assert robot.velocity == (0.0, 0.0)  # state untouched


def test_bad_poses_and_velocities_are_rejected():
    with pytest.raises(ValueError, match="pose.y must be a finite number"):
        DiffDriveRobot(DiffDriveParams(), (0.0, float("nan"), 0.0))
    with pytest.raises(ValueError, match="pose must be a Pose2"):
        OmniRobot(OmniParams(), (0.0, 1.0))
    with pytest.raises(ValueError, match="exceeds max_speed"):
        DiffDriveRobot(DiffDriveParams(), velocity=(2.0, 0.0))
    with pytest.raises(ValueError, match="exceeds max_speed"):
        OmniRobot(OmniParams(), velocity=(0.4, 0.4, 0.0))
    with pytest.raises(ValueError, match="WheelMotion.left"):
        WheelMotion(float("nan"), 0.0, 0.1)
    with pytest.raises(ValueError, match="WheelMotion.dt must be a finite number > 0 s, got -1.0"):
        WheelMotion(0.0, 0.0, -1.0)
    with pytest.raises(ValueError, match="seed must be an integer"):
        WheelOdometry(DiffDriveParams(), NONE, seed=-1)
    with pytest.raises(ValueError, match="needs a WheelMotion"):
        WheelOdometry().update((0.1, 0.1, 0.1))  # type: ignore[arg-type]


# ------------------------------------------------------------------------------------- omni


def test_omni_body_velocity_is_rotated_into_the_world():
    for theta in (0.0, 0.7, -2.0, 3.0):
        robot = OmniRobot(OmniParams(), (1.0, -1.0, theta), velocity=(0.3, -0.2, 0.0))
        m = robot.step(0.3, -0.2, 0.0, 1.5)
        world = np.array([robot.pose.x - 1.0, robot.pose.y + 1.0])
        c, s = math.cos(theta), math.sin(theta)
        np.testing.assert_allclose(world, 1.5 * np.array([c * 0.3 + s * 0.2, s * 0.3 - c * 0.2]))
        np.testing.assert_allclose([m.dx, m.dy], [0.45, -0.3], atol=1e-15)
        assert m.distance == pytest.approx(1.5 * math.hypot(0.3, 0.2))


def test_omni_rotating_step_matches_fine_euler_and_closes_a_circle():
    vx, vy, w, duration = 0.2, 0.35, 0.8, 2.0
    start = (0.5, 0.25, -1.0)
    robot = OmniRobot(OmniParams(), start, velocity=(vx, vy, w))
    m = robot.step(vx, vy, w, duration)
    x, y, th = start
    n = 200_000
    h = duration / n
    for _ in range(n):
        c, s = math.cos(th), math.sin(th)
        x, y, th = x + (c * vx - s * vy) * h, y + (s * vx + c * vy) * h, th + w * h
    np.testing.assert_allclose([robot.pose.x, robot.pose.y], [x, y], atol=1e-4)
    # the BodyMotion is the same displacement expressed in the starting body frame
    c, s = math.cos(start[2]), math.sin(start[2])
    dxw, dyw = robot.pose.x - start[0], robot.pose.y - start[1]
    np.testing.assert_allclose([m.dx, m.dy], [c * dxw + s * dyw, -s * dxw + c * dyw], atol=1e-14)
    # constant body velocity and yaw rate trace a circle of radius |v| / w: back after 2 pi / w
    robot = OmniRobot(OmniParams(), start, velocity=(vx, vy, w))
    for _ in range(10):
        robot.step(vx, vy, w, 2 * math.pi / w / 10)
    np.testing.assert_allclose(pose_array(robot.pose), start, atol=1e-12)


def test_omni_limits_act_on_the_velocity_vector():
    p = OmniParams()
    robot = OmniRobot(p)
    for _ in range(15):  # command along 30 deg from rest: direction kept while ramping
        v0 = np.array(robot.velocity[:2])
        robot.step(2.0 * math.cos(0.5236), 2.0 * math.sin(0.5236), 0.0, 0.1)
        v1 = np.array(robot.velocity[:2])
        assert np.linalg.norm(v1 - v0) <= p.max_accel * 0.1 * (1 + 1e-12)
        assert math.atan2(v1[1], v1[0]) == pytest.approx(0.5236, abs=1e-12)
    assert math.hypot(*robot.velocity[:2]) == pytest.approx(p.max_speed, abs=1e-12)
    rng = Random(9)
    for _ in range(2000):
        dt = float(rng.uniform(0.01, 0.3, 1)[0])
        cmd = rng.uniform(-2.0, 2.0, 3)
        before = np.array(robot.velocity)
        robot.step(*cmd, dt)
        after = np.array(robot.velocity)
        assert np.linalg.norm(after[:2] - before[:2]) <= p.max_accel * dt * (1 + 1e-12)
        assert np.linalg.norm(after[:2]) <= p.max_speed * (1 + 1e-12)
        assert abs(after[2] - before[2]) <= p.max_yaw_accel * dt * (1 + 1e-12)
        assert abs(after[2]) <= p.max_yaw_rate


def test_omni_limit_order_is_acceleration_then_speed():
    """At full speed along x, commanded (0, 2): the change is clipped towards the raw command
    first, then the speed; clipping the command to v_max first would give a different turn."""
    robot = OmniRobot(OmniParams(), velocity=(0.5, 0.0, 0.0))
    robot.step(0.0, 2.0, 0.0, 0.1)
    change = np.array([-0.5, 2.0]) / math.hypot(0.5, 2.0) * 0.05
    expected = np.array([0.5, 0.0]) + change  # norm 0.490 < 0.5: no speed clipping
    np.testing.assert_allclose(robot.velocity[:2], expected, atol=1e-15)


def test_omni_rejects_bad_commands():
    robot = OmniRobot()
    with pytest.raises(ValueError, match="vy_cmd must be a finite number"):
        robot.step(0.0, float("nan"), 0.0, 0.1)
    with pytest.raises(ValueError, match="dt must be a finite number > 0 s, got -0.05"):
        robot.step(0.0, 0.0, 0.0, -0.05)
