# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the MCAP run log: Foxglove protobuf messages checked with the plain mcap reader and
Foxglove's own classes, read-back as a CARMEN-like dataset (also of a run in the older JSON
layout), truncated files (cut and really killed), bad input."""

from __future__ import annotations

import base64
import io
import json
import math
import os
import signal
import subprocess
import sys
import types
import warnings
from pathlib import Path

import numpy as np
import pytest
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.Grid_pb2 import Grid
from foxglove_schemas_protobuf.LaserScan_pb2 import LaserScan
from foxglove_schemas_protobuf.PoseInFrame_pb2 import PoseInFrame
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from google.protobuf.descriptor_pb2 import FileDescriptorSet
from mcap.reader import NonSeekingReader, make_reader
from mcap.records import Chunk, ChunkIndex, Message
from mcap.stream_reader import ReadDataStream, breakup_chunk
from mcap.writer import CompressionType, Writer

import kiseki
from kiseki.errors import LogFormatError
from kiseki.io.runlog import (
    FOXGLOVE_MESSAGES,
    ODOMETRY_SCHEMA,
    ODOMETRY_SCHEMA_NAME,
    RunWriter,
    TruncatedRunWarning,
    read_run,
)
from kiseki.scans import LaserScans

N_STEPS = 40
BEAMS = 21
ANGLES = np.linspace(-np.pi / 2, np.pi / 2, BEAMS)
MAX_RANGE = 12.5


def truth_pose(k: int) -> tuple[float, float, float]:
    return (0.25 * k, 1.0 - 0.125 * k, math.remainder(0.3 * k, math.tau))


def laser_pose(k: int) -> tuple[float, float, float]:
    x, y, theta = truth_pose(k)
    return (x + 0.2 * math.cos(theta), y + 0.2 * math.sin(theta), theta)


def scan_ranges(k: int) -> np.ndarray:
    rng = np.random.default_rng(k)
    ranges = rng.uniform(0.1, MAX_RANGE, BEAMS).astype(np.float32)
    ranges[k % BEAMS] = MAX_RANGE  # a no-return beam
    return ranges


def odom_pose(j: int) -> tuple[float, float, float]:
    return (0.26 * j / 2, 1.01 - 0.06 * j, 0.151 * j)


def make_grid() -> kiseki.OccupancyGrid:
    cells = np.full((6, 9), -1, dtype=np.int8)
    cells[0, :] = 0  # row 0 (at the origin) free
    cells[5, 8] = 100
    cells[2, 3] = 37
    return kiseki.OccupancyGrid(cells, 0.05, kiseki.Pose2(-1.5, 2.0, 0.25))


DEPTH = (np.arange(20, dtype=np.float32).reshape(4, 5) * 0.37 + 0.5).astype(np.float32)
DEPTH[1, 2] = np.nan
DEPTH[3, 4] = np.inf


def write_sample(path: Path, **kwargs) -> None:
    """40 steps at 10 Hz: truth pose + transform + scan per step, odometry at 20 Hz shifted by
    5 ms, a depth image, a grid and a magnetometer message of kiseki's own."""
    mag_schema = {
        "title": "kiseki.Magnetometer",
        "type": "object",
        "properties": {"heading": {"type": "number"}},
    }
    with RunWriter(path, {"seed": "42", "world": "corridor"}, **kwargs) as w:
        w.write_grid("/map", 0.0, make_grid())
        for j in range(2 * N_STEPS):
            w.write_odometry("/odom", 0.05 * j + 0.005, odom_pose(j), velocity=(0.5, 0.1))
        for k in range(N_STEPS):
            t = k / 10
            w.write_pose("/ground_truth", t, truth_pose(k))
            w.write_transform(t, "world", "base_link", truth_pose(k))
            w.write_laser_scan(
                "/scan", t, laser_pose(k), ANGLES, scan_ranges(k), max_range=MAX_RANGE
            )
        w.write_depth_image("/depth", 1.5, DEPTH, frame_id="camera")
        w.write_json("/magnetometer", 2.0, "kiseki.Magnetometer", {"heading": 0.5}, mag_schema)


@pytest.fixture
def sample(tmp_path: Path) -> Path:
    path = tmp_path / "run.mcap"
    write_sample(path)
    return path


