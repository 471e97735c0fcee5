# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A robot's 6-DOF pose for one sweep of the rubble paper's tilting laser: position (x, y, z)
in metres and attitude (roll, pitch, yaw) in radians, world frame x, y horizontal, z up.

The attitude is set per move, as the paper does: (P-2) "ロボットを適当な距離だけ移動させ、設置した
物体に乗り上げることでロボットの姿勢を変化させ" (the robot is moved and climbs onto an object,
which changes its attitude), and the results give the motion and the attitude "x, y, z 軸周りに
それぞれ -2, -10, 15[deg]" (about the x, y and z axes: roll, pitch, yaw). :data:`PAPER_MOVES`
holds both environments' moves.

Or from the terrain (:func:`terrain_pose`): the scene's surface height is sampled under the four
corners of the footprint (rays cast straight down) and a plane z = a + g_u u + g_v v is fitted
to them by least squares, u along the heading and v to the left; the body's z axis is the
plane's normal, so pitch = -atan(g_u) and roll = atan2(g_v, sqrt(1 + g_u^2)), and z = a, the
plane's height under the centre. A rigid robot on a bump rests on three of its corners, not on
a plane through four: the fit is a smoothing approximation of a tracked robot's attitude.
The simulation loop (kiseki.sim.recorder) places each tilting-laser sweep at
:func:`resting_pose`: on the terrain under the planar robot, cast from the robot's height (the
planar robot drives only over what is lower than 5 cm, kiseki.sim.collisions.body_grid).

Rotation: R = Rz(yaw) Ry(pitch) Rx(roll) (kiseki.sim.primitives.rotation), right-handed, so a
positive pitch turns the nose down (x towards -z) and the paper's pitch of -10 deg, on climbing
onto an object, raises the nose.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.sim.primitives import rotation

__all__ = ["PAPER_MOVES", "Pose6", "attitude", "pose_matrix", "resting_pose", "terrain_pose"]


def pose_matrix(x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> np.ndarray:
    """The 4x4 pose (world from body) of a 6-DOF pose; angles in radians."""
    values = (x, y, z, roll, pitch, yaw)
    if not all(isinstance(v, numbers.Real) and math.isfinite(v) for v in values):
        raise ValueError(f"pose: expected finite x, y, z, roll, pitch, yaw, got {values}")
    m = np.eye(4)
    m[:3, :3] = rotation(yaw, pitch, roll)
    m[:3, 3] = [x, y, z]
    return m


def attitude(matrix) -> np.ndarray:
    """(roll, pitch, yaw) in radians of a rotation (3x3 or the top-left of a 4x4), the inverse
    of :func:`pose_matrix` for |pitch| < 90 deg."""
    m = np.asarray(matrix, dtype=float)
    if m.shape not in ((3, 3), (4, 4)) or not np.isfinite(m).all():
        raise ValueError(f"attitude: expected a finite 3x3 or 4x4 matrix, got shape {m.shape}")
    return np.array(
        [
            math.atan2(m[2, 1], m[2, 2]),
            -math.asin(max(-1.0, min(1.0, m[2, 0]))),
            math.atan2(m[1, 0], m[0, 0]),
        ]
    )


@dataclass(frozen=True)
class Pose6:
    """x, y, z in metres; roll, pitch, yaw in radians."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0

    def __post_init__(self) -> None:
        pose_matrix(*self.values)  # checks the numbers

    @classmethod
    def from_degrees(cls, x, y, z, roll_deg, pitch_deg, yaw_deg) -> Pose6:
        angles = (roll_deg, pitch_deg, yaw_deg)
        if not all(isinstance(v, numbers.Real) and math.isfinite(v) for v in angles):
            raise ValueError(f"pose: attitude must be 3 finite numbers (deg), got {angles}")
        return cls(x, y, z, *(math.radians(a) for a in angles))

    @property
    def values(self) -> tuple[float, float, float, float, float, float]:
        return (self.x, self.y, self.z, self.roll, self.pitch, self.yaw)

    def matrix(self) -> np.ndarray:
        return pose_matrix(*self.values)


PAPER_MOVES = {
    # section 7.3: environment A, true motion (35, 30, 5) cm, attitude (-2, -10, 15) deg
    "A": Pose6.from_degrees(0.35, 0.30, 0.05, -2.0, -10.0, 15.0),
    # environment B: the same motion, attitude (-2, -11, 22) deg
    "B": Pose6.from_degrees(0.35, 0.30, 0.05, -2.0, -11.0, 22.0),
}
"""The paper's moves from the first sweep's pose (the origin, level), per environment."""


def terrain_pose(world, x: float, y: float, yaw: float, length: float, width: float, from_z: float):
    """The :class:`Pose6` of a robot of footprint ``length`` x ``width`` (m) centred at (x, y)
    with heading ``yaw`` (rad), resting on the surface of ``world`` (anything with
    ``cast_many(origins, directions, max_range)``): rays are cast down from height ``from_z``
    (below any ceiling, above the ground) at the footprint's corners."""
    for name, value in (("x", x), ("y", y), ("yaw", yaw), ("from_z", from_z)):
        check_number(value, f"terrain_pose: {name}")
    for name, value in (("length", length), ("width", width)):  # the footprint
        check_number(value, f"terrain_pose: {name}", 0.0, low_open=True, unit="m")
    u = np.array([1.0, 1.0, -1.0, -1.0]) * length / 2
    v = np.array([1.0, -1.0, 1.0, -1.0]) * width / 2
    c, s = math.cos(yaw), math.sin(yaw)
    origins = np.stack([x + c * u - s * v, y + s * u + c * v, np.full(4, float(from_z))], axis=1)
    down = np.tile([0.0, 0.0, -1.0], (4, 1))
    reach = 1000.0
    r = np.asarray(world.cast_many(origins, down, reach), dtype=float)
    if not np.all(r < reach):
        missing = origins[r >= reach, :2].tolist()
        raise ValueError(f"terrain_pose: no ground under the footprint's corners {missing}")
    heights = from_z - r
    a, gu, gv = np.linalg.lstsq(np.stack([np.ones(4), u, v], axis=1), heights, rcond=None)[0]
    pitch = -math.atan(gu)
    roll = math.atan2(gv, math.sqrt(1.0 + gu * gu))
    return Pose6(float(x), float(y), float(a), roll, pitch, float(yaw))


def resting_pose(world, planar_pose, length: float, width: float, height: float) -> Pose6:
    """The 6-DOF pose of a planar robot (x, y, yaw) of footprint ``length`` x ``width`` and
    body ``height`` (m): :func:`terrain_pose` cast from ``height``, or level at z = 0 (the
    planar convention) when some corner has no ground under it (a scene without a floor)."""
    x, y, yaw = (float(v) for v in planar_pose)
    try:
        return terrain_pose(world, x, y, yaw, length, width, from_z=height)
    except ValueError as exc:
        if "no ground" not in str(exc):
            raise
        return Pose6(x, y, 0.0, 0.0, 0.0, yaw)
