# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Readers for recorded robot data: CARMEN logs, kiseki's simulated runs (MCAP), and the CMU
Wean Hall map. ``open_scans`` gives the laser scans of any supported log through one interface."""

from __future__ import annotations

import os
from pathlib import Path

from kiseki.datasets.carmen import CarmenLog, LaserScans, OdometryRecords, read_carmen_log
from kiseki.datasets.wean import WeanMap, read_wean_map
from kiseki.datasets.wean_log import WeanLog, is_wean_log, read_wean_log

__all__ = [
    "open_scans",
    "CarmenLog",
    "LaserScans",
    "OdometryRecords",
    "WeanLog",
    "WeanMap",
    "is_wean_log",
    "read_carmen_log",
    "read_wean_log",
    "read_wean_map",
]


def open_scans(path: str | os.PathLike) -> LaserScans:
    """The laser scans of a log: a CARMEN log (.log, .log.gz, .clf), a kiseki run (.mcap,
    scans of /scan paired with /ground_truth and /odom) or a CMU Wean Hall robotdata log
    (recognised by its content: ``O``/``L`` lines; no reference poses)."""
    path = Path(path)
    if path.suffix.lower() == ".mcap":
        from kiseki.sim.mcap_log import read_run

        return read_run(path).laser_scans()
    if is_wean_log(path):
        return read_wean_log(path).scans
    return read_carmen_log(path).scans
