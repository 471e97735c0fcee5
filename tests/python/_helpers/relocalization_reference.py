# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A brute-force numpy reference of relocalization from one scan, shared by the matcher's tests
and the mcl-relocalization experiment's: every lattice pose of a small random map scored with
the likelihood field written out (Probabilistic Robotics, Table 6.3, with nav2's beam rule),
then the greedy selection of distinct poses."""

from __future__ import annotations

import math

import numpy as np

from kiseki.core import Pose2
from kiseki.filters import RelocalizeConfig
from kiseki.grid import OccupancyGrid

MAX_RANGE = 3.0


def random_case(seed: int):
    rng = np.random.default_rng(seed)
    h, w = rng.integers(14, 24, size=2)
    u = rng.random((h, w))
    cells = np.where(u < 0.12, 100, np.where(u < 0.17, -1, 0)).astype(np.int8)
    grid = OccupancyGrid(cells, 0.1, Pose2(*rng.uniform(-2, 2, 2), 0.0))
    n = int(rng.integers(20, 50))
    angles = np.sort(rng.uniform(-np.pi, np.pi, n))
    ranges = rng.uniform(0.1, 2.0, n).astype(np.float32)
    ranges[rng.random(n) < 0.1] = np.inf  # no return: skipped
    ranges[rng.random(n) < 0.05] = np.nan  # invalid: skipped
    return grid, angles, ranges


def brute_force(grid: OccupancyGrid, angles, ranges, config: RelocalizeConfig, headings: int):
    cells = np.asarray(grid.cells)
    h, w = cells.shape
    res = grid.resolution
    # distance from every cell centre to the nearest occupied cell centre, capped
    oy, ox = np.nonzero(cells >= 65)
    yy, xx = np.mgrid[0:h, 0:w]
    d = np.sqrt(((xx[..., None] - ox) ** 2 + (yy[..., None] - oy) ** 2).min(axis=-1)) * res
    s = config.sigma_hit

    def term(dist):
        g = np.exp(-(dist**2) / (2 * s * s)) / (math.sqrt(2 * math.pi) * s)
        return np.float32(np.log(config.z_hit * g + config.z_rand / MAX_RANGE))

    table = term(np.minimum(d, config.max_distance)).astype(np.float32)
    outside = term(np.float64(config.max_distance))
    # nav2's max_beams rule, then the readings that returned
    step = max(1, (len(angles) - 1) // (config.beams - 1)) if config.beams > 1 else 1
    a, r = angles[::step], ranges[::step].astype(np.float64)
    keep = (r > 0) & (r < MAX_RANGE)
    a, r = a[keep], r[keep]
    bx, by = r * np.cos(a) / res, r * np.sin(a) / res
    scores = np.empty((headings, h, w))
    for k in range(headings):
        th = k * 2 * math.pi / headings
        ex = np.floor(xx[..., None] + 0.5 + (math.cos(th) * bx - math.sin(th) * by)).astype(int)
        ey = np.floor(yy[..., None] + 0.5 + (math.sin(th) * bx + math.cos(th) * by)).astype(int)
        inside = (ex >= 0) & (ey >= 0) & (ex < w) & (ey < h)
        vals = np.where(inside, table[np.clip(ey, 0, h - 1), np.clip(ex, 0, w - 1)], outside)
        scores[k] = vals.astype(np.float64).sum(axis=-1)
    if config.free_only:  # the laser on known free cells (0..19) only
        scores[:, ~((cells >= 0) & (cells < 20))] = -np.inf
    order = np.lexsort((np.arange(scores.size), -scores.ravel()))
    taken = []
    for i in order:
        k, y, x = np.unravel_index(i, scores.shape)
        px = grid.origin.x + (x + 0.5) * res  # the origin has no yaw here
        py = grid.origin.y + (y + 0.5) * res
        th = math.remainder(k * 2 * math.pi / headings, 2 * math.pi)
        close = any(
            math.hypot(px - t[1], py - t[2]) < config.min_distance
            and abs(math.remainder(th - t[3], 2 * math.pi)) < config.min_angle
            for t in taken
        )
        if not close:
            taken.append((scores.ravel()[i], px, py, th, (int(x), int(y), int(k))))
        if len(taken) == config.hypotheses:
            break
    return scores, taken


def lattice_positions(grid: OccupancyGrid, headings: int, sensor=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(headings, h, w, 2) robot positions of the lattice poses: the laser at each cell centre
    (the origin has no yaw here) at heading k * 2 pi / headings, the robot behind it by the
    sensor's offset (robot = laser (+) sensor^-1)."""
    h, w = np.asarray(grid.cells).shape
    res = grid.resolution
    yy, xx = np.mgrid[0:h, 0:w]
    lx, ly = grid.origin.x + (xx + 0.5) * res, grid.origin.y + (yy + 0.5) * res
    out = np.empty((headings, h, w, 2))
    sx, sy, st = sensor
    for k in range(headings):
        robot_theta = k * 2 * math.pi / headings - st
        c, s = math.cos(robot_theta), math.sin(robot_theta)
        out[k, ..., 0] = lx - (c * sx - s * sy)
        out[k, ..., 1] = ly - (s * sx + c * sy)
    return out
