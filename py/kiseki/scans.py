# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Laser scans of one log, as kiseki's own type: what every log reader returns and what the
localization pipelines take.

:class:`LaserScans` is made by the readers of recorded data (``kiseki.datasets``: CARMEN logs,
the CMU Wean Hall logs) and by simulated runs (``kiseki.sim.mcap_log.SimRun.laser_scans``), so
a simulated run replays through the interface of a real log. It depends on numpy only: readers
and the simulator import it from here, not from one another.

Each reader's docstring says what its logs put in the fields (which pose is the laser's, whether
the odometry is raw, how ``max_range`` was found).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["LaserScans"]


@dataclass(frozen=True, eq=False)
class LaserScans:
    """Laser scans of one log, in file order."""

    times: np.ndarray  # (N,) float64 message timestamp, seconds
    poses: np.ndarray  # (N, 3) float64 laser pose in the log (x, y, theta); NaN if it has none
    odometry: np.ndarray  # (N, 3) float64 odometry pose as logged (see the reader's docstring)
    ranges: np.ndarray  # (N, B) float32 metres, C-contiguous
    angles: np.ndarray  # (B,) float64 beam angles in the laser frame, radians
    max_range: float  # readings >= max_range mean no return

    def __len__(self) -> int:
        return int(self.times.shape[0])

    def first(self, n: int) -> LaserScans:
        """The first n scans (all of them when n is 0 or at least the log's length)."""
        if n < 0:
            raise ValueError(f"first: n must be >= 0, got {n}")
        if not n or n >= len(self):
            return self
        return LaserScans(
            self.times[:n],
            self.poses[:n],
            self.odometry[:n],
            np.ascontiguousarray(self.ranges[:n]),
            self.angles,
            self.max_range,
        )

    @property
    def has_reference_poses(self) -> bool:
        """False for logs without reference poses (e.g. the Wean Hall logs: ``poses`` all NaN)."""
        return bool(np.isfinite(self.poses).all())