def plain_messages(path: Path) -> dict[str, list]:
    out: dict[str, list] = {}
    with open(path, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages(log_time_order=False):
            out.setdefault(channel.topic, []).append((schema, channel, message))
    return out


# --- the file as any MCAP reader sees it ---


FOXGLOVE_TOPICS = {
    "/map": "foxglove.Grid",
    "/ground_truth": "foxglove.PoseInFrame",
    "/tf": "foxglove.FrameTransform",
    "/scan": "foxglove.LaserScan",
    "/depth": "foxglove.RawImage",
}


def test_plain_mcap_reader_sees_foxglove_protobuf_channels(sample: Path) -> None:
    with open(sample, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    assert summary is not None and summary.statistics is not None
    channels = {c.topic: c for c in summary.channels.values()}
    expected = {**FOXGLOVE_TOPICS, "/odom": ODOMETRY_SCHEMA_NAME}
    expected["/magnetometer"] = "kiseki.Magnetometer"
    assert set(channels) == set(expected)
    for topic, name in expected.items():
        schema = summary.schemas[channels[topic].schema_id]
        assert schema.name == name
        if topic in FOXGLOVE_TOPICS:  # Foxglove's protobuf messages
            assert schema.encoding == "protobuf"
            assert channels[topic].message_encoding == "protobuf"
            files = FileDescriptorSet.FromString(schema.data).file
            proto = name.split(".")[1]
            assert files[-1].name == f"foxglove/{proto}.proto" and files[-1].package == "foxglove"
            assert [m.name for m in files[-1].message_type] == [proto]
        else:  # kiseki's own: JSON
            assert schema.encoding == "jsonschema"
            assert channels[topic].message_encoding == "json"
            assert json.loads(schema.data)["title"] == name
    # each schema registered once, one channel per topic
    assert len(summary.schemas) == len(expected) and len(summary.channels) == len(expected)
    assert channels["/scan"].metadata == {"max_range": "12.5"}
    counts = {
        summary.channels[cid].topic: n
        for cid, n in summary.statistics.channel_message_counts.items()
    }
    assert counts == {
        "/map": 1,
        "/odom": 2 * N_STEPS,
        "/ground_truth": N_STEPS,
        "/tf": N_STEPS,
        "/scan": N_STEPS,
        "/depth": 1,
        "/magnetometer": 1,
    }
    assert metadata == {"kiseki.run": {"seed": "42", "world": "corridor"}}
    assert {t: len(v) for t, v in plain_messages(sample).items()} == counts


def test_small_chunks_are_used(sample: Path) -> None:
    with open(sample, "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    assert all(c.uncompressed_size < 128 * 1024 + 64 * 1024 for c in summary.chunk_indexes)
    chunked = sample.with_name("small.mcap")
    write_sample(chunked, chunk_size=2048)
    with open(chunked, "rb") as f:
        small = make_reader(f).get_summary()
    assert small is not None and len(small.chunk_indexes) > 5


def test_message_values_are_exact(sample: Path) -> None:
    """Each message decoded with Foxglove's published protobuf class, not kiseki's reader."""
    msgs = plain_messages(sample)

    # laser scans: times, sensor pose, angles, float32 ranges
    scans = msgs["/scan"]
    for k, (_, _, message) in enumerate(scans):
        body = LaserScan.FromString(message.data)
        ns = round(0.1 * k * 1e9)
        assert message.log_time == message.publish_time == ns
        assert (body.timestamp.seconds, body.timestamp.nanos) == (ns // 10**9, ns % 10**9)
        assert body.frame_id == "world"
        x, y, theta = laser_pose(k)
        p, q = body.pose.position, body.pose.orientation
        assert (p.x, p.y, p.z) == (x, y, 0.0)
        assert (q.x, q.y) == (0.0, 0.0)
        assert q.z == pytest.approx(math.sin(theta / 2), abs=1e-15)
        assert q.w == pytest.approx(math.cos(theta / 2), abs=1e-15)
        assert body.start_angle == ANGLES[0] and body.end_angle == ANGLES[-1]
        ranges = np.array(body.ranges, dtype=np.float64)
        np.testing.assert_array_equal(ranges, scan_ranges(k).astype(np.float64))
        assert list(body.intensities) == []

    # depth image: the raw little-endian float32 bytes, NaN and inf preserved
    (_, _, message) = msgs["/depth"][0]
    body = RawImage.FromString(message.data)
    assert (body.width, body.height, body.step) == (5, 4, 20)
    assert body.encoding == "32FC1" and body.frame_id == "camera"
    assert body.data == DEPTH.astype("<f4").tobytes()
    assert (body.timestamp.seconds, body.timestamp.nanos) == (1, 500_000_000)

    # grid: INT8 cells, row 0 at the origin, pose of the origin corner
    (_, _, message) = msgs["/map"][0]
    body = Grid.FromString(message.data)
    grid = make_grid()
    assert body.column_count == 9 and body.row_stride == 9 and body.cell_stride == 1
    assert (body.cell_size.x, body.cell_size.y) == (0.05, 0.05)
    [packed] = body.fields
    assert (packed.name, packed.offset, packed.type) == ("occupancy", 0, 2)  # 2: INT8
    assert body.data == grid.cells.tobytes()
    cells = np.frombuffer(body.data, dtype=np.int8).reshape(-1, 9)
    assert cells[0, 0] == 0 and cells[5, 8] == 100 and cells[1, 0] == -1
    p = body.pose.position
    assert (p.x, p.y, p.z) == (-1.5, 2.0, 0.0)
    assert body.pose.orientation.z == pytest.approx(math.sin(0.125), abs=1e-15)

    # ground truth and the transform of base_link in world
    (_, _, message) = msgs["/ground_truth"][3]
    body = PoseInFrame.FromString(message.data)
    assert body.frame_id == "world" and body.pose.position.x == truth_pose(3)[0]
    assert body.pose.orientation.z == pytest.approx(math.sin(0.45), abs=1e-15)
    (_, _, message) = msgs["/tf"][3]
    body = FrameTransform.FromString(message.data)
    assert body.parent_frame_id == "world" and body.child_frame_id == "base_link"
    t = body.translation
    assert (t.x, t.y, t.z) == (0.75, 0.625, 0.0)
    assert body.rotation.w == pytest.approx(math.cos(0.45), abs=1e-15)

    # kiseki odometry and a custom message: JSON
    (_, _, message) = msgs["/odom"][3]
    body = json.loads(message.data)
    assert message.log_time == 155_000_000
    assert (body["x"], body["y"], body["theta"]) == odom_pose(3)
    assert (body["linear_velocity"], body["angular_velocity"]) == (0.5, 0.1)
    (_, _, message) = msgs["/magnetometer"][0]
    assert json.loads(message.data) == {"heading": 0.5}
    assert message.log_time == 2_000_000_000


EXPECTED_FIELDS = {
    "foxglove.PoseInFrame": {"timestamp", "frame_id", "pose"},
    "foxglove.FrameTransform": {
        "timestamp",
        "parent_frame_id",
        "child_frame_id",
        "translation",
        "rotation",
    },
    "foxglove.LaserScan": {
        "timestamp",
        "frame_id",
        "pose",
        "start_angle",
        "end_angle",
        "ranges",
        "intensities",
    },
    "foxglove.RawImage": {"timestamp", "frame_id", "width", "height", "encoding", "step", "data"},
    "foxglove.Grid": {
        "timestamp",
        "frame_id",
        "pose",
        "column_count",
        "cell_size",
        "row_stride",
        "cell_stride",
        "fields",
        "data",
    },
}


def test_foxglove_schemas_are_the_published_descriptors(sample: Path) -> None:
    """The schema of each Foxglove topic describes the message with the fields Foxglove
    publishes, and the pool it builds decodes the message as Foxglove's class does."""
    from google.protobuf.descriptor_pool import DescriptorPool
    from google.protobuf.message_factory import GetMessageClass

    assert set(FOXGLOVE_MESSAGES) == set(EXPECTED_FIELDS)
    with open(sample, "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    stored = {s.name: s for s in summary.schemas.values()}
    first = {t: m for t, [(_, _, m), *_] in plain_messages(sample).items()}
    for topic, name in FOXGLOVE_TOPICS.items():
        pool = DescriptorPool()
        for proto in FileDescriptorSet.FromString(stored[name].data).file:
            pool.Add(proto)  # in dependency order, as mcap-protobuf-support writes them
        descriptor = pool.FindMessageTypeByName(name)
        assert {f.name for f in descriptor.fields} == EXPECTED_FIELDS[name]
        built = GetMessageClass(descriptor).FromString(first[topic].data)
        published = FOXGLOVE_MESSAGES[name].FromString(first[topic].data)
        assert built.SerializeToString() == published.SerializeToString()
        assert built.ListFields() and str(built) == str(published)


# --- read_run ---


def test_read_run_laser_scans_match_what_was_written(sample: Path) -> None:
    run = read_run(sample)
    assert not run.truncated
    assert run.metadata == {"seed": "42", "world": "corridor"}
    assert run.topics()["/scan"] == ("foxglove.LaserScan", N_STEPS)
    assert run.topics()["/odom"] == (ODOMETRY_SCHEMA_NAME, 2 * N_STEPS)
    scans = run.laser_scans()
    assert isinstance(scans, LaserScans) and len(scans) == N_STEPS
    np.testing.assert_array_equal(scans.times, [k / 10 for k in range(N_STEPS)])
    assert scans.ranges.dtype == np.float32 and scans.ranges.flags.c_contiguous
    np.testing.assert_array_equal(scans.ranges, [scan_ranges(k) for k in range(N_STEPS)])
    np.testing.assert_allclose(scans.angles, ANGLES, rtol=0, atol=1e-12)
    np.testing.assert_allclose(scans.poses, [laser_pose(k) for k in range(N_STEPS)], atol=1e-12)
    # odometry at 0.05 j + 0.005: the nearest to 0.1 k is j = 2k (5 ms away, not 45 ms)
    np.testing.assert_array_equal(scans.odometry, [odom_pose(2 * k) for k in range(N_STEPS)])
    assert scans.max_range == MAX_RANGE


def test_read_run_helpers(sample: Path) -> None:
    run = read_run(sample)
    times, poses = run.poses("/ground_truth")
    np.testing.assert_array_equal(times, [k / 10 for k in range(N_STEPS)])
    np.testing.assert_allclose(poses, [truth_pose(k) for k in range(N_STEPS)], atol=1e-12)
    [(t, depth)] = run.depth_images("/depth")
    assert t == 1.5 and depth.dtype == np.float32
    np.testing.assert_array_equal(depth, DEPTH)
    grid = run.grid("/map")
    np.testing.assert_array_equal(grid.cells, make_grid().cells)
    assert grid.resolution == pytest.approx(0.05)
    assert (grid.origin.x, grid.origin.y) == (-1.5, 2.0)
    assert grid.origin.theta == pytest.approx(0.25, abs=1e-12)
    [(t, message)] = run.messages("/magnetometer")
    assert (t, message) == (2.0, {"heading": 0.5})
    with pytest.raises(KeyError, match="/nope"):
        run.messages("/nope")
    with pytest.raises(LogFormatError, match="not foxglove.LaserScan"):
        run.laser_scans(scan_topic="/odom")


def _old_stamp(ns: int) -> dict[str, int]:
    return {"sec": ns // 10**9, "nsec": ns % 10**9}


def _old_pose(x: float, y: float, theta: float) -> dict:
    return {
        "position": {"x": x, "y": y, "z": 0.0},
        "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(theta / 2), "w": math.cos(theta / 2)},
    }


def write_old_json_sample(path: Path) -> None:
    """write_sample's run in the layout kiseki wrote before its protobuf messages: every
    message JSON ("json" channels, "jsonschema" schemas), images and grids as base64 text."""
    with open(path, "wb") as file:
        writer = Writer(file, chunk_size=4096, compression=CompressionType.ZSTD)
        writer.start(profile="", library="kiseki")
        writer.add_metadata("kiseki.run", {"seed": "42", "world": "corridor"})
        channels: dict[str, int] = {}

        def add(topic: str, name: str, ns: int, body: dict, meta: dict | None = None) -> None:
            if topic not in channels:
                schema = ODOMETRY_SCHEMA if name == ODOMETRY_SCHEMA_NAME else {"title": name}
                sid = writer.register_schema(name, "jsonschema", json.dumps(schema).encode())
                channels[topic] = writer.register_channel(topic, "json", sid, meta or {})
            data = json.dumps(body, separators=(",", ":")).encode()
            writer.add_message(channels[topic], log_time=ns, data=data, publish_time=ns)

        grid = make_grid()
        origin = (grid.origin.x, grid.origin.y, grid.origin.theta)
        add("/map", "foxglove.Grid", 0, {
            "timestamp": _old_stamp(0), "frame_id": "world", "pose": _old_pose(*origin),
            "column_count": 9, "cell_size": {"x": 0.05, "y": 0.05}, "row_stride": 9,
            "cell_stride": 1, "fields": [{"name": "occupancy", "offset": 0, "type": 2}],
            "data": base64.b64encode(grid.cells.tobytes()).decode(),
        })  # fmt: skip
        for j in range(2 * N_STEPS):
            ns = round((0.05 * j + 0.005) * 1e9)
            x, y, theta = odom_pose(j)
            add("/odom", ODOMETRY_SCHEMA_NAME, ns, {
                "timestamp": _old_stamp(ns), "frame_id": "odom", "x": x, "y": y, "theta": theta,
                "linear_velocity": 0.5, "angular_velocity": 0.1,
            })  # fmt: skip
        for k in range(N_STEPS):
            ns, (x, y, theta) = round(k / 10 * 1e9), truth_pose(k)
            pose = {
                "timestamp": _old_stamp(ns),
                "frame_id": "world",
                "pose": _old_pose(x, y, theta),
            }
            add("/ground_truth", "foxglove.PoseInFrame", ns, pose)
            add("/tf", "foxglove.FrameTransform", ns, {
                "timestamp": _old_stamp(ns), "parent_frame_id": "world",
                "child_frame_id": "base_link", "translation": {"x": x, "y": y, "z": 0.0},
                "rotation": _old_pose(x, y, theta)["orientation"],
            })  # fmt: skip
            add("/scan", "foxglove.LaserScan", ns, {
                "timestamp": _old_stamp(ns), "frame_id": "world", "pose": _old_pose(*laser_pose(k)),
                "start_angle": ANGLES[0], "end_angle": ANGLES[-1],
                "ranges": scan_ranges(k).astype(np.float64).tolist(), "intensities": [],
            }, {"max_range": "12.5"})  # fmt: skip
        add("/depth", "foxglove.RawImage", 1_500_000_000, {
            "timestamp": _old_stamp(1_500_000_000), "frame_id": "camera", "width": 5, "height": 4,
            "encoding": "32FC1", "step": 20, "data": base64.b64encode(DEPTH.tobytes()).decode(),
        })  # fmt: skip
        add("/magnetometer", "kiseki.Magnetometer", 2_000_000_000, {"heading": 0.5})
        writer.finish()


def _raw_data(message: dict) -> dict:
    """A message with its bytes field as bytes (base64 text in the JSON layout)."""
    if isinstance(message.get("data"), str):
        return {**message, "data": base64.b64decode(message["data"])}
    return message


def test_older_json_run_reads_as_the_protobuf_run(sample: Path, tmp_path: Path) -> None:
    old_path = tmp_path / "old.mcap"
    write_old_json_sample(old_path)
    with open(old_path, "rb") as f:
        encodings = {c.message_encoding for c in make_reader(f).get_summary().channels.values()}
    assert encodings == {"json"}
    old, new = read_run(old_path), read_run(sample)
    assert old.topics() == new.topics() and old.metadata == new.metadata
    a, b = old.laser_scans(), new.laser_scans()
    for name in ("times", "poses", "odometry", "ranges", "angles"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.max_range == b.max_range == MAX_RANGE and a.ranges.dtype == b.ranges.dtype
    np.testing.assert_array_equal(old.poses()[1], new.poses()[1])
    [(t_old, d_old)], [(t_new, d_new)] = old.depth_images("/depth"), new.depth_images("/depth")
    assert t_old == t_new == 1.5 and d_old.tobytes() == d_new.tobytes() == DEPTH.tobytes()
    g_old, g_new = old.grid("/map"), new.grid("/map")
    np.testing.assert_array_equal(g_old.cells, g_new.cells)
    assert g_old.resolution == g_new.resolution
    assert (g_old.origin.x, g_old.origin.y, g_old.origin.theta) == (
        g_new.origin.x, g_new.origin.y, g_new.origin.theta
    )  # fmt: skip
    for topic in old.topics():  # the messages themselves, decoded to the same dicts
        got = [(t, _raw_data(m)) for t, m in old.messages(topic)]
        assert got == new.messages(topic), topic


def test_other_encodings_and_protobuf_schemas(tmp_path: Path) -> None:
    """A protobuf message kiseki has no class for is decoded from the file's schema; a bad
    protobuf message and an unknown encoding are LogFormatErrors naming the file."""
    from foxglove_schemas_protobuf.Vector2_pb2 import Vector2
    from mcap_protobuf.schema import build_file_descriptor_set

    path = tmp_path / "other.mcap"
    with open(path, "wb") as file:
        writer = Writer(file)
        writer.start(profile="", library="test")
        data = build_file_descriptor_set(Vector2).SerializeToString()
        vector = writer.register_schema("foxglove.Vector2", "protobuf", data)
        data = build_file_descriptor_set(LaserScan).SerializeToString()
        scan = writer.register_schema("foxglove.LaserScan", "protobuf", data)
        for topic, sid, encoding, payload in (
            ("/v", vector, "protobuf", Vector2(x=1.5, y=-2.0).SerializeToString()),
            ("/scan", scan, "protobuf", b"\xff\xff\xff"),
            ("/c", vector, "cbor", b"\xa0"),
        ):
            channel = writer.register_channel(topic, encoding, sid)
            writer.add_message(channel, log_time=7, data=payload, publish_time=7)
        writer.finish()
    run = read_run(path)
    assert run.messages("/v") == [(7e-9, {"x": 1.5, "y": -2.0})]
    with pytest.raises(LogFormatError, match="other.mcap: bad protobuf message on '/scan'"):
        run.laser_scans(truth_topic=None, odom_topic=None)
    with pytest.raises(LogFormatError, match="'cbor', not JSON or protobuf"):
        run.messages("/c")


def test_scans_in_the_robot_frame_are_composed_with_ground_truth(tmp_path: Path) -> None:
    path = tmp_path / "robot_frame.mcap"
    mount = (0.2, 0.0, 0.0)
    with RunWriter(path) as w:
        for k in range(5):
            w.write_pose("/ground_truth", 0.1 * k, truth_pose(k))
            w.write_odometry("/odom", 0.1 * k, odom_pose(k))
            w.write_laser_scan("/scan", 0.1 * k, mount, ANGLES, scan_ranges(k), "base_link")
    scans = read_run(path).laser_scans()
    np.testing.assert_allclose(scans.poses, [laser_pose(k) for k in range(5)], atol=1e-12)
    assert scans.max_range == float(max(scan_ranges(k).max() for k in range(5)))
    with RunWriter(path, overwrite=True) as w:  # a scan without a truth pose at its time
        w.write_pose("/ground_truth", 0.0, truth_pose(0))
        w.write_laser_scan("/scan", 0.05, mount, ANGLES, scan_ranges(0), "base_link")
    with pytest.raises(LogFormatError, match="no pose at that time"):
        read_run(path).laser_scans(odom_topic=None)


def test_messages_are_sorted_by_time_and_odometry_can_be_absent(tmp_path: Path) -> None:
    path = tmp_path / "unordered.mcap"
    with RunWriter(path) as w:
        for t in (0.3, 0.1, 0.2):
            w.write_laser_scan("/scan", t, (t, 0.0, 0.0), [0.0, 0.5], [1.0, 2.0])
    run = read_run(path)
    assert [t for t, _ in run.messages("/scan")] == [0.1, 0.2, 0.3]
    with pytest.raises(LogFormatError, match="no ground-truth topic"):
        run.laser_scans()
    with pytest.raises(LogFormatError, match="no odometry topic '/odom'"):
        run.laser_scans(truth_topic=None)
    scans = run.laser_scans(truth_topic=None, odom_topic=None)
    np.testing.assert_array_equal(scans.poses[:, 0], [0.1, 0.2, 0.3])
    assert np.isnan(scans.odometry).all()


def test_times_are_whole_nanoseconds(tmp_path: Path) -> None:
    path = tmp_path / "times.mcap"
    with RunWriter(path) as w:
        for t in (0.1 * 3, 1e-10, 6e-10, 1234567.000000001, 0):
            w.write_json("/t", t, "kiseki.Tick", {}, {"type": "object"})
    with open(path, "rb") as f:
        stamps = [m.log_time for _, _, m in make_reader(f).iter_messages(log_time_order=False)]
    assert stamps == [300_000_000, 0, 1, 1_234_567_000_000_001, 0]
    assert [t for t, _ in read_run(path).messages("/t")] == [0.0, 0.0, 1e-9, 0.3, 1234567.000000001]


def test_infinite_ranges_are_written_as_max_range(tmp_path: Path) -> None:
    path = tmp_path / "inf.mcap"
    with RunWriter(path) as w:
        w.write_laser_scan("/scan", 0.0, (0, 0, 0), [-1, 0, 1], [1, np.inf, 3], max_range=8)
        with pytest.raises(ValueError, match="channel metadata"):
            w.write_laser_scan("/scan", 0.1, (0, 0, 0), [-1, 0, 1], [1, 2, 3], max_range=9)
    scans = read_run(path).laser_scans(truth_topic=None, odom_topic=None)
    np.testing.assert_array_equal(scans.ranges, [[1, 8, 3]])
    assert scans.max_range == 8.0


# --- truncated files ---


def read_all(path: Path) -> list[tuple[str, float, dict]]:
    run = read_run(path)
    return [(topic, t, m) for topic in run.topics() for t, m in run.messages(topic)]


def test_cut_file_yields_the_complete_chunks(tmp_path: Path) -> None:
    full = tmp_path / "full.mcap"
    write_sample(full, chunk_size=2048)
    data = full.read_bytes()
    everything = read_all(full)
    with open(full, "rb") as f:
        chunks = make_reader(f).get_summary().chunk_indexes  # type: ignore[union-attr]
    cut_path = tmp_path / "cut.mcap"
    seen_partial = False
    for cut in (chunks[3].chunk_start_offset + 5, len(data) // 2, len(data) - 10, len(data) - 1):
        cut_path.write_bytes(data[:cut])
        with pytest.warns(TruncatedRunWarning, match="cut.mcap: truncated MCAP"):
            run = read_run(cut_path)
        assert run.truncated and run.metadata == {"seed": "42", "world": "corridor"}
        got = [(topic, t, m) for topic in run.topics() for t, m in run.messages(topic)]
        # exactly the messages of the chunks that end before the cut
        complete = [c for c in chunks if c.chunk_start_offset + c.chunk_length <= cut]
        n_complete = sum(chunk_message_count(data, c) for c in complete)
        assert len(got) == n_complete
        seen_partial |= 0 < n_complete < len(everything)
        assert all(item in everything for item in got)
    assert seen_partial
    # the cut before chunk 3 keeps the first 3 chunks: the first written scans are there
    cut_path.write_bytes(data[: chunks[3].chunk_start_offset + 5])
    with pytest.warns(TruncatedRunWarning):
        run = read_run(cut_path)
    assert run.topics()["/map"] == ("foxglove.Grid", 1)


def chunk_message_count(data: bytes, index: ChunkIndex) -> int:
    """Messages in one chunk, decoded straight from the bytes at the index's offset."""
    start = index.chunk_start_offset + 9  # opcode + record length
    chunk = Chunk.read(ReadDataStream(io.BytesIO(data[start : start + index.chunk_length])))
    return sum(isinstance(r, Message) for r in breakup_chunk(chunk))


def test_cut_before_header_or_magic_is_a_log_format_error(sample: Path, tmp_path: Path) -> None:
    data = sample.read_bytes()
    cut = tmp_path / "tiny.mcap"
    for size in (0, 5, 8, 20):
        cut.write_bytes(data[:size])
        with pytest.raises(LogFormatError, match="tiny.mcap"):
            read_run(cut)


def test_mcap_library_alone_needs_the_footer(tmp_path: Path) -> None:
    """What the docstring says of mcap 1.6: the seeking reader fails on a file without its
    footer; the non-seeking reader yields the complete chunks' messages, then raises."""
    full = tmp_path / "full.mcap"
    write_sample(full, chunk_size=2048)
    data = full.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    with open(cut, "rb") as f, pytest.raises(Exception):  # noqa: B017 - any error, see docstring
        list(make_reader(f).iter_messages())
    streamed = []
    with open(cut, "rb") as f, pytest.raises(Exception):  # noqa: B017
        for _, channel, message in NonSeekingReader(f).iter_messages(log_time_order=False):
            streamed.append((channel.topic, message.log_time))
    with pytest.warns(TruncatedRunWarning):
        run = read_run(cut)
    assert len(streamed) == sum(n for _, n in run.topics().values()) > 0


KILLED_WRITER = """
import os, signal, sys
import numpy as np
from kiseki.io.runlog import RunWriter
w = RunWriter(sys.argv[1], {"run": "killed"}, chunk_size=4096)
for k in range(int(sys.argv[2])):
    w.write_pose("/ground_truth", 0.01 * k, (k, 0.0, 0.0))
    w.write_laser_scan("/scan", 0.01 * k, (k, 0.0, 0.0), np.linspace(-1, 1, 50),
                       np.full(50, k % 7 + 1.0))
os.kill(os.getpid(), signal.SIGKILL)
"""


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="needs SIGKILL")
def test_killed_writer_keeps_every_complete_chunk(tmp_path: Path) -> None:
    path = tmp_path / "killed.mcap"
    steps = 301  # 300 steps happen to fill the last chunk exactly: nothing would be lost
    proc = subprocess.run(
        [sys.executable, "-c", KILLED_WRITER, str(path), str(steps)],
        capture_output=True,
        timeout=120,
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr.decode()
    with pytest.warns(TruncatedRunWarning):
        run = read_run(path)
    assert run.truncated and run.metadata == {"run": "killed"}
    poses = run.messages("/ground_truth")
    scans = run.messages("/scan")
    # Only the last, unfinished chunk is lost: a step (pose ~41 B + scan ~462 B of protobuf + 2
    # message headers of 31 B) takes ~565 B, so a 4 KiB chunk holds fewer than 8 steps.
    assert steps - 8 <= len(poses) <= steps and len(scans) < steps
    assert len(scans) in (len(poses), len(poses) - 1)  # the chunk may end between the two
    assert [m["pose"]["position"]["x"] for _, m in poses] == list(range(len(poses)))
    assert [m["ranges"][0] for _, m in scans] == [k % 7 + 1.0 for k in range(len(scans))]
    assert os.path.getsize(path) > 0


# --- bad input ---


def test_overwrite_is_refused_unless_asked(sample: Path) -> None:
    before = sample.read_bytes()
    with pytest.raises(FileExistsError, match="overwrite=True"):
        RunWriter(sample)
    assert sample.read_bytes() == before
    with RunWriter(sample, overwrite=True) as w:
        w.write_pose("/p", 1.0, (1, 2, 3))
    assert read_run(sample).topics() == {"/p": ("foxglove.PoseInFrame", 1)}


def test_bad_messages_raise_value_error(tmp_path: Path) -> None:
    path = tmp_path / "bad.mcap"
    with RunWriter(path) as w:
        with pytest.raises(ValueError, match="NaN"):
            w.write_pose("/p", 0.0, (1.0, float("nan"), 0.0))
        with pytest.raises(ValueError, match="NaN"):
            w.write_transform(0.0, "world", "base_link", (0.0, 0.0, float("inf")))
        with pytest.raises(ValueError, match=">= 0"):
            w.write_pose("/p", -0.5, (0, 0, 0))
        with pytest.raises(ValueError, match="finite"):
            w.write_pose("/p", float("nan"), (0, 0, 0))
        with pytest.raises(ValueError, match="shape"):
            w.write_pose("/p", 0.0, (0, 0))
        with pytest.raises(ValueError, match="unit norm"):
            w.write_pose("/p", 0.0, (0, 0, 0, 0, 0, 0, 2))
        with pytest.raises(ValueError, match="evenly spaced"):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1, 0.5], [1, 2, 3])
        with pytest.raises(ValueError, match="shape"):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1, 0.2], [1, 2])
        with pytest.raises(ValueError, match="max_range"):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1], [1, float("inf")])
        with pytest.raises(ValueError, match=r"\(h, w\)"):
            w.write_depth_image("/d", 0.0, np.zeros(5, np.float32), "cam")
        with pytest.raises(ValueError, match="floating"):
            w.write_depth_image("/d", 0.0, np.zeros((2, 2), np.uint16), "cam")
        with pytest.raises(ValueError, match="finite JSON"):
            w.write_json("/j", 0.0, "kiseki.X", {"v": float("nan")}, {"type": "object"})
        w.write_pose("/p", 0.0, (0, 0, 0))
        with pytest.raises(ValueError, match="carries foxglove.PoseInFrame"):
            w.write_laser_scan("/p", 0.0, (0, 0, 0), [0.0, 0.1], [1, 2])
    with pytest.raises(ValueError, match="closed"):
        w.write_pose("/p", 1.0, (0, 0, 0))
    # nothing invalid reached the file
    assert read_run(path).topics() == {"/p": ("foxglove.PoseInFrame", 1)}


@pytest.mark.parametrize("bad", [True, "1.5", -0.5, math.nan])
def test_a_time_range_or_resolution_that_is_no_number_is_refused(tmp_path: Path, bad) -> None:
    """True was written as 1 s, 1 m or 1 m per cell and "1.5" as 1.5 s or m (a negative or NaN
    value was refused before too); a max range that no float32 holds is refused as before."""
    grid = types.SimpleNamespace(cells=np.zeros((2, 2), np.int8), resolution=bad, origin=None)
    with RunWriter(tmp_path / "bad.mcap") as w:
        with pytest.raises(ValueError, match=r"^time must be a finite number >= 0 s, got "):
            w.write_pose("/p", bad, (0, 0, 0))
        with pytest.raises(ValueError, match=r"^max_range must be a finite number > 0 m, got "):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1], [1, 2], max_range=bad)
        with pytest.raises(
            ValueError, match=r"^grid resolution must be a finite number > 0 m, got "
        ):
            w.write_grid("/map", 0.0, grid)
        for past in (1e39, 1e-50):  # no float32 holds them: inf and 0
            with pytest.raises(ValueError, match=r"m is outside a float32's range$"):
                w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1], [1, 2], max_range=past)
    assert read_run(tmp_path / "bad.mcap").topics() == {}


def test_missing_and_garbage_files(tmp_path: Path, sample: Path) -> None:
    with pytest.raises(FileNotFoundError):
        read_run(tmp_path / "missing.mcap")
    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"this is not an mcap file at all\n" * 10)
    with pytest.raises(LogFormatError, match="garbage.mcap"):
        read_run(garbage)
    fake = tmp_path / "fake.mcap"
    fake.write_bytes(b"\x89MCAP0\r\n" + bytes(range(256)) * 4)
    with pytest.raises(LogFormatError, match="fake.mcap"):
        read_run(fake)


def test_corrupt_chunk_is_a_log_format_error(tmp_path: Path) -> None:
    path = tmp_path / "corrupt.mcap"
    write_sample(path, chunk_size=2048)
    with open(path, "rb") as f:
        chunk = make_reader(f).get_summary().chunk_indexes[2]  # type: ignore[union-attr]
    data = bytearray(path.read_bytes())
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    data[middle] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(LogFormatError, match="corrupt.mcap: corrupt MCAP"):
        read_run(path)


def test_no_warning_on_a_complete_file(sample: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run = read_run(sample)
    assert "truncated" not in repr(run)
