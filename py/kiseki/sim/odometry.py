# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Odometry of the simulated robots.

Odometry (differential drive, :class:`WheelOdometry`)
    The physics of a real wheel encoder chain, step by step: the true ground travel of each
    wheel (from :class:`WheelMotion`) plus a random slip gives the wheel's rotation through the
    wheel's TRUE radius; the encoder turns that rotation into integer counts (the fractional
    remainder is kept between steps, so quantisation never accumulates into a bias); the counts
    are turned back into distance with the NOMINAL radius and the pose is integrated with the
    NOMINAL track width. Calibration errors therefore appear as systematic drift exactly as on a
    real robot (Borenstein & Feng, "Measurement and correction of systematic odometry errors in
    mobile robots", IEEE Trans. Robotics and Automation 12(6), 1996 -- UMBmark), and the slip
    noise has a variance proportional to the distance each wheel rolls (the error model of
    Chong & Kleeman, ICRA 1997, also in Siegwart, Nourbakhsh & Scaramuzza, "Introduction to
    Autonomous Mobile Robots", sec. 5.2.4).

Every random number comes from :class:`kiseki.core.Random`; pass ``derive_seed(seed, k)`` to
give each robot's odometry its own stream.
"""

from __future__ import annotations

import math

from kiseki.core import Pose2, Random, check_seed
from kiseki.sim.motion import (
    BodyMotion,
    PoseLike,
    WheelMotion,
    arc_displacement,
    as_pose,
    wrap_angle,
)
from kiseki.sim.robot_params import (
    DiffDriveParams,
    OdometryErrorParams,
    OmniOdometryErrorParams,
)

__all__ = ["OmniOdometry", "WheelOdometry"]


class WheelOdometry:
    """Encoder odometry of the differential-drive AGV (see the module docstring for the physics).

    Args:
        robot_params: the robot; ``wheel_radius`` is the nominal radius, ``track_width`` the
            true track, the encoder fields give the quantisation.
        error_params: calibration and slip errors (default :class:`OdometryErrorParams`).
        seed: seed of this odometry's :class:`kiseki.core.Random` stream, an integer in
            [0, 2**64). The random placement error is the stream's first draw; every update
            then draws exactly three normals, so a seed fixes the whole sequence.
        initial_pose: the robot's true initial pose. The odometry starts there, with its
            heading off by ``initial_heading_offset`` plus the random placement error.
    """

    def __init__(
        self,
        robot_params: DiffDriveParams | None = None,
        error_params: OdometryErrorParams | None = None,
        seed: int = 0,
        initial_pose: PoseLike = (0.0, 0.0, 0.0),
    ) -> None:
        self.robot_params = robot_params if robot_params is not None else DiffDriveParams()
        self.error_params = error_params if error_params is not None else OdometryErrorParams()
        self._rng = Random(check_seed(seed))
        rp, ep = self.robot_params, self.error_params
        cpr = rp.counts_per_wheel_rev
        self._true_track = rp.track_width
        self._nominal_track = rp.track_width / (1.0 + ep.track_width_error)
        self._counts_per_metre = (
            cpr / (2.0 * math.pi * rp.wheel_radius * (1.0 + ep.left_radius_error)),
            cpr / (2.0 * math.pi * rp.wheel_radius * (1.0 + ep.right_radius_error)),
        )
        self._metres_per_count = rp.distance_per_count
        self._fraction = [0.0, 0.0]
        self._counts = [0, 0]
        x, y, theta = as_pose(initial_pose, "initial_pose")
        placement = ep.initial_heading_sd * float(self._rng.normal(0.0, 1.0, 1)[0])
        self._x, self._y = x, y
        self._theta = wrap_angle(theta + ep.initial_heading_offset + placement)

    @property
    def pose(self) -> Pose2:
        """The odometry pose."""
        return Pose2(self._x, self._y, self._theta)

    @property
    def counts(self) -> tuple[int, int]:
        """Cumulative encoder counts ``(left, right)`` since construction."""
        return self._counts[0], self._counts[1]

    @property
    def nominal_track_width(self) -> float:
        """The track the odometry integrates with: ``track_width / (1 + track_width_error)``."""
        return self._nominal_track

    def update(self, motion: WheelMotion) -> Pose2:
        """Senses one step's wheel motion and returns the new odometry pose."""
        if not isinstance(motion, WheelMotion):
            raise ValueError(f"update needs a WheelMotion, got {type(motion).__name__}")
        ep = self.error_params
        z = self._rng.normal(0.0, 1.0, 3)
        true_rotation = (motion.right - motion.left) / self._true_track
        sd_turn = 0.5 * self._nominal_track * math.sqrt(ep.slip_rotation_coeff * abs(true_rotation))
        slip = (
            math.sqrt(ep.slip_distance_coeff * abs(motion.left)) * z[0] - sd_turn * z[2],
            math.sqrt(ep.slip_distance_coeff * abs(motion.right)) * z[1] + sd_turn * z[2],
        )
        measured = [0.0, 0.0]
        for i, travel in enumerate((motion.left, motion.right)):
            position = self._fraction[i] + (travel + slip[i]) * self._counts_per_metre[i]
            whole = math.floor(position)
            self._fraction[i] = position - whole
            self._counts[i] += whole
            measured[i] = whole * self._metres_per_count
        ds = 0.5 * (measured[0] + measured[1])
        dtheta = (measured[1] - measured[0]) / self._nominal_track
        dx, dy = arc_displacement(self._theta, ds, dtheta)
        self._x += dx
        self._y += dy
        self._theta = wrap_angle(self._theta + dtheta)
        return self.pose


class OmniOdometry:
    """Odometry of the omnidirectional robot: the true step plus noise that grows with motion.

    Args:
        error_params: the noise model (default :class:`OmniOdometryErrorParams`).
        seed: seed of this odometry's :class:`kiseki.core.Random` stream; every update draws
            exactly three normals.
        initial_pose: the initial pose (the odometry starts exactly there).
    """

    def __init__(
        self,
        error_params: OmniOdometryErrorParams | None = None,
        seed: int = 0,
        initial_pose: PoseLike = (0.0, 0.0, 0.0),
    ) -> None:
        self.error_params = error_params if error_params is not None else OmniOdometryErrorParams()
        self._rng = Random(check_seed(seed))
        self._x, self._y, theta = as_pose(initial_pose, "initial_pose")
        self._theta = wrap_angle(theta)

    @property
    def pose(self) -> Pose2:
        """The odometry pose."""
        return Pose2(self._x, self._y, self._theta)

    def update(self, motion: BodyMotion) -> Pose2:
        """Adds one noisy step (composed in the odometry's body frame); returns the new pose."""
        if not isinstance(motion, BodyMotion):
            raise ValueError(f"update needs a BodyMotion, got {type(motion).__name__}")
        ep = self.error_params
        z = self._rng.normal(0.0, 1.0, 3)
        sd_xy = math.sqrt(ep.translation_coeff * motion.distance)
        sd_theta = math.sqrt(
            ep.heading_distance_coeff * motion.distance
            + ep.heading_rotation_coeff * abs(motion.dtheta)
        )
        dx = motion.dx + sd_xy * z[0]
        dy = motion.dy + sd_xy * z[1]
        c, s = math.cos(self._theta), math.sin(self._theta)
        self._x += c * dx - s * dy
        self._y += s * dx + c * dy
        self._theta = wrap_angle(self._theta + motion.dtheta + sd_theta * z[2])
        return self.pose
