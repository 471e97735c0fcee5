# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Range sensors of the papers: 2-D laser scanners and the Xtion-like depth camera (the tilting
laser of the rubble paper is kiseki.sim.tilting_laser, which builds on this module). Geometry is
ray cast in C++; noise is applied here with kiseki's seeded generator. Every parameter names its
source (datasheet, paper, or stated assumption).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from pydantic import ConfigDict, Field, model_validator
from pydantic.dataclasses import dataclass as pydantic_dataclass

from kiseki._support.schema import NonNegativeFloat, PositiveFloat
from kiseki.core import Random, check_seed
from kiseki.grid import OccupancyGrid, beam_angles
from kiseki.sim.pose6 import pose_matrix
from kiseki.sim.primitives import rotation

__all__ = [
    "LASER_PRESETS",
    "MAX_BEAMS",
    "MAX_IMAGE_SIDE",
    "MAX_RANGE",
    "DepthCamera",
    "DepthCameraParams",
    "Laser2D",
    "LaserParams",
    "Mount",
]


# Limits on what sizes memory and time: rays cast per reading and how far each goes.
MAX_BEAMS = 10_000
"""Beams of one planar scan (the densest 2-D scanners have a few thousand)."""
MAX_IMAGE_SIDE = 4096
"""Pixels along each side of a depth image."""
MAX_RANGE = 1000.0
"""Metres a range sensor's ray is cast."""

# The parameter classes are pydantic dataclasses (kiseki._support.schema's strict number types):
# checked on construction, on dataclasses.replace and as a section of a scene file
# (kiseki.sim.setup).
_params = pydantic_dataclass(frozen=True, config=ConfigDict(extra="forbid"))
Range = Annotated[float, Field(strict=True, gt=0, le=MAX_RANGE, allow_inf_nan=False)]
Probability = Annotated[float, Field(strict=True, ge=0, lt=1, allow_inf_nan=False)]
ImageSide = Annotated[int, Field(strict=True, ge=1, le=MAX_IMAGE_SIDE)]


