# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The run log's names and message schemas: the size limits of a run and of a chunk, the
Foxglove protobuf messages a run holds (:data:`FOXGLOVE_MESSAGES`), kiseki's own JSON schemas
(odometry, velocities), and the run's warnings and errors."""

from __future__ import annotations

from typing import Any

from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.Grid_pb2 import Grid
from foxglove_schemas_protobuf.LaserScan_pb2 import LaserScan
from foxglove_schemas_protobuf.PoseInFrame_pb2 import PoseInFrame
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from google.protobuf.message import Message as ProtobufMessage

from kiseki._support.inputs import GIB, MIB
from kiseki.errors import LogFormatError

__all__ = [
    "DEFAULT_CHUNK_SIZE",
    "FOXGLOVE_MESSAGES",
    "MAX_CHUNK_BYTES",
    "MAX_RUN_BYTES",
    "MESSAGE_ENCODING",
    "MissingTopicError",
    "ODOMETRY_SCHEMA",
    "ODOMETRY_SCHEMA_NAME",
    "PROTOBUF",
    "SCHEMA_ENCODING",
    "TWIST_SCHEMA",
    "TWIST_SCHEMA_NAME",
    "TruncatedRunWarning",
]

DEFAULT_CHUNK_SIZE = 128 * 1024
MAX_RUN_BYTES = 4 * GIB
"""A run is read up to this size, in the file and decompressed: the reader holds every message
(a minute of a 640 x 480 depth camera at 10 Hz is 700 MB)."""
MAX_CHUNK_BYTES = 256 * MIB
"""One chunk decompresses to at most this (the ``mcap`` reader decompresses a chunk whole; kiseki
writes chunks of :data:`DEFAULT_CHUNK_SIZE`, other tools of a few MB)."""
SCHEMA_ENCODING = "jsonschema"  # kiseki's own messages
MESSAGE_ENCODING = "json"
PROTOBUF = "protobuf"  # Foxglove's messages: the schema and the message encoding
FOXGLOVE_MESSAGES: dict[str, type[ProtobufMessage]] = {
    cls.DESCRIPTOR.full_name: cls
    for cls in (PoseInFrame, FrameTransform, LaserScan, RawImage, Grid)
}  # the Foxglove messages RunWriter writes, by schema name: foxglove-schemas-protobuf classes


class TruncatedRunWarning(UserWarning):
    """:func:`read_run` read a file without its footer (a writer killed mid-run)."""


class MissingTopicError(LogFormatError, KeyError):
    """A run has no topic of that name: a KeyError for lookups, and a format error of the file
    (a ValueError naming it) for the commands that read it."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


# --- kiseki's own JSON schemas (no Foxglove message fits them) ---


def _time_schema(description: str) -> dict[str, Any]:
    return {
        "type": "object",
        "title": "time",
        "properties": {
            "sec": {"type": "integer", "minimum": 0},
            "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999},
        },
        "description": description,
    }


ODOMETRY_SCHEMA_NAME = "kiseki.Odometry2D"
ODOMETRY_SCHEMA: dict[str, Any] = {
    "title": ODOMETRY_SCHEMA_NAME,
    "description": "Planar odometry pose as the robot integrates it (not the true pose)",
    "type": "object",
    "properties": {
        "timestamp": _time_schema("Timestamp of the odometry reading"),
        "frame_id": {"type": "string", "description": "Odometry frame"},
        "x": {"type": "number", "description": "x position, metres"},
        "y": {"type": "number", "description": "y position, metres"},
        "theta": {"type": "number", "description": "heading, radians, counterclockwise"},
        "linear_velocity": {"type": "number", "description": "forward velocity, m/s"},
        "angular_velocity": {"type": "number", "description": "turn rate, rad/s"},
    },
    "required": ["timestamp", "x", "y", "theta"],
}

TWIST_SCHEMA_NAME = "kiseki.Twist"
TWIST_SCHEMA: dict[str, Any] = {
    "title": TWIST_SCHEMA_NAME,
    "description": "Planar body velocity (a command, /cmd_vel, or the robot's own, /velocity)",
    "type": "object",
    "properties": {
        "vx": {"type": "number", "description": "forward, m/s, body frame"},
        "vy": {"type": "number", "description": "left, m/s, body frame"},
        "w": {"type": "number", "description": "yaw rate, rad/s, counterclockwise"},
    },
    "required": ["vx", "vy", "w"],
}


# --- conversions and input checks ---
