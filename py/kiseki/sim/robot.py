# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulated robots: their true motion (the ground truth). Their odometry is
:mod:`kiseki.sim.odometry`, their parameters :mod:`kiseki.sim.robot_params`.

Two platforms, one per paper that needs a moving robot:

* :class:`DiffDriveRobot` -- the factory AGV of paper 000 (CARTIS Type B: an AirBuggy COCO
  three-wheeled cart, rear wheels driven by two Maxon RE35 motors, 70:1 gear, Maxon MR Type L
  encoders with 500 counts per turn; 1050 x 580 x 990 mm).
* :class:`OmniRobot` -- the hospital transport robot of paper 004 (MKR-003, omnidirectional,
  v_max 0.5 m/s, a_max 0.5 m/s^2, width 0.70 m).

Units are SI throughout (m, s, rad); poses are ``(x, y, theta)`` in the world frame and are
returned as :class:`kiseki.core.Pose2` (theta wrapped to [-pi, pi)).

Motion model (both robots)
    ``step`` takes a velocity command and a period ``dt``. The command is limited in this
    order: first the **acceleration limit** (the change from the current velocity is clipped to
    ``max_accel * dt``), then the **velocity limit** (clipped to ``max_speed``). Because the
    velocity limit is a projection onto a convex set that contains the previous velocity, the
    second clip never undoes the first: every step satisfies both ``|v_k| <= v_max`` and
    ``|v_k - v_(k-1)| <= a_max dt``. The limited velocity is then held constant for ``dt``
    (zero-order hold, as a velocity-controlled motor driver with a fixed control period does)
    and the pose is integrated **exactly** for that constant velocity (motion along a circular
    arc, not an Euler step), so the truth has no integration error whatever ``dt`` is.