@dataclass(frozen=True)
class Mount:
    """A sensor's pose on the robot: body frame x forward, y left, z up (metres, degrees);
    rotation Rz(yaw) Ry(pitch) Rx(roll)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    roll_deg: float = 0.0

    def matrix(self) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = rotation(
            *(math.radians(a) for a in (self.yaw_deg, self.pitch_deg, self.roll_deg))
        )
        m[:3, 3] = [self.x, self.y, self.z]
        return m

    def world(self, robot_pose) -> np.ndarray:
        """The mount's 4x4 pose in the world for a planar robot pose (x, y, theta) on level
        ground at z = 0, or a 6-DOF pose (x, y, z, roll, pitch, yaw; radians, see
        kiseki.sim.pose6)."""
        values = [float(v) for v in robot_pose]
        if len(values) == 3:
            values = [values[0], values[1], 0.0, 0.0, 0.0, values[2]]
        if len(values) != 6:
            raise ValueError(f"robot_pose: expected (x, y, theta) or 6 values, got {len(values)}")
        return pose_matrix(*values) @ self.matrix()

    def planar(self, robot_pose) -> np.ndarray:
        x, y, th = (float(v) for v in robot_pose)
        c, s = math.cos(th), math.sin(th)
        return np.array(
            [
                x + c * self.x - s * self.y,
                y + s * self.x + c * self.y,
                th + math.radians(self.yaw_deg),
            ]
        )


@_params
class LaserParams:
    """A planar laser scanner. Range noise: Gaussian, SD = max(noise_sd, noise_fraction * r);
    a beam that hits nothing, or drops out, returns max_range (the CARMEN convention)."""

    name: Annotated[str, Field(strict=True)]
    field_of_view_deg: Annotated[float, Field(strict=True, gt=0, le=360, allow_inf_nan=False)]
    beams: Annotated[int, Field(strict=True, ge=1, le=MAX_BEAMS)]
    max_range: Range
    noise_sd: NonNegativeFloat  # m
    noise_fraction: NonNegativeFloat = 0.0  # of the range
    dropout_probability: Probability = 0.0
    period: PositiveFloat = 0.025  # s per scan

    @property
    def angles(self) -> np.ndarray:
        """The beam angles (rad), read-only: computed once per beam count and field of view
        (while among the 64 last used), shared by every scan."""
        return _beam_angles(self.beams, self.field_of_view_deg)


@functools.lru_cache(maxsize=64)
def _beam_angles(beams: int, field_of_view_deg: float) -> np.ndarray:
    # kept here, not on the frozen params (whose __dict__ holds its fields alone), by value: a
    # params object and its equal copies share one array
    angles = beam_angles(beams, math.radians(field_of_view_deg))
    # over immutable bytes: read-only for good (an array that owns its data can be unlocked)
    return np.frombuffer(angles.tobytes(), dtype=angles.dtype)


LASER_PRESETS = {
    # SICK LMS200 datasheet: 180 deg, 0.5 deg steps, 8 m mode, statistical error 5 mm (1 sigma)
    "sick_lms": LaserParams("sick_lms", 180.0, 361, 8.0, 0.005, period=1 / 37.5),
    # Hokuyo UTM-30LX datasheet: 270 deg, 1081 beams, 30 m, accuracy +-30 mm (taken as 3 sigma)
    "hokuyo_utm30lx": LaserParams("hokuyo_utm30lx", 270.0, 1081, 30.0, 0.01, period=0.025),
    # speed-control paper: +-120 deg, 4 m, every 100 ms (a Hokuyo URG-04LX: 683 beams over
    # 240 deg, accuracy +-10 mm below 1 m and +-1 % beyond, taken as 3 sigma)
    "speed_lrf": LaserParams("speed_lrf", 240.0, 683, 4.0, 0.01 / 3, 0.01 / 3, period=0.1),
}


class Laser2D:
    """Casts a scan in the 2-D ground truth of the laser's height and adds the noise model."""

    def __init__(self, params: LaserParams, mount: Mount, seed: int) -> None:
        self.params, self.mount, self.rng = params, mount, Random(seed)

    def scan(self, grid: OccupancyGrid, robot_pose) -> tuple[np.ndarray, np.ndarray]:
        """(sensor pose (3,), ranges (beams,) float32) for the robot at robot_pose."""
        p = self.params
        sensor = self.mount.planar(robot_pose)
        ranges = grid.cast_scans(sensor[None], p.angles, max_range=p.max_range)[0]
        hit = ranges < p.max_range
        sd = np.maximum(p.noise_sd, p.noise_fraction * ranges)
        noisy = ranges + sd * self.rng.normal(0.0, 1.0, ranges.size)
        ranges = np.where(hit, np.clip(noisy, 0.0, p.max_range), p.max_range)
        if p.dropout_probability > 0:
            drop = self.rng.uniform(0.0, 1.0, ranges.size) < p.dropout_probability
            ranges[drop] = p.max_range
        return sensor, ranges.astype(np.float32)


