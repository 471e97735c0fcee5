# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Draws data/maps/factory_corridor.{yaml,pgm}: the straight factory corridor of the
teaching-and-playback thesis (P0 at x = 0, P1 at x = 7.4 m, P2 at x = 13.0 m, all on y = 0).

The thesis gives the waypoints, not the corridor's walls; the layout below (a 3.0 m wide
corridor with shelves, workbench footprints, a pillar and a 0.1 m partition) is an assumption
drawn from its photographs' description, at 0.05 m cells. Run: python scripts/make_demo_map.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import kiseki

RESOLUTION = 0.05
ORIGIN = (-1.5, -2.0)  # world coordinates of the map's lower-left corner
SIZE = (16.5, 4.0)  # metres

# Solid obstacles as (x_min, y_min, x_max, y_max) in metres.
OBSTACLES = [
    (-1.5, -2.0, 15.0, -1.5),  # south wall
    (-1.5, 1.5, 15.0, 2.0),  # north wall
    (-1.5, -2.0, -1.0, 2.0),  # west wall
    (14.5, -2.0, 15.0, 2.0),  # east wall
    (1.0, 0.9, 3.0, 1.5),  # shelf, north side
    (4.0, -1.5, 5.5, -0.9),  # workbench footprint, south side
    (8.5, 0.9, 10.5, 1.5),  # shelf, north side
    (9.0, -1.5, 9.3, -1.2),  # pillar
    (11.0, -1.5, 11.1, -0.5),  # thin 0.1 m partition
    (12.0, 1.0, 13.5, 1.5),  # workbench footprint, north side
]


def draw() -> kiseki.OccupancyGrid:
    width, height = (round(s / RESOLUTION) for s in SIZE)
    cells = np.zeros((height, width), dtype=np.int8)
    for x0, y0, x1, y1 in OBSTACLES:
        c0, r0 = round((x0 - ORIGIN[0]) / RESOLUTION), round((y0 - ORIGIN[1]) / RESOLUTION)
        c1, r1 = round((x1 - ORIGIN[0]) / RESOLUTION), round((y1 - ORIGIN[1]) / RESOLUTION)
        cells[r0:r1, c0:c1] = kiseki.OCCUPIED
    return kiseki.OccupancyGrid(cells, RESOLUTION, kiseki.Pose2(*ORIGIN, 0.0))


if __name__ == "__main__":
    out = Path(__file__).resolve().parents[1] / "data" / "maps" / "factory_corridor.yaml"
    print(kiseki.save_map(draw(), out))
