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
from dataclasses import dataclass

import numpy as np

from kiseki._support.real_numbers import check_number

__all__ = ["PEDESTRIANS_SCHEMA", "DiscStamp", "Pedestrian"]

PEDESTRIANS_SCHEMA = {
    "type": "object",
    "title": "kiseki.Pedestrians",
    "properties": {
        "names": {"type": "array", "items": {"type": "string"}},
        "positions": {"type": "array", "description": "(x, y) m of each pedestrian"},
    },
}


def _pair(value: list, what: str) -> tuple[float, float]:
    if len(value) != 2:
        raise ValueError(f"{what} must be 2 finite numbers, got {value!r}")
    return check_number(value[0], f"{what}[0]"), check_number(value[1], f"{what}[1]")


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
        object.__setattr__(self, "start", _pair(list(self.start), "start"))
        object.__setattr__(self, "velocity", _pair(list(self.velocity), "velocity"))
        radius = check_number(self.radius, "radius", 0.0, low_open=True, unit="m")
        start_time = check_number(self.start_time, "start_time", 0.0, unit="s")
        object.__setattr__(self, "radius", radius)
        object.__setattr__(self, "start_time", start_time)
        if self.stop_after is not None:
            stop = check_number(self.stop_after, "stop_after", 0.0, unit="m")
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
