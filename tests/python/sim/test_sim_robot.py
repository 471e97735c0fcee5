# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulated robots and odometry against closed forms, fine references and sampling statistics.

Statistical checks use tolerances derived from the sample size: for n normal samples the
sample standard deviation has relative standard error 1/sqrt(2(n-1)), and the sample mean has
standard error sd/sqrt(n); the tests allow 4 standard errors (false alarm rate < 1e-4), and
the runs are seeded, so they are reproducible anyway.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from kiseki.core import Pose2, Random, derive_seed
from kiseki.sim.motion import BodyMotion, WheelMotion
from kiseki.sim.odometry import OmniOdometry, WheelOdometry
from kiseki.sim.robot import DiffDriveRobot, OmniRobot
from kiseki.sim.robot_params import (
    DiffDriveParams,
    OdometryErrorParams,
    OmniOdometryErrorParams,
    OmniParams,
)

NONE = OdometryErrorParams.none()
FAST = DiffDriveParams(max_accel=1e6, max_yaw_accel=1e6)  # limits out of the way


def pose_array(p: Pose2) -> np.ndarray:
    return np.array([p.x, p.y, p.theta])


def angle_diff(a: float, b: float) -> float:
    return math.remainder(a - b, 2 * math.pi)


def relative_sd_tolerance(n: int, k: float = 4.0) -> float:
    """k standard errors of a sample SD, relative: k / sqrt(2 (n - 1))."""
    return k / math.sqrt(2 * (n - 1))


# ------------------------------------------------------------------------------- parameters


def test_defaults_carry_the_papers_numbers():
    p = DiffDriveParams()
    assert (p.length, p.width, p.height) == (1.05, 0.58, 0.99)
    assert (p.encoder_counts_per_rev, p.gear_ratio) == (500, 70.0)
    assert p.track_width < p.width  # wheels inside the body
    o = OmniParams()
    assert (o.width, o.max_speed, o.max_accel) == (0.70, 0.5, 0.5)


def test_counts_per_wheel_revolution():
    assert DiffDriveParams().counts_per_wheel_rev == 500 * 70 * 4
    x1 = DiffDriveParams(quadrature=False)
    assert x1.counts_per_wheel_rev == 500 * 70
    # Behaviour, not just the property: 10.5 wheel revolutions (plus a quarter count, clear of
    # the edge) give exactly 10.5 x 35000 counts, in one step or in 1000 small ones.
    travel = 2 * math.pi * x1.wheel_radius * 10.5 + 0.25 * x1.distance_per_count
    one = WheelOdometry(x1, NONE, seed=1)
    one.update(WheelMotion(travel, travel, 1.0))
    assert one.counts == (367500, 367500)
    many = WheelOdometry(x1, NONE, seed=1)
    for _ in range(1000):
        many.update(WheelMotion(travel / 1000, -travel / 1000, 0.01))
    assert many.counts[0] == 367500
    assert many.counts[1] == -367501  # floor: backwards travel reaches the next lower count


def test_from_dict_round_trip_and_defaults():
    p = DiffDriveParams.from_dict({"wheel_radius": 0.1, "encoder_counts_per_rev": 1024}, "a")
    assert p.wheel_radius == 0.1 and p.encoder_counts_per_rev == 1024
    assert isinstance(p.encoder_counts_per_rev, int) and p.track_width == 0.50
    assert isinstance(DiffDriveParams.from_dict({"max_speed": 2}).max_speed, float)  # int -> float
    for cls in (DiffDriveParams, OmniParams, OdometryErrorParams, OmniOdometryErrorParams):
        q = cls()
        assert cls.from_dict(q.to_dict(), "round trip") == q
        new = {"Flag": False, "PositiveInt": 7}  # every other field takes 0.5
        changed = {f.name: new.get(str(f.type), 0.5) for f in dataclasses.fields(cls)}
        assert cls.from_dict(changed).to_dict() == {**q.to_dict(), **changed}