@_params
class DepthCameraParams:
    """An Xtion-like structured-light depth camera (ASUS Xtion PRO: 58 x 45 deg, 0.8 (0.5 in
    near mode) to 3.5 m nominal, used to 10 m in the thesis; 640 x 480 native).

    Noise model (Khoshelham and Elberink, Sensors 12(2), 2012): depth comes from disparity
    d = f b / z with f the native focal length and b the projector-camera baseline (0.075 m);
    disparity noise sigma_d = 0.07 px (their 1.5 cm at 3 m) and quantisation to 1/8 px, so the
    depth error grows with z squared and the depth step exceeds 5 cm beyond about 4.2 m."""

    width: ImageSide = 160
    height: ImageSide = 120
    hfov_deg: Annotated[float, Field(strict=True, gt=0, lt=180, allow_inf_nan=False)] = 58.0
    vfov_deg: Annotated[float, Field(strict=True, gt=0, lt=180, allow_inf_nan=False)] = 45.0
    min_range: NonNegativeFloat = 0.5
    max_range: Range = 10.0
    native_width: ImageSide = 640
    baseline: PositiveFloat = 0.075
    disparity_sd: NonNegativeFloat = 0.07  # px
    disparity_step: NonNegativeFloat = 1 / 8  # px
    period: PositiveFloat = 1 / 30

    @model_validator(mode="after")
    def _consistent(self) -> DepthCameraParams:
        if self.width > self.native_width:
            raise ValueError(
                f"width must be at most native_width {self.native_width}, got {self.width}"
            )
        if self.min_range >= self.max_range:
            raise ValueError(
                f"min_range must be below max_range {self.max_range} m, got {self.min_range}"
            )
        return self

    @property
    def native_focal(self) -> float:
        return 0.5 * self.native_width / math.tan(math.radians(self.hfov_deg) / 2)

    def depth_step(self, z: float) -> float:
        """Quantisation step of the depth (m) at depth z."""
        return z * z * self.disparity_step / (self.native_focal * self.baseline)


# Body frame (x forward, y left, z up) -> optical frame (z forward, x right, y down).
_BODY_FROM_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


class DepthCamera:
    def __init__(self, params: DepthCameraParams, mount: Mount, seed: int) -> None:
        self.params, self.mount, self.rng = params, mount, Random(seed)

    def optical_pose(self, robot_pose) -> np.ndarray:
        m = self.mount.world(robot_pose)
        m[:3, :3] = m[:3, :3] @ _BODY_FROM_OPTICAL
        return m

    def intrinsics(self) -> tuple[float, float, float, float]:
        p = self.params
        fx = 0.5 * p.width / math.tan(math.radians(p.hfov_deg) / 2)
        fy = 0.5 * p.height / math.tan(math.radians(p.vfov_deg) / 2)
        return fx, fy, p.width / 2, p.height / 2

    def render(self, world, robot_pose, noise: bool = True) -> np.ndarray:
        """z-depth image (float32 metres, 0 = no measurement)."""
        depth = world.render_depth(self.optical_pose(robot_pose), *self.camera_args())
        return self.add_noise(depth) if noise else depth

    def camera_args(self) -> tuple:
        """(width, height, fx, fy, cx, cy, min_range, max_range), as the C++ core takes them."""
        p = self.params
        return (p.width, p.height, *self.intrinsics(), p.min_range, p.max_range)

    def add_noise(self, depth: np.ndarray) -> np.ndarray:
        p = self.params
        fb = p.native_focal * p.baseline
        valid = depth > 0
        disparity = np.where(valid, fb / np.where(valid, depth, 1.0), 0.0)
        disparity += p.disparity_sd * self.rng.normal(0.0, 1.0, depth.size).reshape(depth.shape)
        if p.disparity_step > 0:
            disparity = np.round(disparity / p.disparity_step) * p.disparity_step
        out = np.where(valid & (disparity > 0), fb / np.where(disparity > 0, disparity, 1.0), 0.0)
        out[(out < p.min_range) | (out >= p.max_range)] = 0.0
        return out.astype(np.float32)


@_params
class BearingParams:
    """A bearing sensor: the direction to another robot's marker (cooperative positioning,
    paper 001), horizontally (bearing, in the sensor's frame) and vertically (elevation above
    the horizontal plane; a levelled sensor).

    Attributes (value -- source):
        noise_sd_deg: 0.1 deg -- paper 001's simulation.
        elevation_noise_sd_deg: 0.1 deg -- taken equal to the bearing's (assumption).
        max_range: 20 m -- a camera finding a marker of a few centimetres (assumption); beyond
            it a robot is not seen.
        robot_radius: 0.3 m -- another robot hides what is behind it within this distance of
            its centre (about the size of the paper's robots; assumption).
    """

    noise_sd_deg: NonNegativeFloat = 0.1
    elevation_noise_sd_deg: NonNegativeFloat = 0.1
    max_range: Range = 20.0
    robot_radius: NonNegativeFloat = 0.3


