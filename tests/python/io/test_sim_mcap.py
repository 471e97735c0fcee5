# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the MCAP run log: Foxglove protobuf messages checked with the plain mcap reader and
Foxglove's own classes (read back by read_run: test_sim_mcap_read_run.py; truncated files and
bad input: test_sim_mcap_bad_files.py)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.Grid_pb2 import Grid
from foxglove_schemas_protobuf.LaserScan_pb2 import LaserScan
from foxglove_schemas_protobuf.PoseInFrame_pb2 import PoseInFrame
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from google.protobuf.descriptor_pb2 import FileDescriptorSet
from mcap.reader import make_reader

from _helpers.sim_mcap_sample import (
    ANGLES,
    DEPTH,
    N_STEPS,
    laser_pose,
    make_grid,
    odom_pose,
    scan_ranges,
    truth_pose,
    write_sample,
)
from kiseki.io.runlog import (
    FOXGLOVE_MESSAGES,
    ODOMETRY_SCHEMA_NAME,
)


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
