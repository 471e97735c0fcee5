# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Every reader of a user's file reads within bounds (``kiseki._support.inputs``): a file or
what it decompresses to is refused past its format's stated limit, counted while reading, not
taken from a header. The readers run in child processes with an address space limit and a
timeout (``_helpers.bounded_reads``), so that a regression fails here instead of exhausting the
machine; each case reports its time and peak memory (``-s`` prints them). Devices, FIFOs and
signals: ``test_bounded_reads_special.py``."""

from __future__ import annotations

import pytest

import _helpers.bounded_reads as guard
from _helpers.bounded_reads import (
    ZEROS,
    mcap_of_zeros,
    ros1_bag_of_zeros,
    run_cases,
    sparse_file,
    zeros_bz2,
    zeros_gz,
)
from kiseki._support.inputs import GIB, MIB, check_npz, describe_bytes


def test_limits_are_counted_while_reading_and_stated(tmp_path):
    """Past each format's limit: what a file decompresses to is counted, not read from a
    header (the limits lowered here so that the inputs stay small)."""
    low = 8 * MIB
    carmen_gz = zeros_gz(tmp_path / "bomb.log.gz", 1)
    log_lines = tmp_path / "long.log"
    log_lines.write_bytes(b"# a comment\n" * (low // 12 + 1))
    mat = tmp_path / "bomb.mat"
    import numpy as np
    import scipy.io

    zeros = {"t": np.zeros(3), "dPos": np.zeros((2, 3)), "quat": np.zeros((3, 4))}
    scipy.io.savemat(mat, {"m": np.zeros((ZEROS // 24, 3)), **zeros}, do_compression=True)
    cases = [
        {
            "id": "carmen gz bomb",
            "call": "kiseki.datasets:read_carmen_log",
            "args": [str(carmen_gz)],
            "set": {"kiseki.datasets.carmen:MAX_LOG_BYTES": low},
        },
        {
            "id": "carmen plain past limit",
            "call": "kiseki.datasets:read_carmen_log",
            "args": [str(log_lines)],
            "set": {"kiseki.datasets.carmen:MAX_LOG_BYTES": low},
        },
        {
            "id": "wean log gz bomb",
            "call": "kiseki.datasets:read_wean_log",
            "args": [str(carmen_gz)],
            "set": {"kiseki.datasets.wean_log:MAX_LOG_BYTES": low},
        },
        {
            "id": "wean map gz bomb",
            "call": "kiseki.datasets:read_wean_map",
            "args": [str(zeros_gz(tmp_path / "bomb.dat.gz", 5))],
        },
        {
            "id": "text cloud bz2 bomb",
            "call": "kiseki.terrain.cloud_planes:read_cloud",
            "args": [str(zeros_bz2(tmp_path / "bomb.xyz.bz2", 5))],
        },
        {
            "id": "run mcap chunk bomb",
            "call": "kiseki.io.runlog:read_run",
            "args": [str(mcap_of_zeros(tmp_path / "bomb.mcap"))],
            "set": {"kiseki.io.runlog.reader:MAX_CHUNK_BYTES": low},
        },
        {
            "id": "run mcap lz4 chunk bomb",
            "call": "kiseki.io.runlog:read_run",
            "args": [str(mcap_of_zeros(tmp_path / "lz4.mcap", compression="LZ4"))],
            "set": {"kiseki.io.runlog.reader:MAX_CHUNK_BYTES": low},
        },
        {
            "id": "run mcap past total",
            "call": "kiseki.io.runlog:read_run",
            "args": [str(tmp_path / "bomb.mcap")],
            "set": {"kiseki.io.runlog.reader:MAX_RUN_BYTES": low},
        },
        {
            "id": "ros2 mcap chunk bomb",
            "call": "kiseki.datasets:read_bag_scans",
            "args": [str(mcap_of_zeros(tmp_path / "bag.mcap", "cdr"))],
            "set": {"kiseki.datasets.rosbag_files:MAX_BAG_CHUNK_BYTES": low},
        },
        {
            "id": "ros1 bag bz2 chunk bomb",
            "call": "kiseki.datasets:read_bag_scans",
            "args": [str(ros1_bag_of_zeros(tmp_path / "bomb.bag"))],
            "set": {"kiseki.datasets.rosbag_files:MAX_BAG_CHUNK_BYTES": low},
        },
        {
            "id": "kok mat bomb",
            "call": "kiseki.datasets:read_kok_walk",
            "args": [str(mat)],
            "set": {"kiseki.datasets.kok:MAX_MAT_BYTES": low},
        },
    ]
    # files past their real limits: sparse, so refused from their size without being read
    real = [
        ("kiseki.datasets:read_carmen_log", "big.log", GIB, "CARMEN logs"),
        ("kiseki.datasets:read_wean_map", "big.dat", 256 * MIB, "BeeSoft .dat maps"),
        ("kiseki.io.runlog:read_run", "big.mcap", 4 * GIB, "kiseki run logs"),
        ("kiseki.sim.scene:load_scene", "big.yaml", 16 * MIB, "scene files"),
        ("kiseki.io.ros_map:load_map", "big.yaml", 16 * MIB, "ROS map YAML files"),
        ("kiseki.io.trajectory_csv:read_trajectory_csv", "big.csv", 256 * MIB, "trajectory CSV"),
        ("kiseki.datasets:read_field_csv", "big.csv", 256 * MIB, "magnetic sample CSVs"),
        ("kiseki.datasets:read_kok_walk", "big.mat", 256 * MIB, "MATLAB .mat walks"),
        ("kiseki.terrain.cloud_planes:read_cloud", "big.pcd", GIB, "PCD files"),
        ("kiseki.terrain.cloud_planes:read_cloud", "big.xyz", 256 * MIB, "text clouds"),
        ("kiseki.sim.terrain_moves:terrain_stops", "big.bt", 32 * MIB, "OctoMap files"),
    ]
    sparse = tmp_path / "sparse"
    sparse.mkdir()
    for call, name, limit, what in real:
        path = sparse_file(sparse / f"{what.split()[0]}-{name}", limit + 1)
        args = [str(path)] + ([1, 0] if call.endswith("terrain_stops") else [])
        cases.append({"id": f"real limit {what}", "call": call, "args": args})
    results = run_cases(cases, tmp_path)
    stated = {
        "carmen gz bomb": "decompresses to more than 8 MiB (kiseki's limit for CARMEN logs)",
        "carmen plain past limit": "larger than 8 MiB (kiseki's limit for CARMEN logs)",
        "wean log gz bomb": "decompresses to more than 8 MiB (kiseki's limit for Wean robotdata",
        # at their real limits: 256 MiB of the 128 MiB and 320 MiB written
        "wean map gz bomb": "decompresses to more than 256 MiB (kiseki's limit for BeeSoft",
        "text cloud bz2 bomb": "decompresses to more than 256 MiB (kiseki's limit for text clouds",
        "run mcap chunk bomb": "a chunk decompresses to more than 8 MiB (kiseki's limit for chunk",
        "run mcap lz4 chunk bomb": "a chunk decompresses to more than 8 MiB (kiseki's limit",
        "run mcap past total": "its chunks decompress to more than 8 MiB (kiseki's limit for",
        "ros2 mcap chunk bomb": "a chunk decompresses to more than 8 MiB",
        "ros1 bag bz2 chunk bomb": "a chunk decompresses to more than 8 MiB (kiseki's limit for",
        "kok mat bomb": "decompress to more than 8 MiB (kiseki's limit for MATLAB .mat walks)",
    }
    for _, _, limit, what in real:
        stated[f"real limit {what}"] = f"larger than {describe_bytes(limit)} (kiseki's limit for"
    for case_id, text in stated.items():
        result = results[case_id]
        assert text in result["message"], result
        assert result["error"] in ("ValueError", "LogFormatError", "MapFormatError"), result
        assert result["cpu_seconds"] < 3.0, result  # CPU: a loaded machine stretches wall time
        assert result["peak_mb"] < 1500, result
    assert "more than 256 MiB" not in results["carmen gz bomb"]["message"]
    assert describe_bytes(GIB) == "1 GiB" and describe_bytes(4 * GIB) == "4 GiB"


def test_npz_arrays_are_counted_from_their_headers(tmp_path):
    import numpy as np

    path = tmp_path / "nodes.npz"
    np.savez_compressed(path, a=np.zeros(1 << 20), b=np.zeros(3))
    check_npz(path, "test arrays", 9 * MIB)
    with pytest.raises(ValueError, match=r"nodes\.npz: its arrays hold more than 4 MiB"):
        check_npz(path, "test arrays", 4 * MIB)


def test_the_messages_read_from_a_bag_and_a_pcds_stated_size_are_bounded(tmp_path, monkeypatch):
    import numpy as np

    from kiseki.datasets import LaserScans, read_bag_scans, rosbag_files, write_bag
    from kiseki.terrain.cloud_planes import read_cloud

    n, beams = 20, 181
    scans = LaserScans(
        times=np.arange(n, dtype=np.float64),
        poses=np.zeros((n, 3)),
        odometry=np.column_stack([np.arange(n) * 0.1, np.zeros(n), np.zeros(n)]),
        ranges=np.full((n, beams), 2.0, dtype=np.float32),
        angles=np.linspace(-np.pi / 2, np.pi / 2, beams),
        max_range=30.0,
    )
    bag = write_bag(scans, tmp_path / "x.bag", "ros1")
    assert len(read_bag_scans(bag)) == n
    # the scans hold 20 x 760 bytes
    monkeypatch.setattr(rosbag_files, "MAX_BAG_MESSAGE_BYTES", 4000)
    with pytest.raises(ValueError, match=r"x\.bag: the messages on /scan, /odom.* hold more than"):
        read_bag_scans(bag)
    # a binary_compressed PCD stating points of 2 GiB (the reader decompresses what it states)
    pcd = tmp_path / "claims.pcd"
    header = (
        "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 178956971\n"
        "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 178956971\nDATA binary_compressed\n"
    )
    pcd.write_bytes(header.encode() + (16).to_bytes(4, "little") + (2 * GIB).to_bytes(4, "little"))
    with pytest.raises(ValueError, match=r"claims\.pcd: decompresses to more than 1 GiB"):
        read_cloud(pcd)


def test_an_endless_read_is_stopped_by_its_cpu_time(tmp_path, monkeypatch):
    """The guard itself can fail a case: a reader that never returns (a pure-Python loop) ends
    with TimeoutError at the case's CPU limit, well before the whole child's timeout."""
    monkeypatch.setattr(guard, "CASE_CPU_SECONDS", 1)
    (tmp_path / "endless_reader.py").write_text("def read(path):\n    while True:\n        pass\n")
    results = run_cases([{"id": "endless", "call": "endless_reader:read", "args": ["x"]}], tmp_path)
    assert results["endless"]["error"] == "TimeoutError"
    assert results["endless"]["seconds"] < guard.CASE_WALL_SECONDS  # not the wall-clock alarm