@dataclass(frozen=True)
class BearingReadings:
    """One reading per target: bearing (rad, counter-clockwise in the sensor frame, wrapped to
    [-pi, pi)) and elevation (rad), NaN where the target is not seen; ``visible`` says which."""

    bearings: np.ndarray
    elevations: np.ndarray
    visible: np.ndarray


def _points(value, name: str, cols: int) -> np.ndarray:
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected numbers") from None
    a = a.reshape(1, cols) if a.shape == (cols,) else a
    if a.ndim != 2 or a.shape[1] != cols or not np.isfinite(a).all():
        raise ValueError(f"{name}: expected finite rows of {cols} numbers, got shape {a.shape}")
    return a


class BearingSensor:
    """Bearings and elevations from a sensor to other robots' markers, with line of sight:
    a target is seen when it is within ``max_range``, when no obstacle of the world lies on the
    straight line to it, and when no other robot's body (a vertical cylinder of
    ``robot_radius``) crosses that line. Gaussian noise on what is seen; one seeded stream.
    """

    def __init__(self, params: BearingParams | None = None, seed: int = 0) -> None:
        self.params = params if params is not None else BearingParams()
        self._rng = Random(check_seed(seed))

    def observe(self, sensor, targets, world=None, blockers=None) -> BearingReadings:
        """``sensor`` (x, y, z, yaw) in the world; ``targets`` (n, 3) marker points;
        ``world`` anything with ``cast_many(origins, directions, max_range)`` (a scene's world)
        or None; ``blockers`` (m, 2) centres of the robots that can hide a target (the observer
        and the target themselves are left out by distance)."""
        s = _points(sensor, "sensor", 4)[0]
        t = _points(targets, "targets", 3)
        b = np.zeros((0, 2)) if blockers is None else _points(blockers, "blockers", 2)
        p = self.params
        d = t - s[:3]
        dist = np.linalg.norm(d, axis=1)
        if np.any(dist < 1e-9):
            raise ValueError("targets: a target coincides with the sensor (no bearing)")
        visible = dist <= p.max_range
        if world is not None and len(t):
            unit = d / dist[:, None]
            hit = np.asarray(world.cast_many(np.tile(s[:3], (len(t), 1)), unit, p.max_range))
            visible &= hit >= dist - 0.05  # the marker itself may touch its robot's box
        if len(b) and len(t):
            a2 = s[:2]
            seg = t[:, :2] - a2  # (n, 2)
            for c in b:
                rel = c - a2
                lam = np.clip((seg @ rel) / np.maximum((seg**2).sum(1), 1e-12), 0.0, 1.0)
                gap = np.linalg.norm(rel - lam[:, None] * seg, axis=1)
                own = (np.linalg.norm(rel) < 1e-6) | (np.linalg.norm(t[:, :2] - c, axis=1) < 1e-6)
                visible &= ~((gap < p.robot_radius) & ~own)
        bearing = np.arctan2(d[:, 1], d[:, 0]) - s[3]
        elevation = np.arctan2(d[:, 2], np.hypot(d[:, 0], d[:, 1]))
        z = self._rng.normal(0.0, 1.0, 2 * len(t)).reshape(2, len(t))
        bearing = bearing + math.radians(p.noise_sd_deg) * z[0]
        elevation = elevation + math.radians(p.elevation_noise_sd_deg) * z[1]
        bearing = np.remainder(bearing + math.pi, 2 * math.pi) - math.pi
        return BearingReadings(
            np.where(visible, bearing, np.nan), np.where(visible, elevation, np.nan), visible
        )
