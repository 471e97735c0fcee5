# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Simulated runs logged to MCAP with Foxglove's protobuf messages, read back as kiseki datasets.

Writing (:class:`RunWriter`)
    Foxglove's messages are protobuf (channel ``message_encoding`` ``"protobuf"``), with the
    classes and schemas Foxglove publishes in ``foxglove-schemas-protobuf``: each Schema record
    (encoding ``"protobuf"``) holds the message's ``FileDescriptorSet`` as ``mcap-protobuf-support``
    builds it, so Foxglove shows the run with no extra setup: ``foxglove.PoseInFrame`` (poses),
    ``foxglove.FrameTransform`` (the robot's ``base_link`` in ``world``, so the 3-D panel follows
    the robot), ``foxglove.LaserScan``, ``foxglove.RawImage`` (depth images, ``32FC1``
    little-endian metres, the raw bytes in ``data``) and ``foxglove.Grid`` (the occupancy map, one
    INT8 field ``occupancy`` in the ROS convention, row 0 at the grid origin); see
    :data:`FOXGLOVE_MESSAGES`. kiseki's own messages (odometry, magnetometer, bearings, commands),
    which no Foxglove message fits, stay JSON (``"json"`` channels, ``"jsonschema"`` schemas; an
    MCAP file can mix encodings) and go through :meth:`RunWriter.write_json` with a schema given
    by the caller; :meth:`RunWriter.write_odometry` writes ``kiseki.Odometry2D``
    (:data:`ODOMETRY_SCHEMA`); velocities are ``kiseki.Twist`` (:data:`TWIST_SCHEMA`, read back by
    :meth:`SimRun.velocities`). Each schema and each channel is registered once, on the first
    message of its name/topic; a topic keeps its schema.

    Times are seconds (float, >= 0, any order) stored as nanoseconds in ``log_time``,
    ``publish_time`` and the message ``timestamp``. A laser topic's ``max_range`` (readings
    >= ``max_range`` mean no return; ``+inf`` is written as ``max_range``) lives in the channel
    metadata, since ``foxglove.LaserScan`` has no such field.

    The file is written as the run goes, in zstd-compressed chunks of ``chunk_size`` bytes
    (128 KiB by default); a chunk reaches the operating system as soon as it is full. A process
    that is killed therefore leaves a file holding every complete chunk (the last, partial chunk
    and the summary section are lost), which :func:`read_run` reads. The operating system still
    holds the data in its cache, so a power cut can lose more. :meth:`RunWriter.close` (or
    leaving the ``with`` block, also through an exception) writes the last chunk and the summary.

Reading (:func:`read_run`)
    The file is read from the start, record by record, without relying on the summary section:
    first the record framing is checked (opcode + length of each record) to find the end of the
    last complete record, then the complete records are parsed with the ``mcap`` stream reader
    (chunk CRCs checked). A file without its footer is a truncated file: :func:`read_run` warns
    (:class:`TruncatedRunWarning`) and returns the messages of the complete chunks, with
    ``SimRun.truncated`` set. For reference, the ``mcap`` 1.6 library itself does not read such a
    file: ``make_reader(...).iter_messages()`` needs the footer and fails (``EndOfFile``,
    ``RecordLengthLimitExceeded`` or ``OSError`` depending on the cut), and its
    ``NonSeekingReader`` yields the messages of the complete chunks before raising
    (``EndOfFile`` or ``struct.error``). A file that is not an MCAP, that was cut before its
    Header record, or whose complete records do not parse (bad CRC, bad JSON, ...) raises
    :class:`~kiseki.errors.LogFormatError` naming the file.

    Messages are decoded by their channel's message encoding: ``protobuf`` (the runs written now)
    and ``json`` (runs written before kiseki used protobuf, whose images and grids hold base64
    text) both read to the same scans, poses, images and grids.

    :meth:`SimRun.laser_scans` returns the same :class:`~kiseki.scans.LaserScans` as
    the CARMEN reader, so simulated runs replay through the interface of real logs.
