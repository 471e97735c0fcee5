# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Local maps of the thesis' methods from the robot's depth cameras.

- ``plane``: one fixed-height plane, the depth pixels 0.39-0.41 m above the floor (the thesis'
  conventional method and proposal 1: the sensors at 0.4 m, horizontal row h = 0);
- ``band``: per column the nearest pixel 0.4-1.0 m above the floor (proposal 2).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from kiseki import _core

__all__ = ["BANDS", "METHODS", "LocalMapMaker", "local_map_scan"]

BANDS = {"plane": (0.39, 0.41), "band": (0.4, 1.0)}
# method -> (local map band, occlusion-aware expected map)
METHODS = {
    "conventional": ("plane", False),
    "proposal1": ("plane", True),
    "proposal2": ("band", False),
    "both": ("band", True),
}


class DepthCamera(Protocol):
    """What a local map needs of a depth camera (the simulator's ``DepthCamera`` or a real
    one): its image size (``params.width``, ``params.height``), its optical frame in the robot
    frame and the projection arguments of the C++ builder. The method takes the camera, it
    does not import the simulator."""

    params: Any

    def optical_pose(self, robot_pose: Any) -> np.ndarray: ...

    def camera_args(self) -> tuple: ...


@dataclass
class LocalMapMaker:
    """Builds the 8 m x 8 m, 0.1 m local map from depth images of the robot's cameras."""

    cameras: list[DepthCamera]
    band: str = "band"
    size: float = 8.0
    resolution: float = 0.1

    def __post_init__(self) -> None:
        if self.band not in BANDS:
            raise ValueError(f"band must be one of {', '.join(BANDS)}, got {self.band!r}")
        if not self.cameras:
            raise ValueError("local maps need at least one depth camera")

    def make(self, images: list[np.ndarray]):
        """The local map L of one set of depth images (one per camera)."""
        return self.builder(images).build()

    def builder(self, images: list[np.ndarray]) -> _core.LocalMapBuilder:
        """The builder filled with one set of depth images: `build()` is L, `hits()` the cells
        a beam ended in (for the evidence merge)."""
        if len(images) != len(self.cameras):
            raise ValueError(f"expected {len(self.cameras)} depth images, got {len(images)}")
        builder = _core.LocalMapBuilder(self.size, self.resolution)
        z_min, z_max = BANDS[self.band]
        for camera, depth in zip(self.cameras, images, strict=True):
            p = camera.params
            if depth.shape != (p.height, p.width):
                raise ValueError(
                    f"depth image is {depth.shape[1]} x {depth.shape[0]}, the camera "
                    f"gives {p.width} x {p.height}"
                )
            optical = camera.optical_pose((0.0, 0.0, 0.0))  # in the robot frame
            builder.add_depth_band(depth, optical, *camera.camera_args(), z_min, z_max)
        return builder


def local_map_scan(local, angles: np.ndarray, reach: float, scale: float = 1.0) -> np.ndarray:
    """The local map L (robot at its centre, L's origin at -reach) read as a scan: per angle,
    the range to the centre of the first occupied cell along the ray (where the beam that
    marked it ended, on average: a beam's end lies anywhere in its cell, so the cell's near face
    would read every range short by about half a cell), times ``scale`` (a range calibration);
    +inf (a no-return) where the ray meets none within reach."""
    ranges = local.cast_scans(np.zeros((1, 3)), angles, max_range=reach)[0]
    hit = ranges < reach
    res = local.resolution
    inside = ranges[hit] + 1e-6  # just past the face: in the occupied cell
    cx = np.floor((inside * np.cos(angles[hit]) + reach) / res)
    cy = np.floor((inside * np.sin(angles[hit]) + reach) / res)
    ranges[hit] = scale * np.hypot((cx + 0.5) * res - reach, (cy + 0.5) * res - reach)
    ranges[~hit] = np.inf
    return ranges.astype(np.float32)