@pytest.mark.parametrize(
    ("cls", "key", "value", "needle"),
    [
        (DiffDriveParams, "wheel_radiuss", 0.1, "wheel_radiuss: unknown key"),
        (DiffDriveParams, "wheel_radius", 0.0, "wheel_radius: must be greater than 0, got 0.0"),
        (DiffDriveParams, "track_width", -0.5, "track_width: must be greater than 0, got -0.5"),
        (DiffDriveParams, "max_speed", float("nan"), "max_speed: must be a finite number, got nan"),
        (DiffDriveParams, "max_accel", float("inf"), "max_accel: must be a finite number, got inf"),
        (DiffDriveParams, "length", "1.05", "length: must be a valid number, got '1.05'"),
        (DiffDriveParams, "height", True, "height: must be a valid number, got True"),
        (DiffDriveParams, "encoder_counts_per_rev", 500.5, "encoder_counts_per_rev: must be a"),
        (DiffDriveParams, "encoder_counts_per_rev", 500.0, "encoder_counts_per_rev: must be a"),
        (DiffDriveParams, "encoder_counts_per_rev", 0, "encoder_counts_per_rev: must be greater"),
        (DiffDriveParams, "quadrature", 1, "quadrature: must be a valid boolean, got 1"),
        (OmniParams, "max_yaw_rate", 0, "max_yaw_rate: must be greater than 0, got 0"),
        (OmniParams, "v_max", 0.5, "v_max: unknown key"),
        (
            OdometryErrorParams,
            "left_radius_error",
            -1.0,
            "left_radius_error: must be greater than -1",
        ),
        (OdometryErrorParams, "track_width_error", 1.0, "track_width_error: must be less than 1"),
        (OdometryErrorParams, "slip_distance_coeff", -1e-6, "slip_distance_coeff: must be greater"),
        (
            OdometryErrorParams,
            "initial_heading_offset",
            float("nan"),
            "initial_heading_offset: must",
        ),
        (OmniOdometryErrorParams, "translation_coeff", -1.0, "translation_coeff: must be greater"),
    ],
)
def test_from_dict_rejects_bad_input_naming_source_and_key(cls, key, value, needle):
    with pytest.raises(ValueError) as info:
        cls.from_dict({key: value}, "robots/agv.yaml")
    message = str(info.value)
    assert message.startswith("robots/agv.yaml: ") and needle in message
    # a section inside a bigger file: the whole path
    with pytest.raises(ValueError, match=rf"^scene\.yaml: robots\[1\]\.params\.{key}: "):
        cls.from_dict({key: value}, "scene.yaml", at=("robots", 1, "params"))


# the range of every parameter, written out here (not read from the classes)
SIZES = ["length", "width", "max_speed", "max_accel", "max_yaw_rate", "max_yaw_accel"]
KINDS = {
    DiffDriveParams: {
        **dict.fromkeys([*SIZES, "height", "wheel_radius", "track_width", "gear_ratio"], "size"),
        "encoder_counts_per_rev": "count",
        "quadrature": "flag",
    },
    OmniParams: dict.fromkeys(SIZES, "size"),
    OdometryErrorParams: {
        **dict.fromkeys(["left_radius_error", "right_radius_error", "track_width_error"], "rel"),
        "initial_heading_offset": "finite",
        **dict.fromkeys(["initial_heading_sd", "slip_distance_coeff", "slip_rotation_coeff"], "sd"),
    },
    OmniOdometryErrorParams: dict.fromkeys(
        ["translation_coeff", "heading_distance_coeff", "heading_rotation_coeff"], "sd"
    ),
}
EDGES = {  # a value just outside the range, one just inside
    "size": [(0.0, 1e-9)],
    "count": [(0, 1), (2.0, 2)],
    "sd": [(-1e-12, 0.0)],
    "rel": [(-1.0, -0.999), (1.0, 0.999)],
    # finite and within kiseki._support.schema.MAGNITUDE_LIMIT (1e9)
    "finite": [(float("-inf"), -1e9), (-2e9, 0.0), (float("nan"), 0.0)],
    "flag": [(0, False), ("yes", True)],
}


@pytest.mark.parametrize("cls", list(KINDS))
def test_every_field_has_its_range(cls):
    assert {f.name for f in dataclasses.fields(cls)} == set(KINDS[cls])
    for name, kind in KINDS[cls].items():
        for bad, good in EDGES[kind]:
            assert getattr(cls.from_dict({name: good}), name) == good
            # an integral float given for an integer is told how to write it
            hint = r"( \(write it as -?\d+, without a point or an exponent\))?"
            with pytest.raises(ValueError, match=rf"^s\.yaml: {name}: .*, got {bad!r}{hint}$"):
                cls.from_dict({name: bad}, "s.yaml")


