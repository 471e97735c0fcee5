# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""MCAP run logs, the old Foxglove JSON layout against kiseki's writer (printed, never asserted).

A run of 2,000 laser scans of 1,081 beams (with a ground-truth pose each) and 100 depth images
of 120 x 160 is written and read back, median of 3 repeats:

* before: the layout kiseki wrote until its runs became protobuf: JSON messages (``json``
  channels, ``jsonschema`` schemas), ranges as JSON numbers, depth images as base64 text in
  JSON, written here with the plain ``mcap`` writer (zstd chunks of 128 KiB, flushed after each
  message as kiseki's writer does);
* after: :class:`kiseki.io.runlog.RunWriter` as it is now.

Both files are read with :func:`kiseki.io.runlog.read_run` (which reads either), then
``laser_scans`` and ``depth_images``. Figures: microseconds per scan (write: the scan and pose
messages; read: the file plus ``laser_scans``), microseconds per depth image, file sizes.

Run: python benchmarks/bench_mcap.py
"""

from __future__ import annotations

import base64
import json
import math
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from mcap.writer import CompressionType, Writer

from arguments import no_options  # beside this file
from kiseki.io.runlog import RunWriter, read_run
from timing import machine_line  # beside this file

SCANS, BEAMS, IMAGES, HEIGHT, WIDTH = 2000, 1081, 100, 120, 160
MAX_RANGE = 30.0
ANGLES = np.linspace(-3 * math.pi / 4, 3 * math.pi / 4, BEAMS)
REPEATS = 3


def make_data(seed: int = 7) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    poses = np.column_stack(
        [np.linspace(0, 50, SCANS), np.sin(np.arange(SCANS) / 100), np.arange(SCANS) / 300]
    )
    ranges = rng.uniform(0.1, MAX_RANGE, (SCANS, BEAMS)).astype(np.float32)
    depth = rng.uniform(0.3, 8.0, (IMAGES, HEIGHT, WIDTH)).astype(np.float32)
    return poses, ranges, depth


def _stamp(ns: int) -> dict[str, int]:
    return {"sec": ns // 10**9, "nsec": ns % 10**9}


def _pose(x: float, y: float, theta: float) -> dict:
    return {
        "position": {"x": x, "y": y, "z": 0.0},
        "orientation": {"x": 0.0, "y": 0.0, "z": math.sin(theta / 2), "w": math.cos(theta / 2)},
    }


def _dumps(message: dict) -> bytes:
    return json.dumps(message, separators=(",", ":"), allow_nan=False).encode()


def write_json_layout(path: Path, poses, ranges, depth) -> tuple[float, float]:
    """The old layout with the plain mcap writer: (scan seconds, depth seconds)."""
    with open(path, "wb") as file:
        writer = Writer(file, chunk_size=128 * 1024, compression=CompressionType.ZSTD)
        writer.start(profile="", library="bench")
        ids = {}
        for topic, name in (
            ("/ground_truth", "foxglove.PoseInFrame"),
            ("/scan", "foxglove.LaserScan"),
            ("/depth", "foxglove.RawImage"),
        ):
            schema = writer.register_schema(name, "jsonschema", _dumps({"title": name}))
            meta = {"max_range": repr(MAX_RANGE)} if topic == "/scan" else {}
            ids[topic] = writer.register_channel(topic, "json", schema, meta)

        def add(topic: str, ns: int, message: dict) -> None:
            writer.add_message(ids[topic], log_time=ns, data=_dumps(message), publish_time=ns)
            file.flush()

        start = time.perf_counter()
        for k in range(SCANS):
            ns = k * 100_000_000
            x, y, theta = poses[k]
            pose = _pose(float(x), float(y), float(theta))
            add("/ground_truth", ns, {"timestamp": _stamp(ns), "frame_id": "world", "pose": pose})
            scan = {
                "timestamp": _stamp(ns),
                "frame_id": "world",
                "pose": pose,
                "start_angle": float(ANGLES[0]),
                "end_angle": float(ANGLES[-1]),
                "ranges": ranges[k].astype(np.float64).tolist(),
                "intensities": [],
            }
            add("/scan", ns, scan)
        middle = time.perf_counter()
        for i in range(IMAGES):
            ns = i * 2_000_000_000
            image = {
                "timestamp": _stamp(ns),
                "frame_id": "camera",
                "width": WIDTH,
                "height": HEIGHT,
                "encoding": "32FC1",
                "step": 4 * WIDTH,
                "data": base64.b64encode(depth[i].astype("<f4").tobytes()).decode("ascii"),
            }
            add("/depth", ns, image)
        end = time.perf_counter()
        writer.finish()
    return middle - start, end - middle


def write_kiseki(path: Path, poses, ranges, depth) -> tuple[float, float]:
    """kiseki's RunWriter: (scan seconds, depth seconds)."""
    with RunWriter(path, overwrite=True) as w:
        start = time.perf_counter()
        for k in range(SCANS):
            t = k / 10
            w.write_pose("/ground_truth", t, poses[k])
            w.write_laser_scan("/scan", t, poses[k], ANGLES, ranges[k], max_range=MAX_RANGE)
        middle = time.perf_counter()
        for i in range(IMAGES):
            w.write_depth_image("/depth", 2.0 * i, depth[i])
        end = time.perf_counter()
    return middle - start, end - middle


def read(path: Path, ranges, depth) -> tuple[float, float]:
    """(file + laser_scans seconds, depth_images seconds); checks the values read back."""
    start = time.perf_counter()
    run = read_run(path)
    scans = run.laser_scans(truth_topic=None, odom_topic=None)
    middle = time.perf_counter()
    images = run.depth_images("/depth")
    end = time.perf_counter()
    if not np.array_equal(scans.ranges, ranges) or not all(
        np.array_equal(image, d) for (_, image), d in zip(images, depth, strict=True)
    ):
        raise AssertionError(f"{path}: the values read back differ from those written")
    return middle - start, end - middle


def median_of(fn: Callable[[], tuple[float, float]]) -> tuple[float, float]:
    runs = [fn() for _ in range(REPEATS)]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


def main() -> None:
    print(machine_line(), flush=True)
    poses, ranges, depth = make_data()
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        layouts = (("before (JSON)", write_json_layout), ("after (protobuf)", write_kiseki))
        for label, writer in layouts:
            path = Path(folder) / f"{label.split()[0]}.mcap"
            write = median_of(lambda w=writer, p=path: w(p, poses, ranges, depth))
            got = median_of(lambda p=path: read(p, ranges, depth))
            rows.append((label, write, got, path.stat().st_size))
    print(f"{SCANS} scans of {BEAMS} beams + {IMAGES} depth images {HEIGHT}x{WIDTH}, median of 3")
    print(
        f"{'':16} {'write us/scan':>14} {'write us/image':>15} {'read us/scan':>13}"
        f" {'read us/image':>14} {'file MB':>8}"
    )
    for label, (w_scan, w_image), (r_scan, r_image), size in rows:
        print(
            f"{label:16} {w_scan / SCANS * 1e6:14.1f} {w_image / IMAGES * 1e6:15.1f}"
            f" {r_scan / SCANS * 1e6:13.1f} {r_image / IMAGES * 1e6:14.1f} {size / 1e6:8.2f}"
        )


if __name__ == "__main__":
    no_options(__doc__)
    main()
