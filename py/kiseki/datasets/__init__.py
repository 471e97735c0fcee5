# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Readers for recorded robot data: CARMEN logs and the CMU Wean Hall map."""

from __future__ import annotations

from kiseki.datasets.carmen import CarmenLog, LaserScans, OdometryRecords, read_carmen_log
from kiseki.datasets.wean import WeanMap, read_wean_map

__all__ = [
    "CarmenLog",
    "LaserScans",
    "OdometryRecords",
    "WeanMap",
    "read_carmen_log",
    "read_wean_map",
]
