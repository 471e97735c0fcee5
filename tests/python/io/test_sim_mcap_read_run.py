# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the MCAP run log read back as a CARMEN-like dataset by read_run, also of a run in
the older JSON layout and in other encodings (moved from test_sim_mcap.py)."""

from __future__ import annotations

import base64
import json
import math
from pathlib import Path

import numpy as np
import pytest
from foxglove_schemas_protobuf.LaserScan_pb2 import LaserScan
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from _helpers.sim_mcap_sample import (
    ANGLES,
    DEPTH,
    MAX_RANGE,
    N_STEPS,
    laser_pose,
    make_grid,
    odom_pose,
    scan_ranges,
    truth_pose,
)
from kiseki.errors import LogFormatError
from kiseki.io.runlog import (
    ODOMETRY_SCHEMA,
    ODOMETRY_SCHEMA_NAME,
    RunWriter,
    read_run,
)
from kiseki.scans import LaserScans

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
