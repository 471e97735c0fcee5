# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Scene primitives (walls, workbenches, shelves, rubble, ...) expanded into solid boxes.

Every primitive is a mapping from a scene file. Lengths in metres, angles in degrees. Each
expander checks its keys and values and raises ValueError naming the object.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from kiseki.core import Random

__all__ = ["PRIMITIVES", "BoxList", "expand"]


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


def rotation(yaw: float, pitch: float = 0.0, roll: float = 0.0) -> np.ndarray:
    """Rz(yaw) Ry(pitch) Rx(roll), radians."""
    cz, sz, cy, sy, cx, sx = (f(a) for a in (yaw, pitch, roll) for f in (math.cos, math.sin))
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    return rz @ ry @ rx


class _Fields:
    """Typed access to one primitive's mapping, with errors that name the object."""

    def __init__(self, spec: dict, where: str, allowed: set[str]) -> None:
        unknown = sorted(set(spec) - allowed - {"type", "id", "only_in"})
        if unknown:
            raise ValueError(f"{where}: unknown key(s) {', '.join(unknown)}")
        self.spec, self.where = spec, where

    def vec(self, key: str, n: int, default=None, positive: bool = False) -> np.ndarray:
        value = self.spec.get(key, default)
        if value is None:
            raise ValueError(f"{self.where}: missing '{key}'")
        try:
            arr = np.asarray(value, dtype=float).reshape(-1)
        except (TypeError, ValueError):
            raise ValueError(f"{self.where}: '{key}' must be {n} numbers, got {value!r}") from None
        if arr.size != n or not np.isfinite(arr).all():
            raise ValueError(f"{self.where}: '{key}' must be {n} finite numbers, got {value!r}")
        if positive and (arr <= 0).any():
            raise ValueError(f"{self.where}: '{key}' must be positive, got {value!r}")
        return arr

    def num(self, key: str, default=None, positive: bool = False, minimum=None) -> float:
        value = self.vec(key, 1, None if default is None else [default], positive)[0]
        if minimum is not None and value < minimum:
            raise ValueError(f"{self.where}: '{key}' must be >= {minimum}, got {value}")
        return float(value)

    def int(self, key: str, default: int, minimum: int = 0, maximum: int | None = None) -> int:
        value = self.spec.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            raise ValueError(f"{self.where}: '{key}' must be an integer >= {minimum}")
        if maximum is not None and value > maximum:
            raise ValueError(f"{self.where}: '{key}' must be at most {maximum:,}, got {value:,}")
        return value


# Limits on what sizes a world (every box is ray cast by every sensor): a shelf of 50 boards and
# 100 items per board is far beyond a real one; a heap of 100,000 pieces is ten times the largest
# rubble scene.
MAX_SHELF_LEVELS = 50
MAX_SHELF_ITEMS = 100
MAX_RUBBLE_PIECES = 100_000


def _wall(f: _Fields) -> BoxList:
    a, b = f.vec("from", 2), f.vec("to", 2)
    length = float(np.hypot(*(b - a)))
    if length <= 0:
        raise ValueError(f"{f.where}: 'from' and 'to' must differ")
    height, thickness = f.num("height", 2.5, True), f.num("thickness", 0.1, True)
    z0 = f.num("z", 0.0)
    out = BoxList.empty()
    mid = (a + b) / 2
    out.add(
        [mid[0], mid[1], z0 + height / 2], [length, thickness, height], math.atan2(*(b - a)[::-1])
    )
    return out


def _box(f: _Fields) -> BoxList:
    out = BoxList.empty()
    size = f.vec("size", 3, positive=True)
    raw = f.spec.get("center")
    if isinstance(raw, list | tuple) and len(raw) == 2:  # standing on the floor
        xy = f.vec("center", 2)
        center = np.array([xy[0], xy[1], size[2] / 2])
    else:
        center = f.vec("center", 3)
    out.add(center, size, *(math.radians(f.num(k, 0.0)) for k in ("yaw", "pitch", "roll")))
    return out


def _workbench(f: _Fields) -> BoxList:
    c, (length, width) = f.vec("center", 2), f.vec("size", 2, positive=True)
    height, top = f.num("height", 0.85, True), f.num("top_thickness", 0.04, True)
    leg = f.num("leg", 0.05, True)
    if height > 1.5 or top >= height or 2 * leg >= min(length, width):
        raise ValueError(f"{f.where}: workbench proportions are impossible")
    yaw = math.radians(f.num("yaw", 0.0))
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


