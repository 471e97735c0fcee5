# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the run log's writer and reader share: times as nanoseconds, poses as quaternions,
protobuf messages as the dicts of the JSON layout, the record constants of the file, and a
topic's messages as read."""

from __future__ import annotations

import base64
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np
from foxglove_schemas_protobuf.LaserScan_pb2 import LaserScan
from google.protobuf.descriptor import FieldDescriptor
from mcap.records import Schema
from mcap.writer import CompressionType
from mcap_protobuf.schema import build_file_descriptor_set

from kiseki._support.real_numbers import check_number
from kiseki.io.runlog.schemas import FOXGLOVE_MESSAGES
from kiseki.scans import beams_of_one_turn

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


def _time_ns(t: float) -> int:
    value = check_number(t, "time", 0.0, unit="s")
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


@dataclass
class _Topic:
    schema_name: str
    message_encoding: str
    metadata: dict[str, str]
    schema: Schema | None = None
    raw: list[tuple[int, int, bytes]] = field(default_factory=list)  # (log_time, order, data)
    decoded: list[tuple[int, dict[str, Any]]] | None = None  # (log_time ns, message)


def _laser_scan(
    frame_id: str,
    angles: Sequence[float] | np.ndarray,
    ranges: Sequence[float] | np.ndarray,
    intensities: Sequence[float] | np.ndarray | None,
    max_range: float | None,
) -> tuple[LaserScan, dict[str, str] | None]:
    """The ``foxglove.LaserScan`` of one scan (its pose not set yet) and its channel metadata
    (``max_range``), with the checks of :meth:`RunWriter.write_laser_scan`."""
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
    if not beams_of_one_turn(beam[0], (beam[-1] - beam[0]) / max(beam.size - 1, 1), beam.size):
        raise ValueError(
            f"angles from {beam[0]:g} to {beam[-1]:g} rad: not beams of one turn at most (the"
            " first within +-2 pi), which kiseki's readers refuse"
        )
    values = np.asarray(ranges, dtype=np.float32)
    if values.shape != beam.shape:
        raise ValueError(f"ranges have shape {values.shape}, angles {beam.shape}")
    meta = None
    if max_range is not None:
        check_number(max_range, "max_range", 0.0, low_open=True, unit="m")
        with np.errstate(over="ignore"):  # past a float32: inf, refused below
            limit = float(np.float32(max_range))  # the ranges' own type
        if not 0 < limit < math.inf:
            raise ValueError(f"max_range {max_range!r} m is outside a float32's range")
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
    return message, meta