def test_direct_construction_is_validated_too():
    with pytest.raises(ValueError, match=r"DiffDriveParams\nwheel_radius\n.*finite number"):
        DiffDriveParams(wheel_radius=float("nan"))
    with pytest.raises(ValueError, match=r"OdometryErrorParams\nslip_rotation_coeff"):
        dataclasses.replace(OdometryErrorParams(), slip_rotation_coeff=-1.0)
    with pytest.raises(ValueError, match="^x.yaml: must be a mapping"):
        OmniParams.from_dict([("width", 1.0)], "x.yaml")  # type: ignore[arg-type]


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
        ((0.1, 0.0, 0.0), "dt must be > 0"),
        ((0.1, 0.0, -0.1), "dt must be > 0"),
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
    with pytest.raises(ValueError, match="WheelMotion.dt must be > 0"):
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
    with pytest.raises(ValueError, match="dt must be > 0"):
        robot.step(0.0, 0.0, 0.0, -0.05)


# ------------------------------------------------------------------------- wheel odometry


def drive(odometry: WheelOdometry, length: float, step: float = 0.05) -> Pose2:
    """Straight ahead for ``length`` metres, in steps of ``step`` (both wheels equal)."""
    pose = odometry.pose
    for _ in range(round(length / step)):
        pose = odometry.update(WheelMotion(step, step, step))
    return pose


def test_zero_error_odometry_equals_truth_up_to_quantisation():
    p = DiffDriveParams()
    q = p.distance_per_count
    start = (2.0, -1.0, 0.4)
    robot = DiffDriveRobot(p, start)
    odometry = WheelOdometry(p, NONE, seed=3, initial_pose=start)
    rng = Random(11)
    true_total = np.zeros(2)
    travelled = turned = 0.0
    worst_step = worst_total = worst_pose = 0.0
    for k in range(6000):  # 300 s of random driving
        if k % 50 == 0:
            v_cmd, w_cmd = rng.uniform(-1.0, 1.0, 2)
        counts_before = np.array(odometry.counts)
        m = robot.step(v_cmd, w_cmd, 0.05)
        odometry.update(m)
        step_travel = np.array([m.left, m.right])
        measured = (np.array(odometry.counts) - counts_before) * q
        worst_step = max(worst_step, np.max(np.abs(measured - step_travel)))
        true_total += step_travel
        worst_total = max(worst_total, np.max(np.abs(np.array(odometry.counts) * q - true_total)))
        travelled += abs(m.left + m.right) / 2
        turned += abs(m.right - m.left) / p.track_width
        error = math.hypot(odometry.pose.x - robot.pose.x, odometry.pose.y - robot.pose.y)
        worst_pose = max(worst_pose, error)
        assert abs(angle_diff(odometry.pose.theta, robot.pose.theta)) < q / p.track_width
    assert travelled > 50 and turned > 20  # a long run with real turning
    assert worst_step < q  # below one count per step...
    assert worst_total < q  # ...and no accumulation: the remainder is carried
    # Position: the summed per-step distance error telescopes to < q per wheel plus q per
    # radian of direction change; the heading error (< q / b) acts over the whole distance.
    assert worst_pose < q * (2 + 2 * turned + 2 * travelled / p.track_width)


def test_wheel_radius_difference_gives_the_closed_form_heading_drift():
    p = DiffDriveParams()
    e_left, e_right = 0.003, -0.002  # +0.3 % / -0.2 %
    errors = dataclasses.replace(NONE, left_radius_error=e_left, right_radius_error=e_right)
    pose = drive(WheelOdometry(p, errors, seed=1), 10.0)
    d_left, d_right = 10.0 / (1 + e_left), 10.0 / (1 + e_right)  # distances the odometry sees
    theta = (d_right - d_left) / p.track_width
    q = p.distance_per_count  # each wheel's total is within one count: heading within q / b
    assert pose.theta == pytest.approx(theta, abs=q / p.track_width)
    first_order = (e_left - e_right) * 10.0 / p.track_width  # = 0.1 rad
    assert pose.theta == pytest.approx(first_order, rel=2e-3)
    # constant curvature: the odometry traces an arc of length (dL + dR) / 2 turning by theta
    chord = (d_left + d_right) / 2 * math.sin(theta / 2) / (theta / 2)
    position_tol = q * (2 + 2 * 10.0 / p.track_width)  # as in the zero-error test
    assert pose.x == pytest.approx(chord * math.cos(theta / 2), abs=position_tol)
    assert pose.y == pytest.approx(chord * math.sin(theta / 2), abs=position_tol)


