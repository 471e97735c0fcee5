# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulated odometry against closed forms and sampling statistics.

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

from _helpers.sim_robot import NONE, angle_diff, pose_array, relative_sd_tolerance
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
