# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the MCAP run log: Foxglove JSON messages checked with the plain mcap reader,
read-back as a CARMEN-like dataset, truncated files (cut and really killed), bad input."""

from __future__ import annotations

import base64
import io
import json
import math
import os
import signal
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import NonSeekingReader, make_reader
from mcap.records import Chunk, ChunkIndex, Message
from mcap.stream_reader import ReadDataStream, breakup_chunk

import kiseki
from kiseki.errors import LogFormatError
from kiseki.scans import LaserScans
from kiseki.sim.mcap_log import (
    FOXGLOVE_SCHEMAS,
    ODOMETRY_SCHEMA_NAME,
    RunWriter,
    TruncatedRunWarning,
    read_run,
)

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


def test_plain_mcap_reader_sees_foxglove_json_channels(sample: Path) -> None:
    with open(sample, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        metadata = {m.name: m.metadata for m in reader.iter_metadata()}
    assert summary is not None and summary.statistics is not None
    channels = {c.topic: c for c in summary.channels.values()}
    expected = {
        "/map": "foxglove.Grid",
        "/odom": ODOMETRY_SCHEMA_NAME,
        "/ground_truth": "foxglove.PoseInFrame",
        "/tf": "foxglove.FrameTransform",
        "/scan": "foxglove.LaserScan",
        "/depth": "foxglove.RawImage",
        "/magnetometer": "kiseki.Magnetometer",
    }
    assert set(channels) == set(expected)
    for topic, name in expected.items():
        schema = summary.schemas[channels[topic].schema_id]
        assert schema.name == name
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
    msgs = plain_messages(sample)

    # laser scans: times, sensor pose, angles, float32 ranges
    scans = msgs["/scan"]
    for k, (_, _, message) in enumerate(scans):
        body = json.loads(message.data)
        ns = round(0.1 * k * 1e9)
        assert message.log_time == message.publish_time == ns
        assert body["timestamp"] == {"sec": ns // 10**9, "nsec": ns % 10**9}
        assert body["frame_id"] == "world"
        x, y, theta = laser_pose(k)
        assert body["pose"]["position"] == {"x": x, "y": y, "z": 0.0}
        q = body["pose"]["orientation"]
        assert (q["x"], q["y"]) == (0.0, 0.0)
        assert q["z"] == pytest.approx(math.sin(theta / 2), abs=1e-15)
        assert q["w"] == pytest.approx(math.cos(theta / 2), abs=1e-15)
        assert body["start_angle"] == ANGLES[0] and body["end_angle"] == ANGLES[-1]
        ranges = np.array(body["ranges"], dtype=np.float32)
        np.testing.assert_array_equal(ranges, scan_ranges(k))
        assert body["intensities"] == []

    # depth image: base64 little-endian float32, NaN and inf preserved
    (_, _, message) = msgs["/depth"][0]
    body = json.loads(message.data)
    assert (body["width"], body["height"], body["step"]) == (5, 4, 20)
    assert body["encoding"] == "32FC1" and body["frame_id"] == "camera"
    depth = np.frombuffer(base64.b64decode(body["data"]), dtype="<f4").reshape(4, 5)
    np.testing.assert_array_equal(depth, DEPTH)  # NaN == NaN for assert_array_equal

    # grid: INT8 cells, row 0 at the origin, pose of the origin corner
    (_, _, message) = msgs["/map"][0]
    body = json.loads(message.data)
    grid = make_grid()
    assert body["column_count"] == 9 and body["row_stride"] == 9 and body["cell_stride"] == 1
    assert body["cell_size"] == {"x": 0.05, "y": 0.05}
    assert body["fields"] == [{"name": "occupancy", "offset": 0, "type": 2}]
    cells = np.frombuffer(base64.b64decode(body["data"]), dtype=np.int8).reshape(-1, 9)
    np.testing.assert_array_equal(cells, grid.cells)
    assert cells[0, 0] == 0 and cells[5, 8] == 100 and cells[1, 0] == -1
    assert body["pose"]["position"] == {"x": -1.5, "y": 2.0, "z": 0.0}
    assert body["pose"]["orientation"]["z"] == pytest.approx(math.sin(0.125), abs=1e-15)

    # transform of base_link in world
    (_, _, message) = msgs["/tf"][3]
    body = json.loads(message.data)
    assert body["parent_frame_id"] == "world" and body["child_frame_id"] == "base_link"
    assert body["translation"] == {"x": 0.75, "y": 0.625, "z": 0.0}
    assert body["rotation"]["w"] == pytest.approx(math.cos(0.45), abs=1e-15)

    # kiseki odometry and a custom message
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


def test_foxglove_schema_texts(sample: Path) -> None:
    assert set(FOXGLOVE_SCHEMAS) == set(EXPECTED_FIELDS)
    with open(sample, "rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    stored = {s.name: json.loads(s.data) for s in summary.schemas.values()}
    for name, fields in EXPECTED_FIELDS.items():
        schema = stored[name]
        assert schema["title"] == name and schema["type"] == "object"
        props = schema["properties"]
        assert set(props) == fields
        assert props["timestamp"]["properties"]["nsec"]["maximum"] == 999_999_999
        for key in ("pose", "translation", "rotation"):
            if key in props:
                inner = props[key]["properties"]
                sub = inner.get("position", props[key])["properties"]
                assert set(sub) >= {"x", "y", "z"}
        if "pose" in props:
            orientation = props["pose"]["properties"]["orientation"]["properties"]
            assert set(orientation) == {"x", "y", "z", "w"}
    assert stored["foxglove.RawImage"]["properties"]["data"]["contentEncoding"] == "base64"
    grid = stored["foxglove.Grid"]["properties"]
    assert grid["data"]["contentEncoding"] == "base64"
    numeric = grid["fields"]["items"]["properties"]["type"]["oneOf"]
    assert {"title": "INT8", "const": 2} in numeric and len(numeric) == 9
    assert set(grid["cell_size"]["properties"]) == {"x", "y"}
    assert stored["foxglove.LaserScan"]["properties"]["ranges"]["items"] == {"type": "number"}


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
from kiseki.sim.mcap_log import RunWriter
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
    steps = 300
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
    # Only the last, unfinished chunk is lost: a step (pose ~145 B + scan ~410 B of JSON + 2
    # message headers of 31 B) takes ~615 B, so a 4 KiB chunk holds fewer than 7 steps.
    assert steps - 7 <= len(poses) < steps
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
        with pytest.raises(ValueError, match="NaN or negative"):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1], [1, float("nan")])
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
