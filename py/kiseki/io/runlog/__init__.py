# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The run log: a robot's run in one MCAP file with Foxglove's protobuf messages (poses,
transforms, laser scans, depth images, the occupancy grid) and kiseki's own JSON messages
(odometry, velocities, magnetometer, commands). The simulator and the teaching and playback
runs write it; the commands, the dataset readers and the methods read it.

``from kiseki.io.runlog import RunWriter, read_run`` is the one import path; the names, their
schemas and limits are in `schemas`, writing in `writer`, reading in `reader` (which returns a
`run.SimRun`), what the writer and reader share in `_encoding`."""

from __future__ import annotations

from kiseki.io.runlog.reader import read_run
from kiseki.io.runlog.run import SimRun
from kiseki.io.runlog.schemas import (
    DEFAULT_CHUNK_SIZE,
    FOXGLOVE_MESSAGES,
    MAX_CHUNK_BYTES,
    MAX_RUN_BYTES,
    ODOMETRY_SCHEMA,
    ODOMETRY_SCHEMA_NAME,
    TWIST_SCHEMA,
    TWIST_SCHEMA_NAME,
    MissingTopicError,
    TruncatedRunWarning,
)
from kiseki.io.runlog.writer import RunWriter

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "FOXGLOVE_MESSAGES",
    "MAX_CHUNK_BYTES",
    "MAX_RUN_BYTES",
    "MissingTopicError",
    "ODOMETRY_SCHEMA",
    "ODOMETRY_SCHEMA_NAME",
    "TWIST_SCHEMA",
    "TWIST_SCHEMA_NAME",
    "RunWriter",
    "SimRun",
    "TruncatedRunWarning",
    "read_run",
]
