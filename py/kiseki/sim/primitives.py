# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Scene primitives (walls, workbenches, shelves, rubble, ...) expanded into solid boxes.

Every primitive is an entry of a scene file's ``objects:``, checked by its model in
:mod:`kiseki.sim.primitives_schema` (lengths in metres, angles in degrees); the expanders here
build the boxes of a checked entry.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from os import PathLike
from typing import Any

import numpy as np

from kiseki._support.schema import parse
from kiseki.core import Random, rotation_zyx
from kiseki.sim.primitives_schema import (
    Beam,
    Box,
    ObjectEntry,
    ObjectModel,
    Pillar,
    Rubble,
    Shelf,
    Slope,
    Wall,
    Workbench,
)

__all__ = ["PRIMITIVES", "BoxList", "boxes_of", "expand", "rotation"]


@dataclass
class BoxList:
    """Boxes as arrays: centres (n, 3), half sizes (n, 3), rotations (n, 3, 3)."""

    centers: list
    half_sizes: list
    rotations: list

    @classmethod
    def empty(cls) -> BoxList:
        return cls([], [], [])

    def add(self, center, size, yaw=0.0, pitch=0.0, roll=0.0) -> None:
        self.centers.append(np.asarray(center, dtype=float))
        self.half_sizes.append(np.asarray(size, dtype=float) / 2)
        self.rotations.append(rotation(yaw, pitch, roll))

    def extend(self, other: BoxList) -> None:
        self.centers += other.centers
        self.half_sizes += other.half_sizes
        self.rotations += other.rotations

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = len(self.centers)
        return (
            np.reshape(self.centers, (n, 3)),
            np.reshape(self.half_sizes, (n, 3)),
            np.reshape(self.rotations, (n, 3, 3)),
        )


rotation = rotation_zyx
"""Rz(yaw) Ry(pitch) Rx(roll), radians (kiseki.core.rotation_zyx)."""


def _rad(deg: float) -> float:
    return math.radians(deg)


def _wall(o: Wall) -> BoxList:
    a, b = np.asarray(o.start), np.asarray(o.to)
    length = float(np.hypot(*(b - a)))
    out = BoxList.empty()
    mid = (a + b) / 2
    out.add(
        [mid[0], mid[1], o.z + o.height / 2],
        [length, o.thickness, o.height],
        math.atan2(*(b - a)[::-1]),
    )
    return out


def _box(o: Box) -> BoxList:
    out = BoxList.empty()
    size = np.asarray(o.size)
    if len(o.center) == 2:  # standing on the floor
        center = np.array([o.center[0], o.center[1], size[2] / 2])
    else:
        center = np.asarray(o.center)
    out.add(center, size, _rad(o.yaw), _rad(o.pitch), _rad(o.roll))
    return out


def _workbench(o: Workbench) -> BoxList:
    c, (length, width) = o.center, o.size
    height, top, leg = o.height, o.top_thickness, o.leg
    yaw = _rad(o.yaw)
    rot = rotation(yaw)[:2, :2]
    out = BoxList.empty()
    out.add([c[0], c[1], height - top / 2], [length, width, top], yaw)
    for sx in (-1, 1):
        for sy in (-1, 1):
            off = rot @ [sx * (length / 2 - leg / 2), sy * (width / 2 - leg / 2)]
            out.add(
                [c[0] + off[0], c[1] + off[1], (height - top) / 2], [leg, leg, height - top], yaw
            )
    return out


def _shelf(o: Shelf) -> BoxList:
    c, (length, depth) = o.center, o.size
    height, levels, items, post, board = o.height, o.levels, o.items, o.post, 0.02
    yaw = _rad(o.yaw)
    rot = rotation(yaw)[:2, :2]
    rng = Random(o.seed)
    out = BoxList.empty()

    def at(dx: float, dy: float, z: float, size) -> None:
        off = rot @ [dx, dy]
        out.add([c[0] + off[0], c[1] + off[1], z], size, yaw)

    for sx in (-1, 1):
        for sy in (-1, 1):
            at(sx * (length - post) / 2, sy * (depth - post) / 2, height / 2, [post, post, height])
    gap = height / levels
    for k in range(levels):
        z = 0.1 + k * gap
        at(0, 0, z, [length, depth, board])
        for _ in range(items if k < o.item_levels else 0):
            s = rng.uniform(0.1, min(0.4, gap * 0.8), 3)
            x = rng.uniform(-(length - s[0]) / 2, (length - s[0]) / 2, 1)[0]
            y = rng.uniform(-(depth - s[1]) / 2, (depth - s[1]) / 2, 1)[0]
            at(x, y, z + board / 2 + s[2] / 2, s)
    return out


def _slope(o: Slope) -> BoxList:
    c, (length, width), rise = o.center, o.size, o.rise
    pitch = math.atan2(rise, length)
    out = BoxList.empty()
    out.add(
        [c[0], c[1], rise / 2],
        [math.hypot(length, rise), width, o.thickness],
        _rad(o.yaw),
        -pitch,
    )
    return out


def _rubble(o: Rubble) -> BoxList:
    """A heap of slabs and blocks: random sizes and tilts, seeded."""
    c, radius, rng = o.center, o.radius, Random(o.seed)
    smin, smax = o.size_range
    max_tilt = _rad(o.max_tilt)
    out = BoxList.empty()
    for _ in range(o.count):
        r, a = radius * math.sqrt(rng.uniform(0, 1, 1)[0]), rng.uniform(-math.pi, math.pi, 1)[0]
        size = rng.uniform(smin, smax, 3)
        if rng.uniform(0, 1, 1)[0] < 0.5:  # a slab: thin in one dimension
            size[2] = max(0.02, size[2] / 5)
        yaw, pitch, roll = (
            rng.uniform(-math.pi, math.pi, 1)[0],
            *rng.uniform(-max_tilt, max_tilt, 2),
        )
        z = 0.5 * size[2] + 0.5 * max(size[0], size[1]) * abs(math.sin(max(abs(pitch), abs(roll))))
        out.add([c[0] + r * math.cos(a), c[1] + r * math.sin(a), z], size, yaw, pitch, roll)
    return out


def _beam(o: Beam) -> BoxList:
    a, b = np.asarray(o.start), np.asarray(o.to)
    width, height = o.size
    out = BoxList.empty()
    mid = (a + b) / 2
    out.add(
        [mid[0], mid[1], o.z],
        [float(np.hypot(*(b - a))), width, height],
        math.atan2(*(b - a)[::-1]),
    )
    return out


def _pillar(o: Pillar) -> BoxList:
    c, (sx, sy) = o.center, o.size
    out = BoxList.empty()
    out.add([c[0], c[1], o.height / 2], [sx, sy, o.height], _rad(o.yaw))
    return out


PRIMITIVES: dict[type[ObjectModel], Callable[[Any], BoxList]] = {
    Wall: _wall,
    Box: _box,
    Workbench: _workbench,
    Shelf: _shelf,
    Slope: _slope,
    Rubble: _rubble,
    Beam: _beam,
    Pillar: _pillar,
}


def boxes_of(obj: ObjectModel) -> BoxList:
    """The boxes of one checked object (a model of kiseki.sim.primitives_schema)."""
    return PRIMITIVES[type(obj)](obj)


def expand(spec: Any, source: str | PathLike[str], at: tuple[str | int, ...] = ()) -> BoxList:
    """The boxes of one primitive mapping; a SchemaError naming ``source`` and the path ``at``
    (``("objects", 3)``) when the mapping does not match its model."""
    return boxes_of(parse(ObjectEntry, spec, source, at=at).root)
