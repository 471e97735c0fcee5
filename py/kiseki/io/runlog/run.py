# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A run log as read (:class:`SimRun`): its topics' messages decoded on demand to poses, scans,
images, grids and velocities. :meth:`SimRun.laser_scans` returns the same
:class:`~kiseki.scans.LaserScans` as the CARMEN reader, so simulated runs replay through the
interface of real logs."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
from google.protobuf.message import DecodeError
from mcap.exceptions import McapError
from mcap_protobuf.decoder import DecoderFactory

from kiseki._support.numbers_text import parse_float
from kiseki.core import Pose2
from kiseki.errors import LogFormatError
from kiseki.grid import OccupancyGrid
from kiseki.io.runlog._encoding import (
    _INT8,
    _MAX_RANGE_KEY,
    _NS_PER_S,
    _UINT8,
    _as_dict,
    _payload_bytes,
    _quaternion_yaw,
    _Topic,
)
from kiseki.io.runlog.schemas import (
    FOXGLOVE_MESSAGES,
    MESSAGE_ENCODING,
    PROTOBUF,
    TWIST_SCHEMA_NAME,
    MissingTopicError,
)
from kiseki.scans import (
    LaserScans,
    apply_range_rule,
    beams_of_one_turn,
    check_log_max_range,
    check_odometry_jumps,
    largest_reading,
)

__all__ = ["SimRun"]


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
        * ``angles``: ``linspace(start_angle, end_angle, B)``, equal for every scan (1e-9 rad),
          beams of one turn at most (``kiseki.scans.beams_of_one_turn``, as the CARMEN and bag
          readers require: a start within +-2 pi, several beams not all on one ray).
        * ``max_range``: the channel metadata ``max_range`` written by :class:`RunWriter`, else
          ``kiseki.scans.largest_reading`` (as for CARMEN logs without the PARAM), as float32.
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
        start, end, beams = float(starts[0]), float(ends[0]), ranges.shape[1]
        if not beams_of_one_turn(start, (end - start) / max(beams - 1, 1), beams):
            raise LogFormatError(
                f"{self.path}: the first scan on {scan_topic!r} has start_angle {start:g} and "
                f"end_angle {end:g} rad for {beams} beam(s): not beams of one turn at most "
                "(start_angle within +-2 pi, a finite end_angle, several beams not all on one ray)"
            )
        # a later scan's NaN angle is other too (start and end are finite here)
        other = ~((np.abs(starts - start) <= 1e-9) & (np.abs(ends - end) <= 1e-9))
        if np.any(other):
            raise LogFormatError(
                f"{self.path}: the scan at t={times[np.argmax(other)]} on {scan_topic!r} has"
                f" other beam angles than the first scan"
            )
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
            limit = parse_float(limit_text) if limit_text is not None else largest_reading(ranges)
        except ValueError as exc:
            raise LogFormatError(f"{self.path}: bad max_range {limit_text!r}") from exc
        if limit is None:
            raise LogFormatError(f"{self.path}: no valid range reading on {scan_topic!r}")
        limit = check_log_max_range(f"{self.path}: {scan_topic!r}", float(np.float32(limit)))
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
