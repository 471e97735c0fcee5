# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The speed-controlled navigator without the simulator: an ideal omnidirectional robot moved
by its own commands, fake scans, and speeds checked against the hand formula
v = min(v_fpm, limit, sqrt(2 * 0.8 * a_max * d_goal))."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.control import FuzzyPotentialMethod, SpeedLimit
from kiseki.speed.navigator import SpeedControlledNavigator, scan_about_body

MAX_RANGE = 4.0
ANGLES = np.linspace(-math.radians(120), math.radians(120), 683)
OFFSET = 0.2  # laser ahead of the centre, as in the speed worlds


def open_field(pose):
    x, y, th = pose
    sensor = np.array([x + OFFSET * math.cos(th), y + OFFSET * math.sin(th), th])
    return {"scan": (sensor, ANGLES, np.full(ANGLES.shape, MAX_RANGE), MAX_RANGE)}


def drive(nav, pose, steps=400, dt=0.1):
    """Integrates the body-frame command exactly; returns the poses the navigator saw."""
    seen = []
    for k in range(steps):
        vx, vy, w = nav.command(k * dt, pose, open_field(pose))
        assert w == 0.0
        seen.append(pose)
        if nav.done:
            break
        x, y, th = pose
        pose = (x + dt * (vx * math.cos(th) - vy * math.sin(th)),
                y + dt * (vx * math.sin(th) + vy * math.cos(th)), th)  # fmt: skip
    return np.array(seen)


class FixedLimit:
    """A limiter that always says 0.2 m/s and remembers what it was asked."""

    def __init__(self):
        self.calls = []

    def update(self, sensor_pose, angles, ranges, max_range, dt, heading=None):
        self.calls.append((dt, heading))
        return SpeedLimit(0.2)


def test_open_field_drives_straight_at_the_goal_and_stops_within_tolerance():
    nav = SpeedControlledNavigator((0.0, 4.0), FuzzyPotentialMethod(), None)
    poses = drive(nav, (0.0, 0.0, math.pi / 2))  # facing +y, as the paper's robot
    assert nav.done
    assert np.abs(poses[:, 0]).max() < 1e-9  # straight along x = 0
    assert math.hypot(*(poses[-1, :2] - (0.0, 4.0))) <= 0.1
    assert math.hypot(*(poses[-2, :2] - (0.0, 4.0))) > 0.1  # it stopped as soon as it arrived
    log = nav.log.as_arrays()
    d = np.hypot(poses[:-1, 0], poses[:-1, 1] - 4.0)
    assert log["speed"][:-1] == pytest.approx(np.minimum(0.5, np.sqrt(0.8 * d)))
    assert log["vy"][:-1] == pytest.approx(np.zeros(len(d)), abs=1e-12)  # all forward
    assert log["speed"][-1] == 0.0 and np.isnan(log["limit"][-1])
    assert nav.command(99.0, poses[-1], open_field(poses[-1])) == (0.0, 0.0, 0.0)  # stays done


def test_a_goal_to_the_right_is_reached_sideways_without_turning():
    nav = SpeedControlledNavigator((3.0, 0.0), FuzzyPotentialMethod(), None)
    vx, vy, w = nav.command(0.0, (0.0, 0.0, math.pi / 2), open_field((0.0, 0.0, math.pi / 2)))
    assert (vx, vy, w) == pytest.approx((0.0, -0.5, 0.0), abs=1e-12)


def test_a_fixed_limit_caps_every_command():
    limiter = FixedLimit()
    nav = SpeedControlledNavigator((2.0, 2.0), FuzzyPotentialMethod(), limiter)
    poses = drive(nav, (0.0, 0.0, 0.0))
    assert nav.done
    log = nav.log.as_arrays()
    assert log["speed"].max() <= 0.2 + 1e-12
    assert np.hypot(log["vx"], log["vy"]) == pytest.approx(log["speed"])
    d = np.hypot(*(poses[:-1, :2] - (2.0, 2.0)).T)
    assert log["speed"][:-1] == pytest.approx(np.minimum(0.2, np.sqrt(0.8 * d)))
    # the limiter is asked along the map-frame heading (45 deg here) every 0.1 s
    assert [dt for dt, _ in limiter.calls] == pytest.approx([0.1] * len(limiter.calls))
    assert [h for _, h in limiter.calls] == pytest.approx([math.pi / 4] * len(limiter.calls))


def test_scan_about_body_by_hand():
    # robot at (1, 2) facing +y, laser 0.2 m ahead; beam 0 at 0.3 m -> 0.5 m ahead of the
    # centre; beam +90 deg at 0.2 m -> map (0.8, 2.2) -> body (0.2, 0.2)
    pose, sensor = (1.0, 2.0, math.pi / 2), (1.0, 2.2, math.pi / 2)
    a, r = scan_about_body(pose, sensor, [0.0, math.pi / 2, 0.1], [0.3, 0.2, MAX_RANGE], MAX_RANGE)
    assert a[:2] == pytest.approx([0.0, math.pi / 4])
    assert r[:2] == pytest.approx([0.5, math.hypot(0.2, 0.2)])
    assert r[2] == math.inf


@pytest.mark.parametrize("name", ["pose", "sensor_pose"])
@pytest.mark.parametrize("bad", [(math.nan, 0.0, 0.0), (0.0, 0.0, math.inf), (0.0, 0.0), "abc"])
def test_scan_about_body_refuses_a_pose_that_is_not_three_finite_numbers(name, bad):
    """A NaN pose gave every beam a NaN angle and range; two numbers a numpy reshape error."""
    poses = {"pose": (0.0, 0.0, 0.0), "sensor_pose": (0.2, 0.0, 0.0), name: bad}
    with pytest.raises(ValueError) as caught:
        scan_about_body(poses["pose"], poses["sensor_pose"], [0.0, 0.1], [1.0, 2.0], 10.0)
    assert str(caught.value) == f"{name} must be three finite numbers (x, y, theta), got {bad!r}"


@pytest.mark.parametrize(
    ("name", "bad", "unit"),
    [("v_max", True, "m/s"), ("goal_tolerance", 0.0, "m"), ("a_max", -0.5, "m/s^2"),
     ("period", math.nan, "s")],
)  # fmt: skip
def test_the_navigator_refuses_a_bad_setting(name, bad, unit):
    """True was a top speed of 1 m/s."""
    with pytest.raises(ValueError) as caught:
        SpeedControlledNavigator((1.0, 0.0), FuzzyPotentialMethod(), None, **{name: bad})
    assert str(caught.value) == f"{name} must be a finite number > 0 {unit}, got {bad!r}"
