# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Writing a run log (:class:`RunWriter`).

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
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from types import TracebackType
from typing import IO, Any

import numpy as np
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.Grid_pb2 import Grid
from foxglove_schemas_protobuf.PackedElementField_pb2 import PackedElementField
from foxglove_schemas_protobuf.PoseInFrame_pb2 import PoseInFrame
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from mcap.writer import LIBRARY_IDENTIFIER, Writer

from kiseki._support.counts import check_count
from kiseki._support.real_numbers import check_number
from kiseki._support.signal_hold import SignalHold
from kiseki.io.runlog._encoding import (
    _COMPRESSIONS,
    _INT8,
    _METADATA_NAME,
    _NS_PER_S,
    _dumps,
    _laser_scan,
    _name,
    _pose7,
    _protobuf_schema,
    _set_pose,
    _stamp,
    _time_ns,
)
from kiseki.io.runlog.schemas import (
    DEFAULT_CHUNK_SIZE,
    MESSAGE_ENCODING,
    ODOMETRY_SCHEMA,
    ODOMETRY_SCHEMA_NAME,
    PROTOBUF,
    SCHEMA_ENCODING,
)

__all__ = ["RunWriter"]


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
        chunk_size = check_count(chunk_size, "chunk_size", 1, note="bytes")
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
        # Ctrl-C and SIGTERM wait for the record being written (kiseki._support.signal_hold)
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
        rad), one turn at most from a first within +-2 pi (what the reader takes), and ``ranges``
        (B,) metres, stored as float32 values. ``max_range`` (fixed per
        topic, kept in the channel metadata) is the no-return reading; ``+inf`` readings are
        written as ``max_range`` and need it. Invalid readings (NaN, ``-inf``, negative, zero:
        kiseki's rule, ``kiseki.scans``) are written as NaN."""
        ns = _time_ns(t)
        pose7 = _pose7(sensor_pose, "sensor pose")
        _name(frame_id, "frame_id")
        message, meta = _laser_scan(frame_id, angles, ranges, intensities, max_range)
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
        resolution = check_number(grid.resolution, "grid resolution", 0.0, low_open=True, unit="m")
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