"""

from __future__ import annotations

import math

from kiseki._support.moved import moved_names
from kiseki._support.real_numbers import check_number
from kiseki.core import Pose2
from kiseki.sim.motion import (
    BodyMotion,
    PoseLike,
    WheelMotion,
    arc_displacement,
    as_pose,
    sinc,
    wrap_angle,
)
from kiseki.sim.robot_params import DiffDriveParams, OmniParams

__all__ = ["DiffDriveRobot", "OmniRobot"]

# Names this module held before it was split and no longer imports (the robots' own parameters
# and motions it still imports), importable from it for one release with a DeprecationWarning
# naming their module now (kiseki._support.moved)
__getattr__ = moved_names(
    __name__,
    {
        "WheelOdometry": "kiseki.sim.odometry",
        "OmniOdometry": "kiseki.sim.odometry",
        "OdometryErrorParams": "kiseki.sim.robot_params",
        "OmniOdometryErrorParams": "kiseki.sim.robot_params",
    },
)


def _limit(command: float, current: float, max_rate: float, max_value: float, dt: float) -> float:
    """Acceleration limit first (|change| <= max_rate dt), then |value| <= max_value."""
    step = max_rate * dt
    value = current + min(max(command - current, -step), step)
    return min(max(value, -max_value), max_value)


class DiffDriveRobot:
    """True motion of the differential-drive AGV.

    Args:
        params: the robot (:class:`DiffDriveParams`).
        pose: initial true pose, a :class:`Pose2` or ``(x, y, theta)``; default the origin.
        velocity: initial ``(v, w)`` in m/s and rad/s; must be within the velocity limits.
    """

    def __init__(
        self,
        params: DiffDriveParams | None = None,
        pose: PoseLike = (0.0, 0.0, 0.0),
        velocity: tuple[float, float] = (0.0, 0.0),
    ) -> None:
        self.params = params if params is not None else DiffDriveParams()
        self._x, self._y, theta = as_pose(pose, "pose")
        self._theta = wrap_angle(theta)
        v, w = (check_number(c, f"velocity[{i}]") for i, c in enumerate(velocity))
        if abs(v) > self.params.max_speed or abs(w) > self.params.max_yaw_rate:
            raise ValueError(
                f"initial velocity {(v, w)} exceeds max_speed {self.params.max_speed} m/s "
                f"or max_yaw_rate {self.params.max_yaw_rate} rad/s"
            )
        self._v, self._w = v, w

    @property
    def pose(self) -> Pose2:
        """The true pose."""
        return Pose2(self._x, self._y, self._theta)

    @property
    def velocity(self) -> tuple[float, float]:
        """The current (limited) velocity ``(v, w)``: m/s forward, rad/s counter-clockwise."""
        return self._v, self._w

    def step(self, v_cmd: float, w_cmd: float, dt: float) -> WheelMotion:
        """Applies a velocity command for ``dt`` seconds and returns the wheels' true travel.

        The command is limited (acceleration, then velocity; see the module docstring), held
        for ``dt`` and the pose advanced along the exact arc. The returned wheel travel is
        ``(v -+ w * track_width / 2) * dt`` for the left/right wheel.

        Raises:
            ValueError: a NaN or infinite command, or ``dt <= 0``.
        """
        v_cmd = check_number(v_cmd, "v_cmd")
        w_cmd = check_number(w_cmd, "w_cmd")
        dt = check_number(dt, "dt", 0.0, low_open=True, unit="s")
        p = self.params
        self._v = _limit(v_cmd, self._v, p.max_accel, p.max_speed, dt)
        self._w = _limit(w_cmd, self._w, p.max_yaw_accel, p.max_yaw_rate, dt)
        ds, dtheta = self._v * dt, self._w * dt
        dx, dy = arc_displacement(self._theta, ds, dtheta)
        self._x += dx
        self._y += dy
        self._theta = wrap_angle(self._theta + dtheta)
        half_track_turn = 0.5 * p.track_width * dtheta
        return WheelMotion(left=ds - half_track_turn, right=ds + half_track_turn, dt=dt)

    def halt(self, pose: PoseLike) -> None:
        """A contact: the robot stands at `pose` (where its last step began) at rest, as a cart
        pushed against a wall stops there."""
        self._x, self._y, theta = as_pose(pose, "pose")
        self._theta = wrap_angle(theta)
        self._v = self._w = 0.0


class OmniRobot:
    """True motion of the omnidirectional hospital robot; velocities are in the body frame.

    Args:
        params: the robot (:class:`OmniParams`).
        pose: initial true pose, a :class:`Pose2` or ``(x, y, theta)``; default the origin.
        velocity: initial body velocity ``(vx, vy, w)``; must be within the limits.
    """

    def __init__(
        self,
        params: OmniParams | None = None,
        pose: PoseLike = (0.0, 0.0, 0.0),
        velocity: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> None:
        self.params = params if params is not None else OmniParams()
        self._x, self._y, theta = as_pose(pose, "pose")
        self._theta = wrap_angle(theta)
        vx, vy, w = (check_number(c, f"velocity[{i}]") for i, c in enumerate(velocity))
        if math.hypot(vx, vy) > self.params.max_speed or abs(w) > self.params.max_yaw_rate:
            raise ValueError(
                f"initial velocity {(vx, vy, w)} exceeds max_speed {self.params.max_speed} m/s "
                f"or max_yaw_rate {self.params.max_yaw_rate} rad/s"
            )
        self._vx, self._vy, self._w = vx, vy, w

    @property
    def pose(self) -> Pose2:
        """The true pose."""
        return Pose2(self._x, self._y, self._theta)

    @property
    def velocity(self) -> tuple[float, float, float]:
        """The current (limited) body velocity ``(vx, vy, w)``: m/s forward, m/s left, rad/s."""
        return self._vx, self._vy, self._w

    def step(self, vx_cmd: float, vy_cmd: float, w_cmd: float, dt: float) -> BodyMotion:
        """Applies a body-frame velocity command for ``dt`` seconds.

        Limits: the change of the body velocity vector is scaled down to norm
        ``max_accel * dt``, then the vector is scaled down to norm ``max_speed`` (both keep its
        direction); the yaw rate is limited like the differential drive's. With the body
        velocity constant over the step, the world displacement is exactly
        ``dt * sinc(w dt / 2) * R(theta + w dt / 2) @ (vx, vy)``.

        Returns:
            the true :class:`BodyMotion` of the step (body frame at the step's start).

        Raises:
            ValueError: a NaN or infinite command, or ``dt <= 0``.
        """
        vx_cmd = check_number(vx_cmd, "vx_cmd")
        vy_cmd = check_number(vy_cmd, "vy_cmd")
        w_cmd = check_number(w_cmd, "w_cmd")
        dt = check_number(dt, "dt", 0.0, low_open=True, unit="s")
        p = self.params
        ax, ay = vx_cmd - self._vx, vy_cmd - self._vy
        change = math.hypot(ax, ay)
        max_change = p.max_accel * dt
        if change > max_change:
            ax, ay = ax * (max_change / change), ay * (max_change / change)
        vx, vy = self._vx + ax, self._vy + ay
        speed = math.hypot(vx, vy)
        if speed > p.max_speed:
            vx, vy = vx * (p.max_speed / speed), vy * (p.max_speed / speed)
            speed = p.max_speed
        self._vx, self._vy = vx, vy
        self._w = _limit(w_cmd, self._w, p.max_yaw_accel, p.max_yaw_rate, dt)
        dtheta = self._w * dt
        scale = dt * sinc(0.5 * dtheta)
        c, s = math.cos(0.5 * dtheta), math.sin(0.5 * dtheta)
        bx, by = scale * (c * vx - s * vy), scale * (s * vx + c * vy)
        ct, st = math.cos(self._theta), math.sin(self._theta)
        self._x += ct * bx - st * by
        self._y += st * bx + ct * by
        self._theta = wrap_angle(self._theta + dtheta)
        return BodyMotion(dx=bx, dy=by, dtheta=dtheta, distance=speed * dt, dt=dt)
