# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pedestrians of a scene: discs that stand at their start until their start time, then walk at
a constant velocity (and stop after a given distance). A scene's ``pedestrians:`` key lists
them as {name, radius (m, default 0.25), start: [x, y], velocity: [vx, vy] m/s, start_time: s
(default 0), stop_after: m travelled (optional)}, checked by kiseki.sim.scene_schema.

The 2-D lasers see them (:class:`DiscStamp` marks the cells whose centres lie within a disc in
the laser's ground-truth grid for one scan, then restores them), the collision check of
kiseki.sim.run counts them, and a run logs their positions on ``/pedestrians``.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

__all__ = ["PEDESTRIANS_SCHEMA", "DiscStamp", "Pedestrian"]

PEDESTRIANS_SCHEMA = {
    "type": "object",
    "title": "kiseki.Pedestrians",
    "properties": {
        "names": {"type": "array", "items": {"type": "string"}},
        "positions": {"type": "array", "description": "(x, y) m of each pedestrian"},
    },
}


def _finite(value, what: str, n: int = 1) -> tuple[float, ...]:
    items = value if n > 1 else [value]
    if (
        not isinstance(items, list | tuple)
        or len(items) != n
        or not all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in items)
        or not all(math.isfinite(v) for v in items)
    ):
        raise ValueError(f"{what} must be {n} finite number(s), got {value!r}")
    return tuple(float(v) for v in items)


@dataclass(frozen=True)
class Pedestrian:
    """A walking disc; change a field for a trial with ``dataclasses.replace`` (checked again)."""

    name: str
    start: tuple[float, float]
    velocity: tuple[float, float]
    radius: float = 0.25
    start_time: float = 0.0
    stop_after: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"a pedestrian needs a name, got {self.name!r}")
        object.__setattr__(self, "start", _finite(list(self.start), "start", 2))
        object.__setattr__(self, "velocity", _finite(list(self.velocity), "velocity", 2))
        (radius,) = _finite(self.radius, "radius")
        (start_time,) = _finite(self.start_time, "start_time")
        if radius <= 0 or start_time < 0:
            raise ValueError(f"radius must be > 0 and start_time >= 0, got {radius}, {start_time}")
        object.__setattr__(self, "radius", radius)
        object.__setattr__(self, "start_time", start_time)
        if self.stop_after is not None:
            (stop,) = _finite(self.stop_after, "stop_after")
            if stop < 0:
                raise ValueError(f"stop_after must be >= 0 m, got {stop}")
            object.__setattr__(self, "stop_after", stop)

    def position(self, t: float) -> tuple[float, float]:
        """(x, y) at time t: the start until start_time, then start + velocity * walking time,
        the walk ending after stop_after metres."""
        walked = max(0.0, t - self.start_time)
        speed = math.hypot(*self.velocity)
        if self.stop_after is not None and speed > 0:
            walked = min(walked, self.stop_after / speed)
        return (
            self.start[0] + self.velocity[0] * walked,
            self.start[1] + self.velocity[1] * walked,
        )


class DiscStamp:
    """Marks discs as occupied in a grid for the duration of a ``with`` block, touching only the
    cells whose centres lie within a disc, and restores those cells afterwards."""

    def __init__(self, grid, discs: list[tuple[float, float, float]]) -> None:
        self.grid, self.discs, self.saved = grid, discs, []

    def __enter__(self):
        g, cells = self.grid, self.grid.cells
        res, ox, oy = g.resolution, g.origin.x, g.origin.y
        for x, y, r in self.discs:
            i0, i1 = (int(math.floor((v - ox) / res)) for v in (x - r, x + r))
            j0, j1 = (int(math.floor((v - oy) / res)) for v in (y - r, y + r))
            i0, j0, i1, j1 = max(i0, 0), max(j0, 0), min(i1, g.width - 1), min(j1, g.height - 1)
            if i0 > i1 or j0 > j1:
                continue
            jj, ii = np.mgrid[j0 : j1 + 1, i0 : i1 + 1]
            near = np.hypot(ox + (ii + 0.5) * res - x, oy + (jj + 0.5) * res - y) <= r
            jj, ii = jj[near], ii[near]
            self.saved.append((jj, ii, cells[jj, ii].copy()))
            cells[jj, ii] = 100
        return self.grid

    def __exit__(self, *exc) -> None:
        cells = self.grid.cells
        for jj, ii, values in reversed(self.saved):
            cells[jj, ii] = values
        self.saved = []
