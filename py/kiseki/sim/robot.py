# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulated robots (the ground truth) and their odometry.

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

Defaults of :class:`OdometryErrorParams` are chosen so that the factory AGV's odometry
reproduces the magnitude of paper 000's Exp. 1 (odometry minus truth at P2, 13 m straight, 11
runs: y mean -0.20 m, SD 0.23 m; at P1, 7.4 m: y mean -0.07 m, SD 0.11 m). With the defaults the
closed-form prediction is y mean -0.21 m / SD 0.22 m at 13 m and -0.08 m / 0.11 m at 7.4 m.

Every random number comes from :class:`kiseki.core.Random`; pass ``derive_seed(seed, k)`` to
give each robot's odometry its own stream.

Why one file over 400 lines: the two platforms share the odometry error model, the
command limits and the stepping rules; they are one concept (a simulated robot's motion).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Annotated, Any, TypeVar

from pydantic import ConfigDict, Field, RootModel
from pydantic.dataclasses import dataclass as pydantic_dataclass

from kiseki._support.schema import (
    FiniteFloat,
    NonNegativeFloat,
    PositiveFloat,
    PositiveInt,
    parse,
)
from kiseki.core import Pose2, Random, check_seed, normalize_angle

__all__ = [
    "BodyMotion",
    "DiffDriveParams",
    "DiffDriveRobot",
    "OdometryErrorParams",
    "OmniOdometry",
    "OmniOdometryErrorParams",
    "OmniParams",
    "OmniRobot",
    "WheelMotion",
    "WheelOdometry",
]

PoseLike = Pose2 | Sequence[float]

# --------------------------------------------------------------------------------------------
# Parameter checking shared by every parameter class
# --------------------------------------------------------------------------------------------

# The parameter classes are pydantic dataclasses: still frozen dataclasses (dataclasses.fields,
# replace and asdict work), checked on construction by pydantic with kiseki._support.schema's strict
# number types (an int is a float, a float is not an int, a bool is not a number, NaN and
# infinities are errors). A relative error e gives a physical value nominal * (1 + e), so it
# must lie in (-1, 1) for the value to stay positive.
_params = pydantic_dataclass(frozen=True, config=ConfigDict(extra="forbid"))
RelativeError = Annotated[float, Field(strict=True, gt=-1.0, lt=1.0, allow_inf_nan=False)]
Flag = Annotated[bool, Field(strict=True)]

_P = TypeVar("_P", bound="_Params")


@functools.cache
def _document(cls: type) -> type[RootModel]:
    """A model whose document is one parameter section (``parse`` needs a pydantic model)."""
    return RootModel[cls]  # type: ignore[valid-type]


class _Params:
    """``from_dict`` and ``to_dict`` of the parameter classes."""

    @classmethod
    def from_dict(
        cls: type[_P], d: Mapping[str, Any], source: str = "<dict>", at: Sequence[str | int] = ()
    ) -> _P:
        """Builds the parameters from a mapping (a parsed YAML/TOML/JSON section).

        Missing keys keep their documented defaults. Unknown keys, non-numeric values, NaN or
        infinite values and values out of range (sizes and limits must be > 0) raise
        :class:`kiseki._support.schema.SchemaError` (a ValueError) naming ``source`` (e.g. the
        config file), the key (after the path ``at`` of the section in its file) and the value.
        """
        return parse(_document(cls), d, source, at=at).root

    def to_dict(self) -> dict[str, Any]:
        """The parameters as a plain dict (``from_dict(p.to_dict()) == p``)."""
        return dataclasses.asdict(self)  # type: ignore[call-overload]


# --------------------------------------------------------------------------------------------
# Robot parameters
# --------------------------------------------------------------------------------------------


@_params
class DiffDriveParams(_Params):
    """The factory AGV of paper 000 (CARTIS Type B, a differential-drive cart).

    Attributes (value -- source):
        length: 1.05 m -- thesis 000, sec. 3.1 (overall length 1050 mm).
        width: 0.58 m -- thesis 000, sec. 3.1 (580 mm).
        height: 0.99 m -- thesis 000, sec. 3.1 (990 mm).
        wheel_radius: 0.075 m -- NOT in the thesis (the base is an AirBuggy COCO stroller whose
            wheel size it does not give); a stated assumption: a 150 mm drive wheel, common on
            carts of this size. This is the NOMINAL radius, the value the odometry software
            uses; the as-built radii are set by :class:`OdometryErrorParams`.
        track_width: 0.50 m -- NOT in the thesis; stated assumption: the two rear drive wheels
            sit just inside the 0.58 m body (40 mm each side for wheel and mount). This is the
            distance between the wheels' contact points of the simulated (true) robot; the
            odometry's calibrated value differs by :attr:`OdometryErrorParams.track_width_error`.
        max_speed: 1.0 m/s -- stated assumption: the cart is pushed by a worker while teaching
            and drives itself at about walking pace during playback; the thesis gives no limit.
        max_yaw_rate: 1.0 rad/s -- stated assumption (adds +-0.25 m/s at each wheel with the
            0.50 m track, well inside what a 24 V RE35 with 70:1 gear can deliver).
        max_accel: 0.5 m/s^2 -- stated assumption for a light (20 kg payload) cart with a caster.
        max_yaw_accel: 1.0 rad/s^2 -- stated assumption (0.25 m/s^2 at each wheel).
        encoder_counts_per_rev: 500 -- thesis 000, sec. 3.1 (Maxon MR Type L, 500 counts per
            motor turn, on each motor).
        gear_ratio: 70.0 -- thesis 000, sec. 3.1 (reduction 70:1 between motor and wheel).
        quadrature: True -- datasheet reading: Maxon rates its MR encoders in counts per turn
            per channel, and a quadrature decoder (the SH2 counter under YP-Spur) counts all four
            edges, giving 4 x 500 = 2000 counts per motor turn. Set False for x1 counting.
    """

    length: PositiveFloat = 1.05
    width: PositiveFloat = 0.58
    height: PositiveFloat = 0.99
    wheel_radius: PositiveFloat = 0.075
    track_width: PositiveFloat = 0.50
    max_speed: PositiveFloat = 1.0
    max_yaw_rate: PositiveFloat = 1.0
    max_accel: PositiveFloat = 0.5
    max_yaw_accel: PositiveFloat = 1.0
    encoder_counts_per_rev: PositiveInt = 500
    gear_ratio: PositiveFloat = 70.0
    quadrature: Flag = True

    @property
    def counts_per_wheel_rev(self) -> float:
        """Encoder counts per wheel revolution: counts x gear x (4 with quadrature decoding).

        140000 with the defaults (500 x 70 x 4).
        """
        return self.encoder_counts_per_rev * self.gear_ratio * (4 if self.quadrature else 1)

    @property
    def distance_per_count(self) -> float:
        """Ground travel of one encoder count at the nominal radius (3.37e-6 m by default)."""
        return 2.0 * math.pi * self.wheel_radius / self.counts_per_wheel_rev


@_params
class OmniParams(_Params):
    """The omnidirectional hospital transport robot of paper 004 (MKR-003).

    Attributes (value -- source):
        length: 0.70 m -- NOT in paper 004; stated assumption: a square footprint as wide as
            the robot.
        width: 0.70 m -- paper 004 (w1 = 0.70 m, the robot width in the width term f(w)).
        max_speed: 0.5 m/s -- paper 004 (v_max), applied to the norm of the body velocity.
        max_accel: 0.5 m/s^2 -- paper 004 (maximum acceleration), applied to the norm of the
            change of the body-frame velocity vector.
        max_yaw_rate: 1.0 rad/s -- NOT in paper 004; stated assumption: the rim of the 0.70 m
            body then moves at 0.35 m/s, below v_max.
        max_yaw_accel: 1.0 rad/s^2 -- NOT in paper 004; stated assumption: rim acceleration
            0.35 m/s^2, below a_max.
    """

    length: PositiveFloat = 0.70
    width: PositiveFloat = 0.70
    max_speed: PositiveFloat = 0.5
    max_accel: PositiveFloat = 0.5
    max_yaw_rate: PositiveFloat = 1.0
    max_yaw_accel: PositiveFloat = 1.0


@_params
class OdometryErrorParams(_Params):
    """Systematic and random odometry errors of the differential-drive AGV.

    Conventions: the as-built wheel radii are ``wheel_radius * (1 + e)``; the as-built track
    (the simulated robot's, :attr:`DiffDriveParams.track_width`) is ``(1 + track_width_error)``
    times the nominal track the odometry integrates with, i.e. ``1 + track_width_error`` is
    Borenstein & Feng's E_b = b_actual / b_nominal.

    Attributes (value -- source):
        left_radius_error: -0.0015 (-0.15 %) -- stated assumption, fitted to paper 000 Exp. 1:
            the loaded tyres roll on a slightly smaller radius than the nominal one. Tenths of a
            percent is the size of the uncalibrated wheel-diameter errors UMBmark reports.
        right_radius_error: -0.0005 (-0.05 %) -- stated assumption, as above. The left-right
            difference of 0.1 % makes the odometry curve to the right (y error -0.17 m after
            13 m, growing with distance squared, as the thesis's mean error does: 2.7 times
            larger at 13 m than at 7.4 m), the mean of -0.1 % gives the thesis's +0.01 m along
            the track.
        track_width_error: +0.005 (+0.5 %) -- stated assumption: the effective contact point
            of a wide tyre is uncertain by a few millimetres (2.5 mm of 0.50 m). Odometry turns
            are then 0.5 % too large.
        initial_heading_offset: -0.2 deg (-3.49e-3 rad) -- stated assumption: a constant
            mis-alignment when the cart is placed on the start mark; the odometry's initial
            heading is the true one plus this offset (and the random part below). The thesis
            (sec. 4.1.2) names the placement error as the main cause of its odometry drift.
        initial_heading_sd: 0.7 deg (1.22e-2 rad) -- standard deviation of the random placement
            error, drawn once per odometry instance; fitted to the growth of the run-to-run
            spread of Exp. 1 together with the slip noise.
        slip_distance_coeff: 4e-6 m -- k_d: each wheel's slip has variance k_d * |travel|
            (2 mm SD per metre rolled). Fitted to Exp. 1's spread (with the placement error:
            predicted SD 0.11 m at 7.4 m and 0.22 m at 13 m vs the thesis's 0.11 and 0.23 m).
        slip_rotation_coeff: 5e-5 rad -- k_r: turning scrubs the tyres and the caster; an equal
            and opposite slip on the two wheels whose induced heading error has variance
            k_r * |true rotation| (1.0 deg SD per full turn). Stated assumption.
    """

    left_radius_error: RelativeError = -0.0015
    right_radius_error: RelativeError = -0.0005
    track_width_error: RelativeError = 0.005
    initial_heading_offset: FiniteFloat = math.radians(-0.2)
    initial_heading_sd: NonNegativeFloat = math.radians(0.7)
    slip_distance_coeff: NonNegativeFloat = 4e-6
    slip_rotation_coeff: NonNegativeFloat = 5e-5

    @classmethod
    def none(cls) -> OdometryErrorParams:
        """No systematic and no random error: only the encoder quantisation remains."""
        return cls(**{f.name: 0.0 for f in dataclasses.fields(cls)})


@_params
class OmniOdometryErrorParams(_Params):
    """Random odometry error of the omnidirectional robot (a simple, documented model).

    Each step's true body-frame displacement (dx, dy, dtheta) gets independent zero-mean
    Gaussian noise: each translation component with variance ``translation_coeff * distance``,
    the heading with variance ``heading_distance_coeff * distance + heading_rotation_coeff *
    |dtheta|``, where ``distance`` is the path length of the step. Paper 004 gives no odometry
    model; the values are stated assumptions (omni-wheel rollers slip more than plain tyres,
    so the coefficients are larger than those of :class:`OdometryErrorParams`).

    Attributes (value -- source):
        translation_coeff: 1e-4 m -- 1 cm SD per component after 1 m (assumption).
        heading_distance_coeff: 1e-4 rad -- rad^2 per metre: 0.57 deg SD after 1 m (assumption).
        heading_rotation_coeff: 5e-4 rad -- rad^2 per rad turned: 3.2 deg SD per full turn
            (assumption).
    """

    translation_coeff: NonNegativeFloat = 1e-4
    heading_distance_coeff: NonNegativeFloat = 1e-4
    heading_rotation_coeff: NonNegativeFloat = 5e-4

    @classmethod
    def none(cls) -> OmniOdometryErrorParams:
        """No noise: the odometry equals the truth."""
        return cls(**{f.name: 0.0 for f in dataclasses.fields(cls)})


# --------------------------------------------------------------------------------------------
# Motions reported by the robots
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class WheelMotion:
    """True ground travel of the two drive wheels during one step (what the encoders sense).

    Attributes:
        left: signed travel of the left wheel's contact point along its rolling direction, m.
        right: the same for the right wheel, m.
        dt: duration of the step, s.
    """

    left: float
    right: float
    dt: float

    def __post_init__(self) -> None:
        for name in ("left", "right"):
            object.__setattr__(self, name, _finite(getattr(self, name), f"WheelMotion.{name}"))
        object.__setattr__(self, "dt", _positive_dt(self.dt, "WheelMotion.dt"))


@dataclass(frozen=True)
class BodyMotion:
    """True motion of a robot during one step, in the body frame at the start of the step.

    Attributes:
        dx, dy: displacement, m, in the body frame at the step's start (x forward, y left).
        dtheta: heading change, rad (not wrapped).
        distance: path length travelled, m (speed x dt; >= the chord sqrt(dx^2 + dy^2)).
        dt: duration of the step, s.
    """

    dx: float
    dy: float
    dtheta: float
    distance: float
    dt: float

    def __post_init__(self) -> None:
        for name in ("dx", "dy", "dtheta", "distance"):
            object.__setattr__(self, name, _finite(getattr(self, name), f"BodyMotion.{name}"))
        if self.distance < 0:
            raise ValueError(f"BodyMotion.distance must be >= 0, got {self.distance!r}")
        object.__setattr__(self, "dt", _positive_dt(self.dt, "BodyMotion.dt"))


# --------------------------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------------------------


def _finite(value: Any, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be a finite number, got {value!r}") from None
    else:
        number = float(value)
    if not math.isfinite(number):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return number


def _positive_dt(value: Any, name: str) -> float:
    dt = _finite(value, name)
    if dt <= 0:
        raise ValueError(f"{name} must be > 0 s, got {value!r}")
    return dt


def _as_pose(pose: PoseLike, name: str) -> tuple[float, float, float]:
    if isinstance(pose, Pose2):
        return pose.x, pose.y, pose.theta
    try:
        x, y, theta = pose
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a Pose2 or (x, y, theta), got {pose!r}") from None
    return _finite(x, f"{name}.x"), _finite(y, f"{name}.y"), _finite(theta, f"{name}.theta")


def _sinc(a: float) -> float:
    """sin(a) / a, accurate near 0."""
    if abs(a) < 1e-4:
        return 1.0 - a * a / 6.0
    return math.sin(a) / a


def _arc_displacement(theta: float, ds: float, dtheta: float) -> tuple[float, float]:
    """World displacement of a motion of length ``ds`` along a constant-curvature arc.

    Starting at heading ``theta`` and turning by ``dtheta``: the chord has length
    ``ds * sinc(dtheta / 2)`` and points along ``theta + dtheta / 2``. Exact for any dtheta
    (a straight line for dtheta = 0).
    """
    half = 0.5 * dtheta
    chord = ds * _sinc(half)
    mid = theta + half
    return chord * math.cos(mid), chord * math.sin(mid)


def _limit(command: float, current: float, max_rate: float, max_value: float, dt: float) -> float:
    """Acceleration limit first (|change| <= max_rate dt), then |value| <= max_value."""
    step = max_rate * dt
    value = current + min(max(command - current, -step), step)
    return min(max(value, -max_value), max_value)


def _wrap(angle: float) -> float:
    return float(normalize_angle(angle))


# --------------------------------------------------------------------------------------------
# Robots (ground truth)
# --------------------------------------------------------------------------------------------


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
        self._x, self._y, theta = _as_pose(pose, "pose")
        self._theta = _wrap(theta)
        v, w = (_finite(c, f"velocity[{i}]") for i, c in enumerate(velocity))
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
        v_cmd = _finite(v_cmd, "v_cmd")
        w_cmd = _finite(w_cmd, "w_cmd")
        dt = _positive_dt(dt, "dt")
        p = self.params
        self._v = _limit(v_cmd, self._v, p.max_accel, p.max_speed, dt)
        self._w = _limit(w_cmd, self._w, p.max_yaw_accel, p.max_yaw_rate, dt)
        ds, dtheta = self._v * dt, self._w * dt
        dx, dy = _arc_displacement(self._theta, ds, dtheta)
        self._x += dx
        self._y += dy
        self._theta = _wrap(self._theta + dtheta)
        half_track_turn = 0.5 * p.track_width * dtheta
        return WheelMotion(left=ds - half_track_turn, right=ds + half_track_turn, dt=dt)


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
        self._x, self._y, theta = _as_pose(pose, "pose")
        self._theta = _wrap(theta)
        vx, vy, w = (_finite(c, f"velocity[{i}]") for i, c in enumerate(velocity))
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
        vx_cmd = _finite(vx_cmd, "vx_cmd")
        vy_cmd = _finite(vy_cmd, "vy_cmd")
        w_cmd = _finite(w_cmd, "w_cmd")
        dt = _positive_dt(dt, "dt")
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
        scale = dt * _sinc(0.5 * dtheta)
        c, s = math.cos(0.5 * dtheta), math.sin(0.5 * dtheta)
        bx, by = scale * (c * vx - s * vy), scale * (s * vx + c * vy)
        ct, st = math.cos(self._theta), math.sin(self._theta)
        self._x += ct * bx - st * by
        self._y += st * bx + ct * by
        self._theta = _wrap(self._theta + dtheta)
        return BodyMotion(dx=bx, dy=by, dtheta=dtheta, distance=speed * dt, dt=dt)


# --------------------------------------------------------------------------------------------
# Odometry
# --------------------------------------------------------------------------------------------


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
        x, y, theta = _as_pose(initial_pose, "initial_pose")
        placement = ep.initial_heading_sd * float(self._rng.normal(0.0, 1.0, 1)[0])
        self._x, self._y = x, y
        self._theta = _wrap(theta + ep.initial_heading_offset + placement)

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
        dx, dy = _arc_displacement(self._theta, ds, dtheta)
        self._x += dx
        self._y += dy
        self._theta = _wrap(self._theta + dtheta)
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
        self._x, self._y, theta = _as_pose(initial_pose, "initial_pose")
        self._theta = _wrap(theta)

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
        self._theta = _wrap(self._theta + motion.dtheta + sd_theta * z[2])
        return self.pose
