# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Numpy references of paper 004's terms, written from the definitions, for the speed tests."""

from __future__ import annotations

import numpy as np


def reference_ratio(grid, pose, angles, ranges, max_range, half_angle, heading):
    """The definition of eq. 1 counted with numpy over every cell: free map cells within reach
    and +-half_angle of the heading; seen when the beam of nearest angle (inside the field of
    view) passes the cell's centre half a cell before its end, or has no return."""
    cells = grid.cells
    ys, xs = np.nonzero((cells >= 0) & (cells <= 25))
    res = grid.resolution
    cx = grid.origin.x + (xs + 0.5) * res
    cy = grid.origin.y + (ys + 0.5) * res
    dx, dy = cx - pose[0], cy - pose[1]
    rho = np.hypot(dx, dy)
    rel = np.arctan2(np.sin(np.arctan2(dy, dx) - heading), np.cos(np.arctan2(dy, dx) - heading))
    region = (rho <= max_range) & (np.abs(rel) <= half_angle + 1e-12)
    beta = np.arctan2(np.sin(np.arctan2(dy, dx) - pose[2]), np.cos(np.arctan2(dy, dx) - pose[2]))
    nearest = np.abs(beta[:, None] - angles[None, :]).argmin(axis=1)
    half_step = (angles[1] - angles[0]) / 2
    inside = (beta >= angles[0] - half_step) & (beta <= angles[-1] + half_step)
    r = ranges[nearest]
    seen = inside & ~np.isnan(r) & ((r >= max_range) | (rho <= r - res / 2))
    free = int(region.sum())
    return 1.0 if free == 0 else int((region & seen).sum()) / free


def reference_width(angles, ranges, max_range, heading, half_band=0.05):
    """The passage width by its definition (eq. 2, across the heading): hit points within
    half_band of the line across the heading through the sensor bound the passage left and
    right; a side without one counts max_range."""
    hit = np.isfinite(ranges) & (ranges < max_range)
    a, r = angles[hit] - heading, ranges[hit].astype(float)
    along, across = r * np.cos(a), r * np.sin(a)
    ahead = np.abs(along) <= half_band
    left = across[ahead & (across >= 0)]
    right = -across[ahead & (across < 0)]
    return (left.min() if left.size else max_range) + (right.min() if right.size else max_range)
