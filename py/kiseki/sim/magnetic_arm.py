# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Two magnetometers on the bar of a 2-DOF arm: the 3-D magnetic-mapping robot of the thesis
(``002_74cea16d239c028f.txt``, sec. 6.4.2, Figs. 6.5-6.7). Its manipulator has a yaw and a
pitch joint and carries a wooden bar with two 3DM-DH sensors 60 cm apart (the 0.6 m spacing
that sec. 6.3.2 found sufficient); the arm moves continuously while the robot drives (sec.
6.6.2), and a 3-D volume is measured up to about 2 m.

Geometry. The joints sit at ``pivot`` (body frame: x forward, y left, z up, m). The bar points
along ``u = (cos p cos y, cos p sin y, sin p)`` for yaw ``y`` (counter-clockwise from the
body's x axis) and pitch ``p`` (up from the horizontal); the near sensor is ``inner`` m from the
pivot, the far one ``inner + sensors_apart`` m, so the two are always exactly
``sensors_apart`` apart. The pitch runs linearly (a triangle wave of ``period`` s) between the
angles at which the far sensor is at ``heights[0]`` and at ``heights[1]``: the far sensor spans
exactly that range and the near one a part of it. The yaw runs likewise between ``yaw_deg``
with ``yaw_period``, or stays put.

Readings are those of :class:`kiseki.sim.magnetic.Magnetometer` in each sensor's own frame,
which turns with the bar: the body frame turned by ``Rz(yaw) Ry(-pitch)`` (x along the bar),
then y and z flipped (x forward, y right, z down, the 3DM-DH convention). The magnitude, which
the thesis stores for its 3-D map (eq. 6.16), does not depend on that orientation.

Use (``world`` a :class:`~kiseki.sim.magnetic.MagneticWorld`, ``poses`` (n, 3) robot poses,
``times`` (n,) s)::

    arm = ArmMagnetometers(world, pivot=(0.4, 0.0, 1.05), inner=0.35, heights=(0.1, 2.0),
                           period=20.0, seed=7)
    xyz = arm.sensor_positions(poses, times)       # (n, 2, 3) world, [:, 0] near, [:, 1] far
    readings = arm.read_many(poses, times)         # (n, 2, 3) G, noisy, sensor frames

In a scene, each of the two sensors is a ``magnetometer`` whose ``mount`` is the pivot and
whose ``arm`` mapping gives the bar (``sensor: near`` or ``far``), see
:func:`arm_sensor_from_spec`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki._support.schema import SchemaError, parse
from kiseki.core import derive_seed
from kiseki.sim._values import finite_array as _finite_array
from kiseki.sim._values import poses as _poses
from kiseki.sim._values import times as _times
from kiseki.sim.magnetic import (
    DEFAULT_NOISE_SD,
    Dipole,
    MagneticWorld,
    Magnetometer,
    dipole_field,
)
from kiseki.sim.magnetic_schema import ArmSpec

__all__ = ["ARM_KEYS", "ArmMagnetometer", "ArmMagnetometers", "arm_sensor_from_spec"]

#: Keys of a scene sensor's ``arm`` mapping.
ARM_KEYS = tuple(ArmSpec.model_fields)
SENSOR_NAMES = ("near", "far")


def _triangle(u: np.ndarray) -> np.ndarray:
    """0 at whole u, 1 at half-integers, linear between: one sweep out and back per unit."""
    return 1.0 - np.abs(1.0 - 2.0 * (u - np.floor(u)))


class ArmMagnetometers:
    """The bar of the 2-DOF arm and its two magnetometers (see the module's docstring).

    ``world``: the field. ``pivot`` (3,) body frame, m. ``inner`` m > 0: pivot to the near
    sensor. ``sensors_apart`` m > 0 (thesis: 0.6). ``heights`` (zmin, zmax), m above the floor,
    zmin >= 0, each within ``inner + sensors_apart`` of the pivot's height. ``period`` s > 0:
    one pitch sweep up and back. ``yaw_deg`` (lo, hi) degrees about the mounting yaw
    ``mount_yaw`` (rad); ``yaw_period`` s, needed when lo != hi. ``noise_sd``, ``seed``,
    ``self_sources`` as :class:`~kiseki.sim.magnetic.Magnetometer`; sensor k draws its noise
    from ``derive_seed(seed, k)``; the robot's own sources are evaluated where each sensor is.
    """

    def __init__(
        self,
        world: MagneticWorld,
        pivot: Any = (0.4, 0.0, 1.05),
        inner: float = 0.35,
        sensors_apart: float = 0.6,
        heights: Any = (0.1, 2.0),
        period: float = 20.0,
        yaw_deg: Any = (0.0, 0.0),
        yaw_period: float | None = None,
        mount_yaw: float = 0.0,
        noise_sd: float = DEFAULT_NOISE_SD,
        seed: int = 0,
        self_sources: Iterable[Dipole] | None = None,
    ) -> None:
        self.pivot = _finite_array(pivot, (3,), "pivot")
        self.inner = check_number(inner, "inner", 0.0, low_open=True, unit="m")
        self.sensors_apart = check_number(
            sensors_apart, "sensors_apart", 0.0, low_open=True, unit="m"
        )
        self.reach = np.array([self.inner, self.inner + self.sensors_apart])
        zmin, zmax = _finite_array(heights, (2,), "heights")
        far = float(self.reach[1])
        if not 0.0 <= zmin < zmax:
            raise ValueError(f"heights: expected 0 <= zmin < zmax, got [{zmin}, {zmax}]")
        for z in (zmin, zmax):
            if abs(z - self.pivot[2]) > far + 1e-12:
                raise ValueError(
                    f"heights: {z} m is out of the bar's reach: the far sensor is {far} m from "
                    f"the pivot at height {self.pivot[2]} m"
                )
        self.heights = (float(zmin), float(zmax))
        self.pitch_range = tuple(
            math.asin(max(-1.0, min(1.0, (z - self.pivot[2]) / far))) for z in self.heights
        )
        self.period = check_number(period, "period", 0.0, low_open=True, unit="s")
        lo, hi = (math.radians(v) for v in _finite_array(yaw_deg, (2,), "yaw_deg"))
        if hi < lo:
            raise ValueError(f"yaw_deg: expected [lo, hi] with lo <= hi, got {yaw_deg!r}")
        self.yaw_range = (lo, hi)
        if lo != hi and yaw_period is None:
            raise ValueError("yaw_period: needed when the yaw sweeps (yaw_deg lo != hi)")
        self.yaw_period = (
            None
            if yaw_period is None
            else check_number(yaw_period, "yaw_period", 0.0, low_open=True, unit="s")
        )
        self.mount_yaw = check_number(mount_yaw, "mount_yaw")
        self.world = world
        self.sensors = tuple(
            ArmMagnetometer(self, k, noise_sd, derive_seed(seed, k), self_sources) for k in range(2)
        )

    def joint_angles(self, times: Any) -> tuple[np.ndarray, np.ndarray]:
        """(yaw (n,), pitch (n,)) rad at (n,) times s (yaw includes the mounting yaw)."""
        t = np.asarray(times, dtype=float).reshape(-1)
        if not np.isfinite(t).all():
            raise ValueError(f"times: must be finite, got {times!r}")
        p0, p1 = self.pitch_range
        pitch = p0 + (p1 - p0) * _triangle(t / self.period)
        y0, y1 = self.yaw_range
        sweep = _triangle(t / self.yaw_period) if self.yaw_period else np.zeros_like(t)
        return self.mount_yaw + y0 + (y1 - y0) * sweep, pitch

    def body_positions(self, times: Any) -> np.ndarray:
        """(n, 2, 3) body-frame positions of the near ([:, 0]) and far ([:, 1]) sensors."""
        yaw, pitch = self.joint_angles(times)
        cp = np.cos(pitch)
        u = np.column_stack([cp * np.cos(yaw), cp * np.sin(yaw), np.sin(pitch)])
        return self.pivot + self.reach[None, :, None] * u[:, None, :]

    def sensor_positions(self, poses: Any, times: Any) -> np.ndarray:
        """(n, 2, 3) world positions of both sensors for (n, 3) poses at (n,) times."""
        p, _ = _poses(poses)
        t = _times(times, p.shape[0])
        return np.stack([s.sensor_positions(p, t) for s in self.sensors], axis=1)

    def expected_many(self, poses: Any, times: Any) -> np.ndarray:
        """(n, 2, 3) noiseless readings, G, each in its sensor's frame."""
        return np.stack([s.expected_many(poses, times) for s in self.sensors], axis=1)

    def read_many(self, poses: Any, times: Any) -> np.ndarray:
        """(n, 2, 3) noisy readings, G; each sensor draws from its own stream."""
        return np.stack([s.read_many(poses, times) for s in self.sensors], axis=1)

    @classmethod
    def from_dict(
        cls, d: Mapping[str, Any], world: MagneticWorld, where: str = "arm", **kwargs: Any
    ) -> ArmMagnetometers:
        """From a scene's ``arm`` mapping (``inner``, ``sensors_apart`` (0.6), ``heights``,
        ``period``, ``yaw_deg`` ([0, 0]), ``yaw_period``; ``sensor`` is ignored here), checked
        by :class:`kiseki.sim.magnetic_schema.ArmSpec`; ``kwargs`` (pivot, mount_yaw, noise_sd,
        seed, self_sources) go to the constructor. ValueError naming ``where`` (``"FILE:
        key.path"`` of the mapping) and the key."""
        spec = _arm_spec(d, where)
        args = spec.model_dump(exclude={"sensor"}, exclude_unset=True)
        try:
            return cls(world, **args, **kwargs)
        except ValueError as exc:  # the reach of the bar from the pivot (kwargs)
            raise ValueError(f"{where}.{exc}") from None


def _arm_spec(d: Any, where: str) -> ArmSpec:
    """``d`` checked by ArmSpec; ``where`` is ``"FILE: key.path"`` (or just a path)."""
    source, sep, path = where.rpartition(": ")
    return parse(ArmSpec, d, source if sep else where, at=(path,) if sep else ())


class ArmMagnetometer(Magnetometer):
    """One sensor (``index`` 0 near, 1 far) of :class:`ArmMagnetometers`: a
    :class:`~kiseki.sim.magnetic.Magnetometer` whose position and axes follow the arm in time,
    so that ``read(pose, t)`` and ``read_many(poses, times)`` work as for a fixed sensor."""

    def __init__(
        self,
        arm: ArmMagnetometers,
        index: int,
        noise_sd: float = DEFAULT_NOISE_SD,
        seed: int = 0,
        self_sources: Iterable[Dipole] | None = None,
    ) -> None:
        if index not in (0, 1):
            raise ValueError(f"index: expected 0 (near) or 1 (far), got {index!r}")
        self.arm, self.index = arm, index
        start = arm.body_positions([0.0])[0, index]
        super().__init__(arm.world, start, 0.0, noise_sd, seed, self_sources)
        q = [s.position for s in self.self_sources]
        self._self = (
            np.reshape(q, (-1, 3)),
            np.reshape([s.moment for s in self.self_sources], (-1, 3)),
            np.array([s.radius for s in self.self_sources]),
        )

    def sensor_positions(self, poses: Any, times: Any = 0.0) -> np.ndarray:
        """World positions (n, 3) of this sensor for (n, 3) robot poses at (n,) times."""
        p, _ = _poses(poses)
        t = _times(times, p.shape[0])
        b = self.arm.body_positions(t)[:, self.index]
        c, s = np.cos(p[:, 2]), np.sin(p[:, 2])
        return np.column_stack(
            [p[:, 0] + c * b[:, 0] - s * b[:, 1], p[:, 1] + s * b[:, 0] + c * b[:, 1], b[:, 2]]
        )

    def expected_many(self, poses: Any, times: Any = 0.0) -> np.ndarray:
        """Noiseless readings (n, 3) G in this sensor's frame (it turns with the bar)."""
        p, _ = _poses(poses)
        t = _times(times, p.shape[0])
        b = self.world.field_at(self.sensor_positions(p, t), t)
        c, s = np.cos(p[:, 2]), np.sin(p[:, 2])
        body = np.column_stack([c * b[:, 0] + s * b[:, 1], -s * b[:, 0] + c * b[:, 1], b[:, 2]])
        if len(self._self[0]):
            body = body + dipole_field(self.arm.body_positions(t)[:, self.index], *self._self)
        yaw, pitch = self.arm.joint_angles(t)
        cy, sy, cp, sp = np.cos(yaw), np.sin(yaw), np.cos(pitch), np.sin(pitch)
        x1 = cy * body[:, 0] + sy * body[:, 1]  # Rz(yaw)^T
        y1 = -sy * body[:, 0] + cy * body[:, 1]
        xa, za = cp * x1 + sp * body[:, 2], -sp * x1 + cp * body[:, 2]  # Ry(-pitch)^T
        return np.column_stack([xa, -y1, -za])  # flip y (left -> right) and z (up -> down)


def arm_sensor_from_spec(
    spec: Mapping[str, Any],
    world: MagneticWorld,
    pivot: Any,
    mount_yaw: float = 0.0,
    seed: int = 0,
    where: str = "arm",
    **kwargs: Any,
) -> ArmMagnetometer:
    """The sensor a scene's magnetometer entry names in its ``arm`` mapping (``sensor: near``
    or ``far``), on the arm whose pivot is the entry's mount. ``kwargs``: noise_sd,
    self_sources."""
    name = _arm_spec(spec, where).sensor
    if name is None:
        raise SchemaError(f"{where}.sensor: missing (near or far)")
    arm = ArmMagnetometers.from_dict(
        spec, world, where, pivot=pivot, mount_yaw=mount_yaw, seed=seed, **kwargs
    )
    return arm.sensors[SENSOR_NAMES.index(name)]
