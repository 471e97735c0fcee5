# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The environment map M built while teaching (thesis sec. 3.4), with a choice of merge rule:

- ``thesis``: the thesis' rules. M unknown -> L's value; L free over M occupied -> free;
  L occupied over M free -> stays free. Whatever may move away is free, so one stray beam
  erases a wall for good.
- ``evidence`` (beyond the thesis): every M cell counts the local maps that saw it free and
  those whose beam ended in it; it is free only while its free observations outweigh its hits.
  The space behind an obstacle (occupied in L, no beam ended there) makes a cell occupied only
  while nothing else is known of it, as in the thesis. The output has the thesis' three states,
  so the space observation model reads either map alike.

`build_teaching_map` builds M from scans at known poses (recorded logs); teaching builds it
from depth images placed by odometry (`kiseki.apps.teach.teaching`).
"""

from __future__ import annotations

import numpy as np
from tqdm import tqdm

from kiseki import _core
from kiseki._support.real_numbers import check_number
from kiseki.grid import OccupancyGrid
from kiseki.mapping import check_map_poses, check_map_size, scan_local_builder

__all__ = ["MERGE_RULES", "EnvironmentMap", "build_teaching_map"]

MERGE_RULES = ("thesis", "evidence")


class EnvironmentMap:
    """M on the geometry of `frame` (its cells are not used), merged by `rule`."""

    def __init__(self, frame: OccupancyGrid, rule: str = "thesis") -> None:
        if rule not in MERGE_RULES:
            raise ValueError(f"merge rule must be one of {', '.join(MERGE_RULES)}, got {rule!r}")
        self.rule = rule
        if rule == "thesis":
            self._grid = _core.OccupancyGrid(
                frame.width, frame.height, frame.resolution, frame.origin
            )
        else:
            self._evidence = _core.EvidenceMap(frame)

    def merge(self, local: _core.LocalMapBuilder, pose: _core.Pose2) -> int:
        """Places the local map of `local` (a filled LocalMapBuilder) at `pose`; returns the
        number of M cells whose state changed."""
        if self.rule == "thesis":
            return _core.merge_local_map(self._grid, local.build(), pose)
        return self._evidence.merge(local, pose)

    def map(self) -> OccupancyGrid:
        """M in the thesis' three states (a copy)."""
        return self._grid.copy() if self.rule == "thesis" else self._evidence.map()


def build_teaching_map(
    poses: np.ndarray,
    ranges: np.ndarray,
    angles: np.ndarray,
    max_range: float,
    resolution: float = 0.1,
    local_size: float = 8.0,
    rule: str = "thesis",
    progress: bool = False,
) -> OccupancyGrid:
    """The environment map the space observation model is defined against (thesis sec. 3.4),
    from scans at known poses: each scan's local map (no-return beams left out, as in
    `kiseki.mapping.scan_local_map`) placed at its pose and merged by `rule`. Walls are as thin
    as single scans see them and the space behind them is occupied, unlike the log-odds map of
    `kiseki.mapping.build_map`. Refused: a resolution or local size that is not a finite number
    > 0 (a Python or numpy scalar), poses that `kiseki.mapping.check_map_poses` refuses (not
    finite, beyond +-1e9 m), ranges not one row per pose, poses spread over a map larger than
    `check_map_size` allows, and (by the local map, in its own words) a local size below the
    resolution or over 4096 cells across."""
    for name, value in (("resolution", resolution), ("local_size", local_size)):
        check_number(value, f"teaching map: {name}", 0.0, low_open=True, unit="m")
    poses = check_map_poses(poses)
    ranges = np.asarray(ranges)
    if ranges.ndim != 2 or ranges.shape[0] != poses.shape[0]:
        raise ValueError(f"ranges: expected ({poses.shape[0]}, beams), got shape {ranges.shape}")
    reach = local_size / np.sqrt(2.0) + resolution  # half the diagonal of a local map
    lo = poses[:, :2].min(axis=0) - reach
    hi = poses[:, :2].max(axis=0) + reach
    # kiseki's map limit (poses 2 km apart built a map of 4e8 cells past it)
    width, height = check_map_size(*(hi - lo), resolution)
    frame = _core.OccupancyGrid(int(width), int(height), resolution, _core.Pose2(lo[0], lo[1], 0))
    env = EnvironmentMap(frame, rule)
    for k in tqdm(range(len(poses)), desc="teaching map", disable=not progress, leave=False):
        local = scan_local_builder(angles, ranges[k], max_range, local_size, resolution)
        env.merge(local, _core.Pose2(*poses[k]))
    return env.map()