def test_initial_heading_offset_rotates_the_whole_odometry_path():
    errors = dataclasses.replace(NONE, initial_heading_offset=math.radians(0.2))
    pose = drive(WheelOdometry(DiffDriveParams(), errors, seed=1), 13.0)
    assert pose.theta == pytest.approx(math.radians(0.2), abs=1e-9)
    assert pose.y == pytest.approx(13.0 * math.sin(math.radians(0.2)), abs=1e-5)


def square(errors: OdometryErrorParams, clockwise: bool, side: float = 4.0) -> np.ndarray:
    """UMBmark: drive a square of ``side`` metres (turns on the spot); odometry end - start."""
    p = DiffDriveParams()
    odometry = WheelOdometry(p, errors, seed=1)
    b, sign, step = p.track_width, -1.0 if clockwise else 1.0, 0.05
    for _ in range(4):
        drive(odometry, side, step)
        for _ in range(30):  # the turn: pi/2 in 30 steps
            arc = sign * (math.pi / 2 / 30) * b / 2
            odometry.update(WheelMotion(-arc, arc, 0.05))
    return pose_array(odometry.pose)


def test_umbmark_square_shows_the_expected_end_point_errors():
    side = 4.0
    # Type A (track too wide): every 90 deg turn is over-counted by delta = e_b pi / 2.
    e_b = 0.01
    delta = e_b * math.pi / 2
    a_ccw = square(dataclasses.replace(NONE, track_width_error=e_b), clockwise=False)
    a_cw = square(dataclasses.replace(NONE, track_width_error=e_b), clockwise=True)
    # First order: CCW (2 L delta, -2 L delta), CW (2 L delta, 2 L delta); second-order terms
    # are O(delta) relative, i.e. a few percent here.
    np.testing.assert_allclose(a_ccw[:2], 2 * side * delta * np.array([1, -1]), rtol=0.05)
    np.testing.assert_allclose(a_cw[:2], 2 * side * delta * np.array([1, 1]), rtol=0.05)
    q = DiffDriveParams().distance_per_count  # quantisation: heading within q / b
    assert angle_diff(a_ccw[2], 4 * delta) == pytest.approx(0, abs=q / 0.5)
    assert angle_diff(a_cw[2], -4 * delta) == pytest.approx(0, abs=q / 0.5)
    # Type B (unequal wheels): each leg curves by alpha, in both directions the same way.
    e = 0.001
    b_errors = dataclasses.replace(NONE, left_radius_error=e, right_radius_error=-e)
    alpha = side * (1 / (1 - e) - 1 / (1 + e)) / DiffDriveParams().track_width
    b_ccw = square(b_errors, clockwise=False)
    b_cw = square(b_errors, clockwise=True)
    np.testing.assert_allclose(b_ccw[:2], 2 * side * alpha * np.array([1, -1]), rtol=0.05)
    np.testing.assert_allclose(b_cw[:2], 2 * side * alpha * np.array([-1, -1]), rtol=0.05)
    # Both with delta = alpha: they add up CCW and cancel CW -- why UMBmark needs both runs.
    # (Smaller errors here: the summed heading error doubles the second-order terms.)
    e = 0.0003
    alpha = side * (1 / (1 - e) - 1 / (1 + e)) / DiffDriveParams().track_width
    both = dataclasses.replace(NONE, left_radius_error=e, right_radius_error=-e)
    both = dataclasses.replace(both, track_width_error=2 * alpha / math.pi)
    ccw, cw = square(both, clockwise=False), square(both, clockwise=True)
    np.testing.assert_allclose(ccw[:2], 4 * side * alpha * np.array([1, -1]), rtol=0.05)
    assert np.linalg.norm(cw[:2]) < 0.05 * np.linalg.norm(ccw[:2])


