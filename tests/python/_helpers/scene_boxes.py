# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Which points lie on a scene's small objects, by brute force over its boxes: a reference for
the terrain tests' labels and plane removals."""

from __future__ import annotations

import numpy as np

from kiseki.sim.scene import load_scene


def near_small_boxes(scene_path, points: np.ndarray, margin: float) -> np.ndarray:
    """Whether each point (n, 3, world frame) lies within ``margin`` of a box standing on the
    floor below 1 m (the rubble heaps' pieces; not the floor slab or the walls)."""
    boxes = load_scene(scene_path).boxes
    near = np.zeros(len(points), dtype=bool)
    for c, h, r in zip(boxes.centers, boxes.half_sizes, boxes.rotations, strict=True):
        extent = np.abs(r) @ h
        if c[2] - extent[2] > -0.02 and c[2] + extent[2] < 1.0:
            local = (points - c) @ r  # r^T (p - c)
            near |= (np.abs(local) <= h + margin).all(axis=1)
    return near
