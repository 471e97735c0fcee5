# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A simulated 3-axis magnetometer on a planar, level robot (:class:`Magnetometer`), reading a
:class:`~kiseki.sim.magnetic_world.MagneticWorld` in its own frame (x forward, y right, z
down) with the robot's own parts as body-frame dipoles, and the magnetic azimuth of a reading
(:func:`magnetic_azimuth`). The facts behind it, the units and the frames are in
:mod:`kiseki.sim.magnetic`, which also gathers this module's names and the world's."""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.core import Random, check_seed, normalize_angle
from kiseki.sim._values import finite_array as _finite_array
from kiseki.sim._values import float_array as _float_array
from kiseki.sim._values import poses as _poses
from kiseki.sim._values import times as _times
from kiseki.sim.dipoles import Dipole
from kiseki.sim.magnetic_world import MagneticWorld

__all__ = [
    "DEFAULT_MOUNT",
    "DEFAULT_NOISE_SD",
    "ROBOT_SOURCE_MOMENT",
    "Magnetometer",
    "magnetic_azimuth",
    "robot_self_sources",
]

#: Magnetometer noise SD per axis, G: "the sensor's SD is about 0.01 G" (thesis ch. 6,
#: sec. 6.3.2, p. ~76, the 3DM-DH).
DEFAULT_NOISE_SD = 0.01
#: Mount of the magnetometer on the robot (body frame), m: the thesis' navigation robot carries
#: its 3DM-DH 0.50 m above the floor over the centre of the drive axle (sec. 3.3.1, Fig. 3.5).
DEFAULT_MOUNT = (0.0, 0.0, 0.5)

#: Moment of each of the robot's own sources (motor, battery, PC), A m^2. Chosen so that a
#: source changes the reading by more than the sensor noise (0.01 G) at 0.10 m in every
#: direction (equatorial field 1e-3 * 0.012 / 0.1^3 = 0.012 G), by less than the noise at
#: 0.15 m in every direction (axial 2e-3 * 0.012 / 0.15^3 = 0.0071 G) and by less than a tenth
#: of the noise at 0.30 m (axial 8.9e-4 G): "negligible beyond 10-15 cm for low-disturbance
#: devices" (thesis sec. 2.3, Fig. 2.6, p. 18). A dipole's field falls 27-fold from 0.1 to
#: 0.3 m and varies 2-fold with direction, so the moment must lie in (0.0100, 0.0135).
ROBOT_SOURCE_MOMENT = 0.012


def robot_self_sources(moment: float = ROBOT_SOURCE_MOMENT) -> list[Dipole]:
    """The robot's own motors, battery and PC as body-frame dipoles of strength ``moment``.

    Layout (an assumption; thesis Fig. 3.6 shows the parts but its drawing is not in the text):
    drive motors on the axle 0.2 m left and right at 0.1 m height (moments along the motor
    shafts, +-y), battery 0.15 m behind the axle at 0.15 m (moment along x), PC 0.1 m behind at
    0.3 m (moment up). With the default sensor mount (0, 0, 0.5) every source is at least 0.2 m
    from the sensor, as the thesis' robot keeps its sensor 20 cm from all electronics
    (sec. 3.3.1).
    """
    return [
        Dipole((0.0, 0.2, 0.1), (0.0, moment, 0.0)),
        Dipole((0.0, -0.2, 0.1), (0.0, -moment, 0.0)),
        Dipole((-0.15, 0.0, 0.15), (moment, 0.0, 0.0)),
        Dipole((-0.1, 0.0, 0.3), (0.0, 0.0, moment)),
    ]


class Magnetometer:
    """A 3-axis magnetometer on a planar, level robot; readings in G in the SENSOR frame
    (x forward, y right, z down).

    ``world``: the :class:`MagneticWorld`. ``mount``: sensor position in the body frame
    (x forward, y left, z up), m; default (0, 0, 0.5) (thesis sec. 3.3.1). ``yaw``: rotation of
    the sensor's x axis from the body's x axis, counter-clockwise seen from above, rad.
    ``noise_sd``: per-axis Gaussian noise SD, G; default 0.01 G (thesis ch. 6). ``seed``:
    seed of the sensor's own :class:`kiseki.core.Random` stream. ``self_sources``: the robot's
    own magnetic parts as body-frame :class:`Dipole` objects; None gives
    :func:`robot_self_sources`, ``[]`` none. They move and turn with the robot, so they add a
    constant offset in the sensor frame (a "hard-iron" bias).

    A reading is ``F Rz(yaw)^T (Rz(theta)^T B_world(p, t) + B_self) + noise`` with
    ``F = diag(1, -1, -1)`` and ``p`` the sensor's world position.
    """

    def __init__(
        self,
        world: MagneticWorld,
        mount: Any = DEFAULT_MOUNT,
        yaw: float = 0.0,
        noise_sd: float = DEFAULT_NOISE_SD,
        seed: int = 0,
        self_sources: Iterable[Dipole] | None = None,
    ) -> None:
        if not isinstance(world, MagneticWorld):
            raise ValueError(f"world: expected a MagneticWorld, got {type(world).__name__}")
        self.world = world
        self.mount = _finite_array(mount, (3,), "mount")
        self.yaw = check_number(yaw, "yaw")
        self.noise_sd = check_number(noise_sd, "noise_sd", 0.0, unit="G")
        self.seed = check_seed(seed)
        self.self_sources: tuple[Dipole, ...] = tuple(
            robot_self_sources() if self_sources is None else self_sources
        )
        for s in self.self_sources:
            if not isinstance(s, Dipole):
                raise ValueError(f"self_sources: expected Dipole objects, got {s!r}")
        self._rng = Random(self.seed)
        self.self_field = np.zeros(3)  # body frame, G
        for s in self.self_sources:
            self.self_field = self.self_field + s.field_at(self.mount)

    def sensor_positions(self, poses: Any) -> np.ndarray:
        """World positions (n, 3) of the sensor for (n, 3) robot poses."""
        p, _ = _poses(poses)
        c, s = np.cos(p[:, 2]), np.sin(p[:, 2])
        mx, my, mz = self.mount
        return np.column_stack(
            [p[:, 0] + c * mx - s * my, p[:, 1] + s * mx + c * my, np.full(len(p), mz)]
        )

    def expected_many(self, poses: Any, times: Any = 0.0) -> np.ndarray:
        """Noiseless readings (n, 3) G, sensor frame, for (n, 3) poses at (n,) times."""
        p, _ = _poses(poses)
        t = _times(times, p.shape[0])
        b = self.world.field_at(self.sensor_positions(p), t)
        c, s = np.cos(p[:, 2]), np.sin(p[:, 2])
        bx = c * b[:, 0] + s * b[:, 1] + self.self_field[0]  # world -> body
        by = -s * b[:, 0] + c * b[:, 1] + self.self_field[1]
        bz = b[:, 2] + self.self_field[2]
        cy, sy = math.cos(self.yaw), math.sin(self.yaw)
        # body -> yawed sensor axes, then flip y (left -> right) and z (up -> down)
        return np.column_stack([cy * bx + sy * by, -(-sy * bx + cy * by), -bz])

    def expected(self, robot_pose: Any, t: float = 0.0) -> np.ndarray:
        """Noiseless reading (3,) G for one pose (x, y, theta) (or a Pose2) at time ``t``."""
        p, single = _poses(robot_pose, "robot_pose")
        if not single:
            raise ValueError(f"robot_pose: expected (x, y, theta), got shape {p.shape}")
        return self.expected_many(p, t)[0]

    def read_many(self, poses: Any, times: Any = 0.0) -> np.ndarray:
        """Noisy readings (n, 3) G. Draws 3 n normals in row order, so it gives the same
        numbers as n successive :meth:`read` calls."""
        b = self.expected_many(poses, times)
        if self.noise_sd > 0 and b.size:
            b = b + self._rng.normal(0.0, self.noise_sd, b.size).reshape(b.shape)
        return b

    def read(self, robot_pose: Any, t: float = 0.0) -> np.ndarray:
        """Noisy reading (3,) G in the sensor frame for one pose (x, y, theta) at time ``t``."""
        p, single = _poses(robot_pose, "robot_pose")
        if not single:
            raise ValueError(f"robot_pose: expected (x, y, theta), got shape {p.shape}")
        return self.read_many(p, t)[0]


def magnetic_azimuth(reading: Any) -> float | np.ndarray:
    """Azimuth ``m_theta = atan2(m_y, m_x)`` of the horizontal field in the sensor frame, rad,
    wrapped to [-pi, pi): the angle from the sensor's x axis to magnetic north, positive
    towards the sensor's +y (to the right, clockwise seen from above).

    This is the thesis' yaw-plane magnetic azimuth (sec. 2.5, ch. 4-5) for a level sensor. With
    it, the world heading (counter-clockwise from east) of the sensor's x axis is
    ``alpha_N + m_theta``, where ``alpha_N`` is the world direction of the local horizontal
    field; so ``theta - m_theta`` depends on the place only, which is what the thesis stores in
    its map (``theta_m = theta - m_theta``, ch. 4-5). ``-m_theta`` is the compass heading
    (clockwise from magnetic north). (3,) gives a float, (n, 3) an (n,) array; a zero
    horizontal field gives 0.
    """
    a = _float_array(reading, "reading")
    single = a.shape == (3,)
    a = _finite_array(a.reshape(1, 3) if single else a, (None, 3), "reading")
    az = np.asarray(normalize_angle(np.arctan2(a[:, 1], a[:, 0])), dtype=float)
    return float(az[0]) if single else az