def test_random_slip_error_grows_with_the_square_root_of_distance():
    """Slip alone, straight runs of 5 m and 20 m, 200 seeds each.

    Per wheel the slip variance is k_d s, so the travelled distance (mean of the wheels) and
    the heading ((dR - dL) / b) have SDs growing like sqrt(s): x2 for 4x the distance. The
    lateral error integrates the heading random walk, variance (2 k_d / b^2) s^3 / 3, so it
    grows like s^1.5 (x8), and the heading wander shortens x by E[integral theta^2 / 2] =
    q s^2 / 4 with q = 2 k_d / b^2 (second order, visible at 20 m).
    """
    p = DiffDriveParams()
    q = p.distance_per_count
    k_d = OdometryErrorParams().slip_distance_coeff
    errors = dataclasses.replace(NONE, slip_distance_coeff=k_d)
    n = 200
    tol = relative_sd_tolerance(n)  # 4 standard errors: 0.28 for n = 200
    sd: dict[float, np.ndarray] = {}
    for length, stream in ((5.0, 0), (20.0, 1)):  # independent streams for the two distances
        rows = []
        for i in range(n):
            odometry = WheelOdometry(p, errors, derive_seed(derive_seed(42, stream), i))
            pose = drive(odometry, length, 0.1)
            path = (odometry.counts[0] + odometry.counts[1]) / 2 * q
            rows.append([path - length, pose.theta, pose.y, pose.x - length])
        f = np.array(rows)
        path_sd = math.sqrt(k_d * length / 2)
        heading_sd = math.sqrt(2 * k_d * length) / p.track_width
        lateral_sd = math.sqrt(2 * k_d / p.track_width**2 * length**3 / 3)
        sample_sd = np.std(f, axis=0, ddof=1)
        np.testing.assert_allclose(sample_sd[:3], [path_sd, heading_sd, lateral_sd], rtol=tol)
        means = np.mean(f, axis=0)
        assert np.all(np.abs(means[:3]) < 4 * sample_sd[:3] / math.sqrt(n))  # zero mean
        shortening = -(2 * k_d / p.track_width**2) * length**2 / 4
        assert abs(means[3] - shortening) < 4 * sample_sd[3] / math.sqrt(n)
        sd[length] = sample_sd
    ratio = sd[20.0] / sd[5.0]
    ratio_tol = math.sqrt(2) * tol  # log-ratio of two independent sample SDs
    np.testing.assert_allclose(ratio[:3], [2.0, 2.0, 8.0], rtol=ratio_tol)


def test_slip_noise_does_not_depend_on_the_step_size():
    """The same 5 m in 500 steps of 1 cm or in 25 steps of 20 cm: the same heading spread."""
    p = DiffDriveParams()
    errors = dataclasses.replace(NONE, slip_distance_coeff=4e-6)
    n = 200
    spread = []
    for step, stream in ((0.01, 0), (0.2, 1)):
        seeds = [derive_seed(derive_seed(99, stream), i) for i in range(n)]
        thetas = [drive(WheelOdometry(p, errors, seed), 5.0, step).theta for seed in seeds]
        spread.append(np.std(thetas, ddof=1))
    expected = math.sqrt(2 * 4e-6 * 5.0) / p.track_width
    np.testing.assert_allclose(spread, expected, rtol=relative_sd_tolerance(n))


def test_defaults_reproduce_the_thesis_odometry_drift():
    """Paper 000 Exp. 1: odometry - truth at P2 (13 m), y mean -0.196 m, SD 0.226 m (11 runs)."""
    p, e = DiffDriveParams(), OdometryErrorParams()
    b_nominal = p.track_width / (1 + e.track_width_error)
    s = 13.0
    mean = s**2 * (e.left_radius_error - e.right_radius_error) / (2 * b_nominal) + s * math.sin(
        e.initial_heading_offset
    )
    sd = math.sqrt(
        (e.initial_heading_sd * s) ** 2 + 2 * e.slip_distance_coeff / b_nominal**2 * s**3 / 3
    )
    # the model agrees with the thesis within the thesis's own sampling error (11 runs)
    assert abs(mean - -0.196) < 0.226 / math.sqrt(11)
    assert sd == pytest.approx(0.226, rel=relative_sd_tolerance(11, k=1.0))
    n = 300
    y = np.array([drive(WheelOdometry(p, e, derive_seed(2013, i)), s, 0.1).y for i in range(n)])
    assert abs(np.mean(y) - mean) < 4 * sd / math.sqrt(n)
    assert np.std(y, ddof=1) == pytest.approx(sd, rel=relative_sd_tolerance(n))


