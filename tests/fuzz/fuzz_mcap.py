# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Fuzz the MCAP run reader kiseki.io.runlog.read_run and the decoders of its topics
(laser scans, poses, grid, depth images, velocities); see fuzz_common.py.

An input that starts with the MCAP magic is the file itself (the seeds: the sample run as
kiseki writes it, protobuf and JSON, and its messages in the older all-JSON layout). Any other
input is one message: its first byte picks a topic of the sample run, the rest is that
message's JSON payload, and the file is the sample run in the JSON layout with the message
added (the MCAP framing and CRCs are then valid, so the fuzzer reaches the message decoders
instead of the CRC check).
"""

from __future__ import annotations

import base64
import json
from pathlib import Path

import numpy as np
from fuzz_common import main
from mcap.well_known import MessageEncoding, SchemaEncoding
from mcap.writer import CompressionType, Writer

from kiseki.core import Pose2
from kiseki.grid import OccupancyGrid
from kiseki.io.runlog import TWIST_SCHEMA, TWIST_SCHEMA_NAME, RunWriter, read_run

MAGIC = b"\x89MCAP0\r\n"
DECODERS = {
    "foxglove.LaserScan": lambda run, topic: (
        run.laser_scans(topic),
        run.laser_scans(topic, truth_topic=None, odom_topic=None),
    ),
    "foxglove.PoseInFrame": lambda run, topic: run.poses(topic),
    "foxglove.Grid": lambda run, topic: run.grid(topic),
    "foxglove.RawImage": lambda run, topic: run.depth_images(topic),
    TWIST_SCHEMA_NAME: lambda run, topic: run.velocities(topic),
}


def write_sample(path: Path, compression: str) -> None:
    """Four steps of a run as `kiseki sim run` writes it: a grid, truth poses, transforms,
    scans, odometry, velocities and a depth image."""
    grid = OccupancyGrid(np.array([[0, 100, -1], [0, 0, 100]], dtype=np.int8), 0.5, Pose2(1, 2, 0))
    angles = np.linspace(-1.0, 1.0, 5)
    with RunWriter(path, {"seed": "1"}, chunk_size=512, compression=compression) as w:
        w.write_grid("/map", 0.0, grid)
        for k in range(4):
            t, pose = 0.1 * k, (0.2 * k, 0.1, 0.05 * k)
            w.write_odometry("/odom", t + 0.01, pose, velocity=(0.5, 0.1))
            w.write_pose("/ground_truth", t, pose)
            w.write_transform(t, "world", "base_link", pose)
            w.write_laser_scan(
                "/scan", t, (0.1, 0.0, 0.0), angles, [1, 2, 3, 9, 2], "base_link", max_range=8.0
            )
            w.write_json(
                "/velocity", t, TWIST_SCHEMA_NAME, {"vx": 0.5, "vy": 0, "w": 0.1}, TWIST_SCHEMA
            )
        w.write_depth_image("/depth", 0.3, np.full((2, 3), 1.5, dtype=np.float32), "camera")


def _old_json(value: object) -> object:
    """A decoded protobuf value as the older JSON layout wrote it: bytes as base64 text."""
    if isinstance(value, bytes):
        return base64.b64encode(value).decode("ascii")
    return list(value)  # protobuf's repeated numbers


def sample_messages(path: Path) -> list[tuple[str, str, dict, bytes]]:
    """(topic, schema name, channel metadata, first payload as JSON) of each topic of a sample
    run."""
    run = read_run(path)
    out = []
    for topic, (schema, _) in run.topics().items():
        payload = json.dumps(run.messages(topic)[0][1], default=_old_json).encode()
        out.append((topic, schema, run.channel_metadata(topic), payload))
    return out


def small_run(path: Path, topics, compression: CompressionType, extra: bytes | None = None):
    """The sample's messages (one per topic) with empty JSON schemas, which keeps the file a few
    kilobytes; ``extra`` (first byte: the topic) is added as a second message."""
    with open(path, "wb") as file:
        writer = Writer(file, compression=compression, chunk_size=1024)
        writer.start(profile="", library="kiseki fuzz")
        channels = []
        for topic, schema, metadata, payload in topics:
            schema_id = writer.register_schema(schema, SchemaEncoding.JSONSchema, b"{}")
            channel = writer.register_channel(topic, MessageEncoding.JSON, schema_id, metadata)
            writer.add_message(channel, 0, payload, 0)
            channels.append(channel)
        if extra is not None:
            channel = channels[extra[0] % len(channels)]
            writer.add_message(channel, 5_000_000, extra[1:], 5_000_000)
        writer.finish()


def sample_topics(folder: Path) -> list[tuple[str, str, dict, bytes]]:
    sample = folder / "sample.mcap"
    sample.unlink(missing_ok=True)
    write_sample(sample, "zstd")
    return sample_messages(sample)


def seeds(folder: Path):
    topics = sample_topics(folder)
    yield (folder / "sample.mcap").read_bytes()  # protobuf (Foxglove) and JSON (kiseki) topics
    for compression in (CompressionType.NONE, CompressionType.ZSTD):
        small_run(folder / "seed.mcap", topics, compression)
        yield (folder / "seed.mcap").read_bytes()
    for i, (_, _, _, payload) in enumerate(topics):
        yield bytes([i]) + payload


def reader(folder: Path):
    topics = sample_topics(folder)

    def read(path: Path) -> object:
        data = path.read_bytes()
        if data and not data.startswith(MAGIC):
            small_run(path, topics, CompressionType.NONE, extra=data)
        run = read_run(path)
        for topic, (schema, _) in run.topics().items():
            run.messages(topic)
            decode = DECODERS.get(schema)
            if decode is not None:
                decode(run, topic)
        return run

    return read


if __name__ == "__main__":
    from fuzz_common import workdir

    main(reader(workdir()), seeds, suffix=".mcap", packages=("kiseki", "mcap"))