"""

from __future__ import annotations

import base64
import io
import json
import math
import os
import struct
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from types import TracebackType
from typing import IO, Any

import numpy as np
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.Grid_pb2 import Grid
from foxglove_schemas_protobuf.LaserScan_pb2 import LaserScan
from foxglove_schemas_protobuf.PackedElementField_pb2 import PackedElementField
from foxglove_schemas_protobuf.PoseInFrame_pb2 import PoseInFrame
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.message import DecodeError
from google.protobuf.message import Message as ProtobufMessage
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.records import Channel, Header, Message, Metadata, Schema, Statistics
from mcap.stream_reader import StreamReader
from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer
from mcap_protobuf.decoder import DecoderFactory
from mcap_protobuf.schema import build_file_descriptor_set

from kiseki._chunk_limits import check_mcap_chunks
from kiseki._inputs import GIB, MIB, check_input
from kiseki._signal_hold import SignalHold
from kiseki.core import Pose2
from kiseki.errors import LogFormatError
from kiseki.grid import OccupancyGrid
from kiseki.scans import LaserScans, apply_range_rule, check_odometry_jumps, largest_reading

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
_MAGIC = b"\x89MCAP0\r\n"
_NS_PER_S = 1_000_000_000
_MAX_NS = 2**64 - 1
_METADATA_NAME = "kiseki.run"
_MAX_RANGE_KEY = "max_range"
_INT8 = 2  # foxglove.NumericType INT8
_UINT8 = 1
_COMPRESSIONS = {
    "zstd": CompressionType.ZSTD,
    "lz4": CompressionType.LZ4,
    "none": CompressionType.NONE,
}
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


def _time_ns(t: float) -> int:
    try:
        value = float(t)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"time must be a number of seconds, got {t!r}") from exc
    if not math.isfinite(value) or value < 0:
        raise ValueError(f"time must be finite and >= 0 seconds, got {value}")
    ns = round(Fraction(value) * _NS_PER_S)  # the nearest nanosecond, exactly
    if ns > _MAX_NS:
        raise ValueError(f"time {value} s does not fit in 64-bit nanoseconds")
    return ns


def _stamp(ns: int) -> dict[str, int]:
    sec, nsec = divmod(ns, _NS_PER_S)
    return {"sec": sec, "nsec": nsec}


def _yaw_quaternion(theta: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(theta / 2), math.cos(theta / 2))


def _quaternion_yaw(x: float, y: float, z: float, w: float) -> float:
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _pose7(pose: Any, what: str = "pose") -> tuple[float, ...]:
    """(x, y, z, qx, qy, qz, qw) from (x, y, theta), (x, y, z, qx, qy, qz, qw) or a Pose2."""
    if all(hasattr(pose, a) for a in ("x", "y", "theta")):
        values = np.array([pose.x, pose.y, pose.theta], dtype=np.float64)
    else:
        try:
            values = np.asarray(pose, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{what} must be numbers, got {pose!r}") from exc
    if values.shape not in ((3,), (7,)):
        raise ValueError(
            f"{what} must be (x, y, theta) or (x, y, z, qx, qy, qz, qw), got shape {values.shape}"
        )
    if not np.all(np.isfinite(values)):
        raise ValueError(f"{what} has NaN or infinite values: {values.tolist()}")
    if values.shape == (3,):
        x, y, theta = values.tolist()
        return (x, y, 0.0, *_yaw_quaternion(theta))
    norm = float(np.linalg.norm(values[3:]))
    if abs(norm - 1.0) > 1e-6:
        raise ValueError(f"{what} quaternion must have unit norm, got norm {norm}")
    return tuple(values.tolist())


def _set_pose(pose: Any, pose7: Sequence[float]) -> None:
    """Fills a foxglove.Pose (protobuf) from (x, y, z, qx, qy, qz, qw)."""
    p, q = pose.position, pose.orientation
    p.x, p.y, p.z, q.x, q.y, q.z, q.w = pose7


_SCHEMA_DATA: dict[str, bytes] = {}


def _protobuf_schema(name: str) -> bytes:
    """The serialized FileDescriptorSet of a Foxglove message (built once)."""
    data = _SCHEMA_DATA.get(name)
    if data is None:
        data = build_file_descriptor_set(FOXGLOVE_MESSAGES[name]).SerializeToString()
        _SCHEMA_DATA[name] = data
    return data


_TIMESTAMP = "google.protobuf.Timestamp"
_FIELDS: dict[str, list[tuple[str, int]]] = {}  # message name -> (field, kind)
_SCALAR, _REPEATED, _MESSAGE, _MESSAGES, _STAMP = range(5)


def _fields(descriptor: Any) -> list[tuple[str, int]]:
    kinds = _FIELDS.get(descriptor.full_name)
    if kinds is None:
        kinds = []
        for f in descriptor.fields:
            nested = f.type == FieldDescriptor.TYPE_MESSAGE
            # protobuf >= 5.29 has is_repeated; 7 has no label
            repeated = f.is_repeated if hasattr(f, "is_repeated") else f.label == f.LABEL_REPEATED
            if repeated:
                kinds.append((f.name, _MESSAGES if nested else _REPEATED))
            elif nested:
                stamp = f.message_type.full_name == _TIMESTAMP
                kinds.append((f.name, _STAMP if stamp else _MESSAGE))
            else:
                kinds.append((f.name, _SCALAR))
        _FIELDS[descriptor.full_name] = kinds
    return kinds


def _as_dict(message: Any) -> dict[str, Any]:
    """A protobuf message as a dict of the JSON layout: timestamps {"sec", "nsec"}, nested
    messages as dicts, enums as ints, bytes as bytes, repeated numbers as protobuf's own
    (read-only) sequence, which numpy reads at once."""
    out: dict[str, Any] = {}
    for name, kind in _fields(message.DESCRIPTOR):
        value = getattr(message, name)
        if kind == _STAMP:
            out[name] = {"sec": value.seconds, "nsec": value.nanos}
        elif kind == _MESSAGE:
            out[name] = _as_dict(value)
        elif kind == _MESSAGES:
            out[name] = [_as_dict(v) for v in value]
        else:
            out[name] = value
    return out


def _payload_bytes(value: Any) -> bytes:
    """A bytes field: raw bytes (protobuf) or base64 text (older JSON runs)."""
    if isinstance(value, bytes):
        return value
    if not isinstance(value, str):
        raise TypeError(f"data must be bytes or base64 text, got {type(value).__name__}")
    return base64.b64decode(value, validate=True)


def _name(value: str, what: str) -> str:
    if not isinstance(value, str) or not value:
        raise ValueError(f"{what} must be a non-empty string, got {value!r}")
    return value


def _json_default(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def _dumps(payload: Any) -> bytes:
    return json.dumps(
        payload, separators=(",", ":"), allow_nan=False, default=_json_default
    ).encode("utf-8")


# --- writer ---


class RunWriter:
    """Writes one simulated run to an MCAP file as the run goes (see the module docstring).

    ``path`` must not exist unless ``overwrite`` is true (FileExistsError). ``metadata`` goes
    in a Metadata record named ``kiseki.run`` right after the header, so it survives a kill.
    """

    def __init__(
        self,
        path: str | os.PathLike,
        metadata: Mapping[str, str] | None = None,
        *,
        overwrite: bool = False,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
        compression: str = "zstd",
    ) -> None:
        self.path = Path(path)
        if isinstance(chunk_size, bool) or not isinstance(chunk_size, int) or chunk_size < 1:
            raise ValueError(f"chunk_size must be a positive integer of bytes, got {chunk_size!r}")
        if compression not in _COMPRESSIONS:
            raise ValueError(
                f"compression must be one of {sorted(_COMPRESSIONS)}, got {compression!r}"
            )
        meta = dict(metadata or {})
        for key, value in meta.items():
            if not isinstance(key, str) or not isinstance(value, str):
                raise ValueError(
                    f"metadata keys and values must be strings, got {key!r}: {value!r}"
                )
        try:
            self._file: IO[bytes] | None = open(self.path, "wb" if overwrite else "xb")  # noqa: SIM115
        except FileExistsError as exc:
            raise FileExistsError(
                f"{self.path}: file exists; pass overwrite=True to replace it"
            ) from exc
        try:
            self._writer = Writer(
                self._file, chunk_size=chunk_size, compression=_COMPRESSIONS[compression]
            )
            self._writer.start(profile="", library=f"kiseki; {LIBRARY_IDENTIFIER}")
            if meta:
                self._writer.add_metadata(_METADATA_NAME, meta)
            self._file.flush()
        except BaseException:
            self._file.close()
            raise
        self._schemas: dict[str, tuple[int, bytes]] = {}  # name -> (id, schema text)
        self._channels: dict[str, tuple[int, str, dict[str, str]]] = {}  # topic -> (id, schema)
        self._sequence: dict[int, int] = {}
        # Ctrl-C and SIGTERM wait for the record being written (kiseki._signal_hold)
        self._hold = SignalHold()

    # context manager

    def __enter__(self) -> RunWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    @property
    def closed(self) -> bool:
        return self._file is None

    def close(self) -> None:
        """Writes the last chunk and the summary section, then closes the file (idempotent)."""
        if self._file is None:
            return
        file, self._file = self._file, None
        try:
            with self._hold.section():
                try:
                    self._writer.finish()
                finally:
                    file.close()
        finally:
            self._hold.release()

    # registration

    def _channel(
        self,
        topic: str,
        schema_name: str,
        schema: Mapping[str, Any] | None,
        channel_metadata: dict[str, str] | None = None,
    ) -> int:
        """The channel of ``topic``: JSON with the JSON schema ``schema``, or (``schema`` None)
        the Foxglove protobuf message ``schema_name``."""
        if self._file is None:
            raise ValueError(f"{self.path}: the run writer is closed")
        _name(topic, "topic")
        _name(schema_name, "schema name")
        known = self._channels.get(topic)
        if known is not None:
            channel_id, known_schema, known_meta = known
            if known_schema != schema_name:
                raise ValueError(
                    f"topic {topic!r} carries {known_schema} messages, not {schema_name}"
                )
            if channel_metadata is not None and channel_metadata != known_meta:
                raise ValueError(
                    f"topic {topic!r} was registered with channel metadata {known_meta},"
                    f" not {channel_metadata}"
                )
            return channel_id
        if schema is None:
            schema_encoding, encoding = PROTOBUF, PROTOBUF
            text = _protobuf_schema(schema_name)
        elif isinstance(schema, Mapping):
            schema_encoding, encoding = SCHEMA_ENCODING, MESSAGE_ENCODING
            text = json.dumps(schema, indent=2, allow_nan=False).encode("utf-8")
        else:
            raise ValueError(f"schema of {schema_name} must be a dict (a JSON schema)")
        if schema_name in self._schemas:
            schema_id, known_text = self._schemas[schema_name]
            if known_text != text:
                raise ValueError(f"schema {schema_name} was registered with a different text")
        else:
            with self._hold.section():
                schema_id = self._writer.register_schema(schema_name, schema_encoding, text)
                self._schemas[schema_name] = (schema_id, text)
        meta = dict(channel_metadata or {})
        with self._hold.section():
            channel_id = self._writer.register_channel(topic, encoding, schema_id, meta)
            self._channels[topic] = (channel_id, schema_name, meta)
            self._sequence[channel_id] = 0
        return channel_id

    def _write(self, channel_id: int, ns: int, data: bytes) -> None:
        assert self._file is not None
        with self._hold.section():  # Ctrl-C or SIGTERM then stop the run between two messages
            self._sequence[channel_id] += 1
            self._writer.add_message(
                channel_id,
                log_time=ns,
                data=data,
                publish_time=ns,
                sequence=self._sequence[channel_id] & 0xFFFFFFFF,
            )
            # The mcap writer hands bytes to the file only when a chunk is full; pass them on
            # to the operating system at once so that a killed process keeps every complete
            # chunk.
            self._file.flush()

    def _foxglove(
        self, topic: str, ns: int, message: Any, meta: dict[str, str] | None = None
    ) -> None:
        """Writes a Foxglove protobuf message on ``topic``, its ``timestamp`` set to ``ns``."""
        channel = self._channel(topic, message.DESCRIPTOR.full_name, None, meta)
        message.timestamp.seconds, message.timestamp.nanos = divmod(ns, _NS_PER_S)
        self._write(channel, ns, message.SerializeToString())

    # messages

    def write_pose(self, topic: str, t: float, pose: Any, frame_id: str = "world") -> None:
        """``foxglove.PoseInFrame``: pose is (x, y, theta), (x, y, z, qx, qy, qz, qw) or a
        ``kiseki.Pose2``, in ``frame_id``."""
        ns = _time_ns(t)
        pose7 = _pose7(pose)
        _name(frame_id, "frame_id")
        message = PoseInFrame(frame_id=frame_id)
        _set_pose(message.pose, pose7)
        self._foxglove(topic, ns, message)

    def write_transform(
        self, t: float, parent: str, child: str, pose: Any, topic: str = "/tf"
    ) -> None:
        """``foxglove.FrameTransform``: the pose of frame ``child`` in frame ``parent`` (e.g. the
        robot's ``base_link`` in ``world``)."""
        ns = _time_ns(t)
        x, y, z, qx, qy, qz, qw = _pose7(pose)
        _name(parent, "parent frame")
        _name(child, "child frame")
        if parent == child:
            raise ValueError(f"a transform needs two different frames, got {parent!r} twice")
        message = FrameTransform(parent_frame_id=parent, child_frame_id=child)
        shift, turn = message.translation, message.rotation
        shift.x, shift.y, shift.z, turn.x, turn.y, turn.z, turn.w = x, y, z, qx, qy, qz, qw
        self._foxglove(topic, ns, message)

    def write_laser_scan(
        self,
        topic: str,
        t: float,
        sensor_pose: Any,
        angles: Sequence[float] | np.ndarray,
        ranges: Sequence[float] | np.ndarray,
        frame_id: str = "world",
        *,
        intensities: Sequence[float] | np.ndarray | None = None,
        max_range: float | None = None,
    ) -> None:
        """``foxglove.LaserScan``: ``sensor_pose`` (x, y, theta) is the laser's pose in
        ``frame_id``; ``angles`` (B,) are evenly spaced beam angles in the laser frame (to 1e-6
        rad) and ``ranges`` (B,) metres, stored as float32 values. ``max_range`` (fixed per
        topic, kept in the channel metadata) is the no-return reading; ``+inf`` readings are
        written as ``max_range`` and need it. Invalid readings (NaN, ``-inf``, negative, zero:
        kiseki's rule, ``kiseki.scans``) are written as NaN."""
        ns = _time_ns(t)
        pose7 = _pose7(sensor_pose, "sensor pose")
        _name(frame_id, "frame_id")
        beam = np.asarray(angles, dtype=np.float64)
        if beam.ndim != 1 or beam.size < 1:
            raise ValueError(f"angles must be a non-empty 1-D array, got shape {beam.shape}")
        if not np.all(np.isfinite(beam)):
            raise ValueError("angles have NaN or infinite values")
        if beam.size >= 2:
            even = np.linspace(beam[0], beam[-1], beam.size)
            if beam[0] == beam[-1] or not np.allclose(beam, even, rtol=0.0, atol=1e-6):
                raise ValueError(
                    "angles must be evenly spaced from the first to the last beam"
                    " (foxglove.LaserScan stores only start_angle and end_angle)"
                )
        values = np.asarray(ranges, dtype=np.float32)
        if values.shape != beam.shape:
            raise ValueError(f"ranges have shape {values.shape}, angles {beam.shape}")
        meta = None
        if max_range is not None:
            limit = float(np.float32(max_range))
            if not math.isfinite(limit) or limit <= 0:
                raise ValueError(f"max_range must be finite and positive, got {max_range}")
            meta = {_MAX_RANGE_KEY: repr(limit)}
        if np.any(np.isposinf(values)):
            if meta is None:
                raise ValueError("ranges have +inf values: pass max_range to write no returns")
            values = np.where(np.isposinf(values), np.float32(limit), values)
        with np.errstate(invalid="ignore"):
            values = np.where(values > 0, values, np.float32(np.nan))  # invalid: NaN
        if intensities is None:
            strength: list[float] = []
        else:
            inten = np.asarray(intensities, dtype=np.float64)
            if inten.shape != beam.shape or not np.all(np.isfinite(inten)):
                raise ValueError(f"intensities must be finite with shape {beam.shape}")
            strength = inten.tolist()
        message = LaserScan(
            frame_id=frame_id,
            start_angle=float(beam[0]),
            end_angle=float(beam[-1]),
            ranges=values.astype(np.float64).tolist(),
            intensities=strength,
        )
        _set_pose(message.pose, pose7)
        self._foxglove(topic, ns, message, meta)

    def write_depth_image(
        self, topic: str, t: float, depth: np.ndarray, frame_id: str = "camera"
    ) -> None:
        """``foxglove.RawImage`` with encoding ``32FC1``: ``depth`` (h, w) metres, stored as
        little-endian float32 (NaN/inf allowed, e.g. for no return)."""
        ns = _time_ns(t)
        _name(frame_id, "frame_id")
        image = np.asarray(depth)
        if image.ndim != 2 or image.shape[0] < 1 or image.shape[1] < 1:
            raise ValueError(f"depth must be a non-empty (h, w) array, got shape {image.shape}")
        if not np.issubdtype(image.dtype, np.floating):
            raise ValueError(f"depth must be floating-point metres, got dtype {image.dtype}")
        height, width = image.shape
        data = np.ascontiguousarray(image, dtype="<f4").tobytes()
        message = RawImage(
            frame_id=frame_id,
            width=width,
            height=height,
            encoding="32FC1",
            step=4 * width,
            data=data,
        )
        self._foxglove(topic, ns, message)

    def write_grid(self, topic: str, t: float, grid: Any, frame_id: str = "world") -> None:
        """``foxglove.Grid`` of an occupancy grid (``kiseki.OccupancyGrid`` or anything with
        ``cells`` int8 (H, W), ``resolution`` and ``origin`` x/y/theta): one INT8 field
        ``occupancy`` (0 free, 100 occupied, -1 unknown), row 0 at the origin corner."""
        ns = _time_ns(t)
        _name(frame_id, "frame_id")
        cells = np.asarray(grid.cells)
        if cells.ndim != 2 or cells.dtype != np.int8:
            raise ValueError(f"grid cells must be an int8 (H, W) array, got {cells.dtype}")
        resolution = float(grid.resolution)
        if not math.isfinite(resolution) or resolution <= 0:
            raise ValueError(f"grid resolution must be positive, got {resolution}")
        pose7 = _pose7(grid.origin, "grid origin")
        width = int(cells.shape[1])
        message = Grid(
            frame_id=frame_id,
            column_count=width,
            row_stride=width,
            cell_stride=1,
            fields=[PackedElementField(name="occupancy", offset=0, type=_INT8)],
            data=np.ascontiguousarray(cells).tobytes(),
        )
        message.cell_size.x = message.cell_size.y = resolution
        _set_pose(message.pose, pose7)
        self._foxglove(topic, ns, message)

    def write_json(
        self,
        topic: str,
        t: float,
        schema_name: str,
        payload: Mapping[str, Any],
        schema: Mapping[str, Any],
    ) -> None:
        """A message of kiseki's own (odometry, magnetometer, bearings, commands): ``payload``
        is a JSON object (numpy scalars and arrays are converted; NaN/inf refused), ``schema``
        its JSON schema, registered under ``schema_name`` on the topic's first message."""
        ns = _time_ns(t)
        if not isinstance(payload, Mapping):
            raise ValueError(f"payload must be a dict, got {type(payload).__name__}")
        try:
            data = _dumps(dict(payload))
        except (TypeError, ValueError) as exc:
            raise ValueError(f"payload of {topic!r} is not finite JSON: {exc}") from exc
        channel = self._channel(topic, schema_name, schema)
        self._write(channel, ns, data)

    def write_odometry(
        self,
        topic: str,
        t: float,
        pose: Any,
        velocity: tuple[float, float] | None = None,
        frame_id: str = "odom",
    ) -> None:
        """``kiseki.Odometry2D`` (:data:`ODOMETRY_SCHEMA`): the odometry pose (x, y, theta) and
        optionally the velocity (linear m/s, angular rad/s)."""
        if all(hasattr(pose, a) for a in ("x", "y", "theta")):
            pose = (pose.x, pose.y, pose.theta)
        values = np.asarray(pose, dtype=np.float64)
        if values.shape != (3,) or not np.all(np.isfinite(values)):
            raise ValueError(f"odometry pose must be finite (x, y, theta), got {pose!r}")
        _name(frame_id, "frame_id")
        payload: dict[str, Any] = {"timestamp": _stamp(_time_ns(t)), "frame_id": frame_id}
        payload.update(zip(("x", "y", "theta"), values.tolist(), strict=True))
        if velocity is not None:
            speed = np.asarray(velocity, dtype=np.float64)
            if speed.shape != (2,) or not np.all(np.isfinite(speed)):
                raise ValueError(f"velocity must be finite (linear, angular), got {velocity!r}")
            payload["linear_velocity"], payload["angular_velocity"] = speed.tolist()
        self.write_json(topic, t, ODOMETRY_SCHEMA_NAME, payload, ODOMETRY_SCHEMA)


# --- reader ---


@dataclass
class _Topic:
    schema_name: str
    message_encoding: str
    metadata: dict[str, str]
    schema: Schema | None = None
    raw: list[tuple[int, int, bytes]] = field(default_factory=list)  # (log_time, order, data)
    decoded: list[tuple[int, dict[str, Any]]] | None = None  # (log_time ns, message)


class SimRun:
    """The messages of one MCAP run (see :func:`read_run`), held in memory as read.

    Channels sharing a topic are merged (the schema of the first channel is reported). The
    decoded messages are cached: treat the returned dicts as read-only.
    """

    def __init__(
        self,
        path: Path,
        topics: dict[str, _Topic],
        metadata: dict[str, str],
        truncated: bool,
    ) -> None:
        self.path = path
        self.metadata = metadata  # every Metadata record of the file, merged in file order
        self.truncated = truncated  # True when the footer is missing (a killed writer)
        self._topics = topics

    def __repr__(self) -> str:
        count = sum(len(t.raw) for t in self._topics.values())
        cut = ", truncated" if self.truncated else ""
        return f"SimRun({str(self.path)!r}, {len(self._topics)} topics, {count} messages{cut})"

    def topics(self) -> dict[str, tuple[str, int]]:
        """topic -> (schema name, message count), in the order the channels appear."""
        return {name: (t.schema_name, len(t.raw)) for name, t in self._topics.items()}

    def channel_metadata(self, topic: str) -> dict[str, str]:
        return dict(self._topic(topic).metadata)

    def _topic(self, topic: str) -> _Topic:
        if topic not in self._topics:
            raise MissingTopicError(
                f"{self.path}: no topic {topic!r} (topics: {', '.join(sorted(self._topics))})"
            )
        return self._topics[topic]

    def messages(self, topic: str) -> list[tuple[float, dict[str, Any]]]:
        """(t seconds from ``log_time``, decoded message) of the topic, sorted by time (stable:
        file order for equal times). KeyError for a topic not in the file. A JSON message is
        its JSON object; a protobuf message is a dict of the same layout (timestamps as
        ``{"sec", "nsec"}``, nested messages as dicts, enums as ints), except that repeated
        numbers are protobuf's read-only sequences and ``bytes`` fields are bytes (base64 text in
        older JSON runs)."""
        return [(ns / _NS_PER_S, message) for ns, message in self._decoded(topic)]

    def _decoded(self, topic: str) -> list[tuple[int, dict[str, Any]]]:
        entry = self._topic(topic)
        if entry.decoded is None:
            rows = sorted(entry.raw, key=lambda r: (r[0], r[1]))
            if entry.message_encoding == MESSAGE_ENCODING:
                entry.decoded = [(ns, self._json(topic, ns, data)) for ns, _, data in rows]
            elif entry.message_encoding == PROTOBUF:
                parse = self._protobuf_parser(topic, entry)
                entry.decoded = [
                    (ns, self._protobuf(topic, ns, data, parse)) for ns, _, data in rows
                ]
            else:
                raise LogFormatError(
                    f"{self.path}: topic {topic!r} has message encoding"
                    f" {entry.message_encoding!r}, not JSON or protobuf"
                )
        return entry.decoded

    def _json(self, topic: str, ns: int, data: bytes) -> dict[str, Any]:
        try:
            message = json.loads(data)
        except (UnicodeDecodeError, ValueError) as exc:
            raise LogFormatError(
                f"{self.path}: bad JSON message on {topic!r} at {ns} ns ({exc})"
            ) from exc
        if not isinstance(message, dict):
            raise LogFormatError(f"{self.path}: {topic!r} message is not a JSON object")
        return message

    def _protobuf_parser(self, topic: str, entry: _Topic) -> Any:
        """The protobuf class's FromString: Foxglove's own class for its messages, else a
        class built from the schema's FileDescriptorSet."""
        known = FOXGLOVE_MESSAGES.get(entry.schema_name)
        if known is not None:
            return known.FromString
        decoder = None
        try:
            decoder = DecoderFactory().decoder_for(PROTOBUF, entry.schema)
        except Exception as exc:  # a corrupt FileDescriptorSet: DecodeError, TypeError, ...
            raise LogFormatError(
                f"{self.path}: bad protobuf schema {entry.schema_name!r} of {topic!r} ({exc})"
            ) from exc
        if decoder is None:
            raise LogFormatError(f"{self.path}: protobuf topic {topic!r} has no protobuf schema")
        return decoder

    def _protobuf(self, topic: str, ns: int, data: bytes, parse: Any) -> dict[str, Any]:
        try:
            return _as_dict(parse(data))
        except (DecodeError, McapError) as exc:  # McapError: the mcap-protobuf decoder's
            raise LogFormatError(
                f"{self.path}: bad protobuf message on {topic!r} at {ns} ns ({exc})"
            ) from exc

    def _typed(self, topic: str, schema_name: str) -> list[tuple[int, dict[str, Any]]]:
        """(log_time ns, message) of a topic that must carry ``schema_name`` messages."""
        found = self._topic(topic).schema_name
        if found != schema_name:
            raise LogFormatError(
                f"{self.path}: topic {topic!r} carries {found!r}, not {schema_name}"
            )
        return self._decoded(topic)

    def poses(self, topic: str = "/ground_truth") -> tuple[np.ndarray, np.ndarray]:
        """A ``foxglove.PoseInFrame`` topic as (times (N,), poses (N, 3) x, y, yaw)."""
        rows = self._typed(topic, "foxglove.PoseInFrame")
        poses = np.array([self._xytheta(topic, m.get("pose")) for _, m in rows]).reshape(-1, 3)
        return _seconds(rows), poses

    def velocities(self, topic: str = "/velocity") -> tuple[np.ndarray, np.ndarray]:
        """A ``kiseki.Twist`` topic (/cmd_vel, /velocity) as (times (N,), (N, 3) vx, vy, w)."""
        rows = self._typed(topic, TWIST_SCHEMA_NAME)
        try:
            values = [(float(m["vx"]), float(m["vy"]), float(m["w"])) for _, m in rows]
        except (KeyError, TypeError, ValueError) as exc:
            raise LogFormatError(f"{self.path}: bad kiseki.Twist on {topic!r} ({exc})") from exc
        return _seconds(rows), np.array(values, dtype=float).reshape(-1, 3)

    def depth_images(self, topic: str) -> list[tuple[float, np.ndarray]]:
        """A ``foxglove.RawImage`` ``32FC1`` topic as (t, (h, w) float32 metres) pairs."""
        out = []
        for ns, m in self._typed(topic, "foxglove.RawImage"):
            try:
                width, height, step = int(m["width"]), int(m["height"]), int(m["step"])
                encoding = m["encoding"]
                data = _payload_bytes(m["data"])
            except (KeyError, TypeError, ValueError) as exc:
                raise LogFormatError(f"{self.path}: bad RawImage on {topic!r} ({exc})") from exc
            if encoding != "32FC1" or step < 4 * width or len(data) < step * height:
                raise LogFormatError(
                    f"{self.path}: {topic!r} image is {encoding} {width}x{height} step {step}"
                    f" with {len(data)} bytes; only complete 32FC1 images are read"
                )
            rows = np.frombuffer(data, dtype=np.uint8, count=step * height).reshape(height, step)
            image = rows[:, : 4 * width].copy().view("<f4").astype(np.float32)
            out.append((ns / _NS_PER_S, image))
        return out

    def grid(self, topic: str = "/map", index: int = -1) -> OccupancyGrid:
        """Message ``index`` of a ``foxglove.Grid`` topic with an INT8 (or UINT8) field at offset
        0 and equal cell sizes, as a ``kiseki.OccupancyGrid``."""
        rows = self._typed(topic, "foxglove.Grid")
        if not rows:
            raise LogFormatError(f"{self.path}: no grid on {topic!r}")
        _, m = rows[index]
        try:
            width = int(m["column_count"])
            row_stride, cell_stride = int(m["row_stride"]), int(m["cell_stride"])
            size_x, size_y = float(m["cell_size"]["x"]), float(m["cell_size"]["y"])
            fields = m["fields"]
            data = _payload_bytes(m["data"])
        except (KeyError, TypeError, ValueError) as exc:
            raise LogFormatError(f"{self.path}: bad Grid on {topic!r} ({exc})") from exc
        kind = [f.get("type") for f in fields if f.get("offset") == 0]
        if size_x != size_y or not kind or kind[0] not in (_INT8, _UINT8) or width < 1:
            raise LogFormatError(
                f"{self.path}: {topic!r} grid is not an occupancy grid (cell size"
                f" {size_x}x{size_y}, fields {fields})"
            )
        if row_stride < width * cell_stride or cell_stride < 1 or row_stride < 1:
            raise LogFormatError(f"{self.path}: {topic!r} grid has bad strides")
        height = len(data) // row_stride
        raw = np.frombuffer(data, dtype=np.uint8, count=height * row_stride)
        raw = raw.reshape(height, row_stride)[:, : width * cell_stride : cell_stride]
        cells = np.ascontiguousarray(raw).view(np.int8)
        x, y, theta = self._xytheta(topic, m.get("pose"))
        return OccupancyGrid(cells, size_x, Pose2(x, y, theta))

    def _xytheta(self, topic: str, pose: Any) -> tuple[float, float, float]:
        try:
            p, q = pose["position"], pose["orientation"]
            x, y = float(p["x"]), float(p["y"])
            yaw = _quaternion_yaw(float(q["x"]), float(q["y"]), float(q["z"]), float(q["w"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise LogFormatError(f"{self.path}: bad pose on {topic!r} ({exc})") from exc
        return x, y, yaw

    def laser_scans(
        self,
        scan_topic: str = "/scan",
        truth_topic: str | None = "/ground_truth",
        odom_topic: str | None = "/odom",
    ) -> LaserScans:
        """The scans as a CARMEN-like :class:`~kiseki.scans.LaserScans`, by time.

        * ``poses``: the sensor pose in the world, the pose written in each LaserScan message
          (the laser pose of a CARMEN log). A scan whose ``frame_id`` is not the frame of the
          ``truth_topic`` poses (``world``) is taken as given in the robot frame, and is
          composed with the ground-truth pose of the same timestamp (LogFormatError if there
          is none). With ``truth_topic=None`` the scan poses are used as written.
        * ``odometry``: the odometry pose nearest in time (the earlier one on a tie) on
          ``odom_topic``, a JSON topic whose payload has ``x``, ``y``, ``theta``; NaN when
          ``odom_topic`` is None.
        * ``angles``: ``linspace(start_angle, end_angle, B)``, equal for every scan (1e-9 rad).
        * ``max_range``: the channel metadata ``max_range`` written by :class:`RunWriter`, else
          the largest finite reading (as for CARMEN logs without the PARAM), rounded to float32.
        * ``ranges`` follow kiseki's rule (``kiseki.scans``): NaN, ``-inf``, negative and zero
          readings are invalid, kept as NaN and counted; ``+inf`` is a no return. A NaN or
          infinite pose or odometry, and an odometry jump of more than
          ``kiseki.scans.MAX_ODOMETRY_JUMP`` between two consecutive scans, are errors naming
          the scan (its index from 0, by time) and its time.
        """
        scans = self._typed(scan_topic, "foxglove.LaserScan")
        if not scans:
            raise LogFormatError(f"{self.path}: no laser scans on {scan_topic!r}")
        times = _seconds(scans)
        try:
            starts = np.array([m["start_angle"] for _, m in scans], dtype=np.float64)
            ends = np.array([m["end_angle"] for _, m in scans], dtype=np.float64)
            rows = [np.asarray(m["ranges"], dtype=np.float32) for _, m in scans]
            ranges = np.stack(rows) if rows[0].ndim == 1 else np.empty((0, 0), np.float32)
        except (KeyError, TypeError, ValueError) as exc:
            raise LogFormatError(
                f"{self.path}: laser scans on {scan_topic!r} are malformed or do not all have"
                f" the same beam count ({exc})"
            ) from exc
        if ranges.ndim != 2 or ranges.shape[1] < 1:
            raise LogFormatError(f"{self.path}: laser scans on {scan_topic!r} have no beams")
        start, end = float(starts[0]), float(ends[0])
        other = (np.abs(starts - start) > 1e-9) | (np.abs(ends - end) > 1e-9)
        if np.any(other):
            raise LogFormatError(
                f"{self.path}: the scan at t={times[np.argmax(other)]} on {scan_topic!r} has"
                f" other beam angles than the first scan"
            )
        beams = ranges.shape[1]
        angles = np.linspace(start, end, beams) if beams > 1 else np.array([start])
        poses = np.array([self._xytheta(scan_topic, m.get("pose")) for _, m in scans])
        self._check_finite(scan_topic, "pose", times, poses)
        frames = [m.get("frame_id") for _, m in scans]
        if truth_topic is not None:
            poses = self._scan_poses_in_world(truth_topic, scans, frames, poses)
        odometry = np.full((len(scans), 3), np.nan)
        if odom_topic is not None:
            odometry = self._nearest_odometry(odom_topic, times)
            self._check_finite(odom_topic, "odometry", times, odometry)
        limit_text = self._topic(scan_topic).metadata.get(_MAX_RANGE_KEY)
        try:
            limit = float(limit_text) if limit_text is not None else largest_reading(ranges)
        except ValueError as exc:
            raise LogFormatError(f"{self.path}: bad max_range {limit_text!r}") from exc
        if limit is None:
            raise LogFormatError(f"{self.path}: no valid range reading on {scan_topic!r}")
        limit = float(np.float32(limit))
        if not (math.isfinite(limit) and limit > 0):
            raise LogFormatError(f"{self.path}: bad max_range {limit_text!r}")
        laser = LaserScans(
            times=times,
            poses=np.ascontiguousarray(poses, dtype=np.float64),
            odometry=odometry,
            ranges=apply_range_rule(ranges, limit),
            angles=angles.astype(np.float64),
            max_range=limit,
        )
        check_odometry_jumps(self.path, laser.times, laser.odometry)
        return laser

    def _check_finite(self, topic: str, what: str, times: np.ndarray, rows: np.ndarray) -> None:
        """A LogFormatError naming the first scan whose pose or odometry is NaN or infinite."""
        bad = ~np.isfinite(rows).all(axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            raise LogFormatError(
                f"{self.path}: the {what} on {topic!r} at scan {k} (t = {times[k]:.3f} s) is "
                "NaN or infinite"
            )

    def _scan_poses_in_world(
        self,
        truth_topic: str,
        scans: list[tuple[int, dict[str, Any]]],
        frames: list[Any],
        poses: np.ndarray,
    ) -> np.ndarray:
        if truth_topic not in self._topics:
            raise LogFormatError(
                f"{self.path}: no ground-truth topic {truth_topic!r} (pass truth_topic=None to"
                f" use the scan poses as written)"
            )
        truth_rows = self._typed(truth_topic, "foxglove.PoseInFrame")
        world = {m.get("frame_id") for _, m in truth_rows}
        if len(world) > 1:
            raise LogFormatError(f"{self.path}: {truth_topic!r} poses are in frames {world}")
        if all(frame in world for frame in frames):
            return poses
        truth = {ns: self._xytheta(truth_topic, m.get("pose")) for ns, m in truth_rows}
        out = poses.copy()
        for i, ((ns, _), frame) in enumerate(zip(scans, frames, strict=True)):
            if frame in world:
                continue
            robot = truth.get(ns)
            if robot is None:
                raise LogFormatError(
                    f"{self.path}: the scan at t={ns / _NS_PER_S} is in frame {frame!r} and"
                    f" {truth_topic!r} has no pose at that time"
                )
            rx, ry, rtheta = robot
            sx, sy, stheta = poses[i]
            c, s = math.cos(rtheta), math.sin(rtheta)
            yaw = math.remainder(rtheta + stheta, math.tau)
            out[i] = (rx + c * sx - s * sy, ry + s * sx + c * sy, yaw)
        return out

    def _nearest_odometry(self, odom_topic: str, times: np.ndarray) -> np.ndarray:
        if odom_topic not in self._topics:
            raise LogFormatError(
                f"{self.path}: no odometry topic {odom_topic!r} (topics: {sorted(self._topics)};"
                f" pass odom_topic=None for NaN odometry)"
            )
        rows = self._decoded(odom_topic)
        if not rows:
            raise LogFormatError(f"{self.path}: no odometry messages on {odom_topic!r}")
        try:
            odom = np.array([[m["x"], m["y"], m["theta"]] for _, m in rows], dtype=np.float64)
        except (KeyError, TypeError, ValueError) as exc:
            raise LogFormatError(
                f"{self.path}: odometry on {odom_topic!r} needs numbers x, y, theta ({exc})"
            ) from exc
        odom_times = _seconds(rows)  # sorted by _decoded()
        after = np.searchsorted(odom_times, times, side="left").clip(0, len(rows) - 1)
        before = (after - 1).clip(0, len(rows) - 1)
        use_before = np.abs(times - odom_times[before]) <= np.abs(odom_times[after] - times)
        return odom[np.where(use_before, before, after)]


def _seconds(rows: list[tuple[int, dict[str, Any]]]) -> np.ndarray:
    return np.array([ns for ns, _ in rows], dtype=np.float64) / _NS_PER_S


class _Prefix(io.RawIOBase):
    """The first ``limit`` bytes of a binary file."""

    def __init__(self, file: IO[bytes], limit: int) -> None:
        self._file = file
        self.remaining = limit

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        view = memoryview(buffer).cast("B")
        size = min(len(view), self.remaining)
        data = self._file.read(size) if size else b""
        view[: len(data)] = data
        self.remaining -= len(data)
        return len(data)


def _complete_prefix(path: Path, file: IO[bytes]) -> tuple[int, bool]:
    """(bytes of complete records, including the closing magic when complete; whether the
    file ends with a footer and the magic), from the record framing alone."""
    size = file.seek(0, io.SEEK_END)
    file.seek(0)
    if file.read(len(_MAGIC)) != _MAGIC:
        raise LogFormatError(f"{path}: not an MCAP file (no MCAP magic at the start)")
    pos = len(_MAGIC)
    first = True
    while True:
        head = file.read(9)
        if len(head) < 9:
            return pos, False
        opcode, length = struct.unpack("<BQ", head)
        if first and opcode != Opcode.HEADER:
            raise LogFormatError(f"{path}: not an MCAP file (first record is not a Header)")
        first = False
        end = pos + 9 + length
        if end > size:
            return pos, False
        file.seek(end)
        if opcode == Opcode.FOOTER:
            tail = file.read(len(_MAGIC))
            if len(tail) < len(_MAGIC):
                return end, False
            if tail != _MAGIC:
                raise LogFormatError(f"{path}: corrupt MCAP (no magic after the footer)")
            return end + len(_MAGIC), True
        pos = end


def read_run(path: str | os.PathLike) -> SimRun:
    """Reads an MCAP run written by :class:`RunWriter` (or any MCAP; its JSON and protobuf
    topics are decoded, older kiseki runs' all-JSON ones too). FileNotFoundError if missing,
    LogFormatError if not an MCAP or corrupt; a file without its footer (writer killed) gives
    the complete chunks with a TruncatedRunWarning."""
    path = Path(path)
    if check_input(path, "kiseki run logs", MAX_RUN_BYTES, LogFormatError) is not None:
        check_mcap_chunks(path, "kiseki run logs", MAX_CHUNK_BYTES, MAX_RUN_BYTES, LogFormatError)
    topics: dict[str, _Topic] = {}
    metadata: dict[str, str] = {}
    schemas: dict[int, Schema] = {}
    channels: dict[int, _Topic] = {}
    statistics: Statistics | None = None
    header_seen = False
    count = 0
    with open(path, "rb") as file:
        limit, complete = _complete_prefix(path, file)
        file.seek(0)
        prefix = _Prefix(file, limit)
        reader = StreamReader(io.BufferedReader(prefix), validate_crcs=True)
        try:
            for record in reader.records:
                if isinstance(record, Header):
                    header_seen = True
                elif isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    if record.id in channels:
                        continue  # repeated in the summary section
                    if record.schema_id != 0 and record.schema_id not in schemas:
                        raise LogFormatError(
                            f"{path}: channel {record.topic!r} refers to missing schema"
                            f" {record.schema_id}"
                        )
                    name = schemas[record.schema_id].name if record.schema_id else ""
                    entry = topics.get(record.topic)
                    if entry is None:
                        entry = _Topic(
                            name,
                            record.message_encoding,
                            dict(record.metadata),
                            schemas.get(record.schema_id),
                        )
                        topics[record.topic] = entry
                    channels[record.id] = entry
                elif isinstance(record, Message):
                    if record.channel_id not in channels:
                        raise LogFormatError(
                            f"{path}: message on unknown channel {record.channel_id}"
                        )
                    channels[record.channel_id].raw.append((record.log_time, count, record.data))
                    count += 1
                elif isinstance(record, Metadata):
                    metadata.update(record.metadata)
                elif isinstance(record, Statistics):
                    statistics = record
        except EndOfFile as exc:
            if complete or prefix.remaining:
                raise LogFormatError(f"{path}: corrupt MCAP (a record overruns its end)") from exc
        except LogFormatError:
            raise
        except Exception as exc:
            # The mcap reader raises McapError subclasses, ValueError (CRC check), struct.error,
            # UnicodeDecodeError, zstandard.ZstdError, RuntimeError (lz4), ... on corrupt data.
            raise LogFormatError(f"{path}: corrupt MCAP ({type(exc).__name__}: {exc})") from exc
    if not header_seen:
        raise LogFormatError(f"{path}: truncated MCAP (cut before the end of its Header)")
    if statistics is not None and statistics.message_count != count:
        raise LogFormatError(
            f"{path}: the summary counts {statistics.message_count} messages, the file has {count}"
        )
    if not complete:
        warnings.warn(
            f"{path}: truncated MCAP (no footer; the writer was probably killed): read the"
            f" {count} messages of the complete chunks, up to byte {limit}",
            TruncatedRunWarning,
            stacklevel=2,
        )
    return SimRun(path, topics, metadata, truncated=not complete)