def _shelf(f: _Fields) -> BoxList:
    c, (length, depth) = f.vec("center", 2), f.vec("size", 2, positive=True)
    height, levels = f.num("height", 1.8, True), f.int("levels", 4, 1, MAX_SHELF_LEVELS)
    items, post, board = f.int("items", 0, 0, MAX_SHELF_ITEMS), f.num("post", 0.04, True), 0.02
    yaw = math.radians(f.num("yaw", 0.0))
    rot = rotation(yaw)[:2, :2]
    rng = Random(f.int("seed", 0))
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
        for _ in range(items if k < levels - 1 or levels == 1 else 0):
            s = rng.uniform(0.1, min(0.4, gap * 0.8), 3)
            x = rng.uniform(-(length - s[0]) / 2, (length - s[0]) / 2, 1)[0]
            y = rng.uniform(-(depth - s[1]) / 2, (depth - s[1]) / 2, 1)[0]
            at(x, y, z + board / 2 + s[2] / 2, s)
    return out


def _slope(f: _Fields) -> BoxList:
    c, (length, width) = f.vec("center", 2), f.vec("size", 2, positive=True)
    rise, thickness = f.num("rise", None, True), f.num("thickness", 0.05, True)
    pitch = math.atan2(rise, length)
    out = BoxList.empty()
    out.add(
        [c[0], c[1], rise / 2],
        [math.hypot(length, rise), width, thickness],
        math.radians(f.num("yaw", 0.0)),
        -pitch,
    )
    return out


def _rubble(f: _Fields) -> BoxList:
    """A heap of slabs and blocks: random sizes and tilts, seeded."""
    c, radius = f.vec("center", 2), f.num("radius", None, True)
    count, rng = f.int("count", 20, 1, MAX_RUBBLE_PIECES), Random(f.int("seed", 0))
    smin, smax = f.vec("size_range", 2, [0.1, 0.6], positive=True)
    if smin > smax:
        raise ValueError(f"{f.where}: size_range must be [min, max]")
    max_tilt = math.radians(f.num("max_tilt", 30.0, minimum=0.0))
    out = BoxList.empty()
    for _ in range(count):
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


def _beam(f: _Fields) -> BoxList:
    a, b = f.vec("from", 2), f.vec("to", 2)
    width, height = f.vec("size", 2, positive=True)
    out = BoxList.empty()
    mid = (a + b) / 2
    out.add(
        [mid[0], mid[1], f.num("z", None)],
        [float(np.hypot(*(b - a))), width, height],
        math.atan2(*(b - a)[::-1]),
    )
    return out


def _pillar(f: _Fields) -> BoxList:
    c, (sx, sy) = f.vec("center", 2), f.vec("size", 2, positive=True)
    height = f.num("height", 2.5, True)
    out = BoxList.empty()
    out.add([c[0], c[1], height / 2], [sx, sy, height], math.radians(f.num("yaw", 0.0)))
    return out


PRIMITIVES: dict[str, tuple[set[str], Callable[[_Fields], BoxList]]] = {
    "wall": ({"from", "to", "height", "thickness", "z"}, _wall),
    "partition": ({"from", "to", "height", "thickness", "z"}, _wall),
    "box": ({"center", "size", "yaw", "pitch", "roll"}, _box),
    "workbench": ({"center", "size", "height", "top_thickness", "leg", "yaw"}, _workbench),
    "shelf": ({"center", "size", "height", "levels", "items", "post", "yaw", "seed"}, _shelf),
    "slope": ({"center", "size", "rise", "thickness", "yaw"}, _slope),
    "rubble": ({"center", "radius", "count", "seed", "size_range", "max_tilt"}, _rubble),
    "beam": ({"from", "to", "size", "z"}, _beam),
    "pillar": ({"center", "size", "height", "yaw"}, _pillar),
}


def expand(spec: dict, where: str) -> BoxList:
    """The boxes of one primitive mapping."""
    if not isinstance(spec, dict) or "type" not in spec:
        raise ValueError(f"{where}: each object needs a 'type'")
    kind = spec["type"]
    if not isinstance(kind, str) or kind not in PRIMITIVES:  # a list is not hashable
        raise ValueError(f"{where}: unknown type {kind!r} (known: {', '.join(sorted(PRIMITIVES))})")
    allowed, expander = PRIMITIVES[kind]
    return expander(_Fields(spec, f"{where} ({kind})", allowed))