def test_rotation_slip_scales_with_the_angle_turned():
    p = DiffDriveParams()
    k_r = 5e-4
    errors = dataclasses.replace(NONE, slip_rotation_coeff=k_r)
    n, turn = 300, 4 * math.pi
    headings = []
    for i in range(n):
        odometry = WheelOdometry(p, errors, derive_seed(77, i))
        arc = (turn / 100) * p.track_width / 2
        for _ in range(100):
            odometry.update(WheelMotion(-arc, arc, 0.05))
        headings.append(angle_diff(odometry.pose.theta, turn))
        assert math.hypot(odometry.pose.x, odometry.pose.y) < 1e-4  # still on the spot
    expected = math.sqrt(k_r * turn)
    assert np.std(headings, ddof=1) == pytest.approx(expected, rel=relative_sd_tolerance(n))


def test_odometry_is_deterministic_per_seed():
    def run(seed: int) -> list[tuple[float, float, float]]:
        robot = DiffDriveRobot()
        odometry = WheelOdometry(DiffDriveParams(), OdometryErrorParams(), seed)
        out = []
        for k in range(400):
            odometry.update(robot.step(0.8, 0.5 * math.sin(k / 40), 0.05))
            out.append(tuple(pose_array(odometry.pose)))
        return out

    assert run(7) == run(7)
    assert run(7) != run(8)

    def omni(seed: int) -> list[tuple[float, float, float]]:
        robot = OmniRobot()
        odometry = OmniOdometry(OmniOdometryErrorParams(), seed)
        return [
            tuple(pose_array(odometry.update(robot.step(0.3, 0.1, 0.2, 0.1)))) for _ in range(100)
        ]

    assert omni(7) == omni(7)
    assert omni(7) != omni(8)


# -------------------------------------------------------------------------- omni odometry


def test_omni_odometry_without_noise_equals_the_truth():
    start = (1.0, 2.0, -0.5)
    robot = OmniRobot(OmniParams(), start)
    odometry = OmniOdometry(OmniOdometryErrorParams.none(), seed=1, initial_pose=start)
    rng = Random(4)
    for k in range(2000):
        if k % 40 == 0:
            cmd = rng.uniform(-0.6, 0.6, 3)
        odometry.update(robot.step(*cmd, 0.1))
    assert abs(robot.pose.x - start[0]) + abs(robot.pose.y - start[1]) > 1.0
    np.testing.assert_allclose(pose_array(odometry.pose)[:2], pose_array(robot.pose)[:2], atol=1e-9)
    assert angle_diff(odometry.pose.theta, robot.pose.theta) == pytest.approx(0, abs=1e-9)


def test_omni_odometry_noise_grows_with_distance():
    errors = OmniOdometryErrorParams(translation_coeff=1e-4, heading_distance_coeff=0.0)
    n = 200
    lateral = {}
    for length, stream in ((2.0, 0), (8.0, 1)):
        finals = []
        for i in range(n):
            odometry = OmniOdometry(errors, derive_seed(derive_seed(5, stream), i))
            for _ in range(round(length / 0.05)):  # sideways at 0.5 m/s
                odometry.update(BodyMotion(0.0, 0.05, 0.0, 0.05, 0.1))
            finals.append(pose_array(odometry.pose))
        f = np.array(finals)
        expected = math.sqrt(1e-4 * length)
        assert np.std(f[:, 0], ddof=1) == pytest.approx(expected, rel=relative_sd_tolerance(n))
        assert np.std(f[:, 1], ddof=1) == pytest.approx(expected, rel=relative_sd_tolerance(n))
        assert np.std(f[:, 2], ddof=1) == 0.0  # no heading noise configured, none appears
        lateral[length] = np.std(f[:, 0], ddof=1)
    ratio = lateral[8.0] / lateral[2.0]
    assert ratio == pytest.approx(2.0, rel=math.sqrt(2) * relative_sd_tolerance(n))
