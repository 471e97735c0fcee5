# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Readers for recorded robot data: CARMEN logs, ROS 1 and ROS 2 bags, kiseki's simulated runs
(MCAP), the CMU Wean Hall map, and magnetic-field samples (CSV, Aalto robot runs, Kok-Solin
walks); and unknown obstacles added to a recorded log (``occlude_scans``). ``open_scans`` gives
the laser scans of any supported log through one interface; ``read_magnetic_data`` the samples
of any supported magnetic recording."""

from __future__ import annotations

import os
from pathlib import Path

from kiseki._support.inputs import check_input
from kiseki.datasets.carmen import CarmenLog, OdometryRecords, read_carmen_log
from kiseki.datasets.kok import read_kok_walk
from kiseki.datasets.magnetic import (
    MagneticSamples,
    concatenate_samples,
    read_aalto_run,
    read_field_csv,
    read_magnetic_data,
)
from kiseki.datasets.rosbag import BAG_KINDS, is_ros_bag, read_bag_scans
from kiseki.datasets.rosbag_writer import write_bag
from kiseki.datasets.unknown_obstacles import UnknownObstacles, occlude_scans
from kiseki.datasets.wean import WeanMap, read_wean_map
from kiseki.datasets.wean_log import WeanLog, is_wean_log, read_wean_log
from kiseki.errors import LogFormatError
from kiseki.io.runlog import read_run
from kiseki.scans import LaserScans

__all__ = [
    "open_scans",
    "BAG_KINDS",
    "CarmenLog",
    "LaserScans",
    "MagneticSamples",
    "OdometryRecords",
    "UnknownObstacles",
    "WeanLog",
    "WeanMap",
    "concatenate_samples",
    "is_ros_bag",
    "is_wean_log",
    "occlude_scans",
    "read_aalto_run",
    "read_bag_scans",
    "read_carmen_log",
    "read_field_csv",
    "read_kok_walk",
    "read_magnetic_data",
    "read_wean_log",
    "read_wean_map",
    "write_bag",
]


def open_scans(
    path: str | os.PathLike,
    scan_topic: str = "/scan",
    odom_topic: str = "/odom",
    reference_topic: str | None = None,
) -> LaserScans:
    """The laser scans of a log: a ROS 1 bag (.bag) or ROS 2 bag (folder, .db3, or .mcap with
    CDR messages; see :func:`read_bag_scans` for the topics), a CARMEN log (.log, .log.gz, .clf),
    a kiseki run (.mcap, scans of /scan paired with /ground_truth and /odom) or a CMU Wean Hall
    robotdata log (recognised by its content: ``O``/``L`` lines; no reference poses). The topic
    arguments are for bags only: other logs name their own topics or have none."""
    path = Path(path)
    check_input(path, error=LogFormatError)  # before anything opens it: a FIFO would block
    if is_ros_bag(path) or path.suffix.lower() in (".bag", ".db3"):
        return read_bag_scans(path, scan_topic, odom_topic, reference_topic)
    if (scan_topic, odom_topic, reference_topic) != ("/scan", "/odom", None):
        raise ValueError(
            f"{path}: not a ROS bag: the scan, odometry and reference topics can only be "
            "chosen for ROS bags"
        )
    if path.suffix.lower() == ".mcap":
        run = read_run(path)
        topics = run.topics()
        if "/scan" in topics and "/ground_truth" not in topics:
            # laser_scans' hint is its argument (truth_topic=None), which no caller of this
            # function, nor the command line, can give
            raise LogFormatError(
                f"{path}: no ground-truth topic '/ground_truth' (topics: {sorted(topics)}): "
                "the scans are placed by its poses; give a run that records it (kiseki sim run "
                "does)"
            )
        if "/scan" in topics and "/odom" not in topics:
            # laser_scans' hint is its argument (odom_topic=None), as for /ground_truth above
            raise LogFormatError(
                f"{path}: no odometry topic '/odom' (topics: {sorted(topics)}): the scans' "
                "odometry is read from it; give a run that records it (kiseki sim run does)"
            )
        return run.laser_scans()
    if is_wean_log(path):
        return read_wean_log(path).scans
    return read_carmen_log(path).scans
