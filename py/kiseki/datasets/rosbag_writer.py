# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Laser scans written as a ROS 1 bag or a ROS 2 bag (sqlite3 or MCAP storage) with the
pure-Python ``rosbags`` library: the inverse of :func:`kiseki.datasets.rosbag.read_bag_scans`
(its topics, frames and message types), so that a bag kiseki writes reads back to the same
scans."""

from __future__ import annotations

import math
import os
import shutil
import tempfile
from collections.abc import Iterator, Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np

from kiseki.datasets.ros_messages import NS_PER_S, TF_MESSAGE_MSG, compose, frame_name, inverse
from kiseki.datasets.rosbag import (
    BASE_FRAME,
    LASER_SCAN,
    MAP_FRAME,
    ODOM_FRAME,
    ODOMETRY,
    TF_MESSAGES,
    TF_STATIC_TOPIC,
)
from kiseki.datasets.rosbag_files import BAG_KINDS
from kiseki.scans import LaserScans

__all__ = ["write_bag"]


def write_bag(
    scans: LaserScans,
    path: str | os.PathLike,
    kind: str = "ros1",
    scan_topic: str = "/scan",
    odom_topic: str = "/odom",
    reference_topic: str = "/ground_truth",
    laser_frame: str = "laser",
    mount: Sequence[float] = (0.0, 0.0, 0.0),
) -> Path:
    """Write ``scans`` as a bag: ``kind`` ``ros1`` (a ``.bag`` file), ``ros2-sqlite3`` or
    ``ros2-mcap`` (a bag folder). ``mount`` is the laser's planar pose (x, y, yaw) in
    ``base_link``; the odometry (and reference poses) of ``base_link`` are the laser's composed
    with its inverse. The bag is written beside ``path`` under a temporary name and renamed when
    complete; an existing ``path`` is refused. Scan times that step back or repeat (some CARMEN
    logs) are written as they are, but the reader orders scans and poses by stamp."""
    # here: rosbags loads only for a bag (see rosbag_files._is_ros2_mcap)
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    path = Path(path)
    if kind not in BAG_KINDS:
        raise ValueError(f"bag kind must be one of {', '.join(BAG_KINDS)}, got {kind!r}")
    if path.exists():
        raise FileExistsError(f"{path}: exists already, not overwriting")
    if not path.parent.is_dir():
        raise FileNotFoundError(f"{path}: directory {path.parent} does not exist")
    mount = np.array(mount, dtype=np.float64)
    if mount.shape != (3,) or not np.isfinite(mount).all():
        raise ValueError(f"mount must be three finite numbers x, y, yaw, got {mount.tolist()}")
    laser_frame = frame_name(laser_frame)
    if laser_frame == BASE_FRAME and mount.any():
        raise ValueError(f"a laser frame {BASE_FRAME!r} is the base frame: its mount must be 0")
    if len(scans) == 0:
        raise ValueError(f"{path}: no scans to write")
    if not np.isfinite(scans.odometry).all():
        raise ValueError(f"{path}: the scans' odometry has NaN or inf poses")
    if not np.isfinite(scans.times).all() or (scans.times < 0).any():
        raise ValueError(f"{path}: scan times must be finite and >= 0")
    angle_min, angle_increment = _beam_spacing(path, scans.angles)

    ros1 = kind == "ros1"
    store = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if TF_MESSAGES[0] not in store.types:  # ROS1_NOETIC in rosbags has no tf2_msgs
        store.register(get_types_from_msg(TF_MESSAGE_MSG, TF_MESSAGES[0]))
    types = store.types
    ns = [round(Fraction(float(t)) * NS_PER_S) for t in scans.times]
    seq = iter(range(1, 2**32))

    def header(stamp: int, frame: str) -> Any:
        sec, nanosec = divmod(stamp, NS_PER_S)
        time = types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
        if ros1:
            return types["std_msgs/msg/Header"](seq=next(seq), stamp=time, frame_id=frame)
        return types["std_msgs/msg/Header"](stamp=time, frame_id=frame)

    def odometry(stamp: int, frame: str, pose: np.ndarray) -> Any:
        geometry = "geometry_msgs/msg/"
        q = types[geometry + "Quaternion"](*_yaw_quaternion(pose[2]))
        where = types[geometry + "Pose"](
            position=types[geometry + "Point"](x=pose[0], y=pose[1], z=0.0), orientation=q
        )
        zero = types[geometry + "Vector3"](x=0.0, y=0.0, z=0.0)
        return types[ODOMETRY](
            header=header(stamp, frame),
            child_frame_id=BASE_FRAME,
            pose=types[geometry + "PoseWithCovariance"](pose=where, covariance=np.zeros(36)),
            twist=types[geometry + "TwistWithCovariance"](
                twist=types[geometry + "Twist"](linear=zero, angular=zero),
                covariance=np.zeros(36),
            ),
        )

    def tf_static() -> Any:
        geometry = "geometry_msgs/msg/"
        transform = types[geometry + "TransformStamped"](
            header=header(ns[0], BASE_FRAME),
            child_frame_id=laser_frame,
            transform=types[geometry + "Transform"](
                translation=types[geometry + "Vector3"](x=mount[0], y=mount[1], z=0.0),
                rotation=types[geometry + "Quaternion"](*_yaw_quaternion(mount[2])),
            ),
        )
        return types[TF_MESSAGES[0]](transforms=[transform])

    back = inverse(mount)
    base_odometry = compose(scans.odometry, back)
    base_reference = compose(scans.poses, back) if scans.has_reference_poses else None
    range_max = float(scans.max_range)
    empty = np.zeros(0, dtype=np.float32)

    def records() -> Iterator[tuple[str, int, Any]]:
        if laser_frame != BASE_FRAME:
            yield TF_STATIC_TOPIC, ns[0], tf_static()
        for i, stamp in enumerate(ns):
            yield odom_topic, stamp, odometry(stamp, ODOM_FRAME, base_odometry[i])
            if base_reference is not None:
                yield reference_topic, stamp, odometry(stamp, MAP_FRAME, base_reference[i])
            beams = np.ascontiguousarray(scans.ranges[i], dtype=np.float32)
            yield (
                scan_topic,
                stamp,
                types[LASER_SCAN](
                    header=header(stamp, laser_frame),
                    angle_min=angle_min,
                    angle_max=angle_min + (len(beams) - 1) * angle_increment,
                    angle_increment=angle_increment,
                    time_increment=0.0,
                    scan_time=0.0,
                    range_min=0.0,
                    range_max=range_max,
                    ranges=beams,
                    intensities=empty,
                ),
            )

    msgtypes = {scan_topic: LASER_SCAN, odom_topic: ODOMETRY, TF_STATIC_TOPIC: TF_MESSAGES[0]}
    if base_reference is not None:
        msgtypes[reference_topic] = ODOMETRY
    if len(msgtypes) != 3 + (base_reference is not None):
        raise ValueError(f"{path}: the scan, odometry and reference topics must differ")
    work = Path(tempfile.mkdtemp(dir=path.parent, prefix=f".{path.name}."))
    try:
        staged = work / path.name
        if ros1:
            _write_ros1(staged, store, msgtypes, records())
        else:
            _write_ros2(staged, store, msgtypes, records(), kind.removeprefix("ros2-"))
        if path.exists():
            raise FileExistsError(f"{path}: appeared while the bag was written, not overwriting")
        os.rename(staged, path)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return path


def _beam_spacing(path: Path, angles: np.ndarray) -> tuple[float, float]:
    """``angle_min`` and ``angle_increment`` of evenly spaced beam angles."""
    angles = np.asarray(angles, dtype=np.float64)
    if angles.ndim != 1 or len(angles) < 1 or not np.isfinite(angles).all():
        raise ValueError(f"{path}: beam angles must be a non-empty 1-D array of finite numbers")
    step = float((angles[-1] - angles[0]) / (len(angles) - 1)) if len(angles) > 1 else 0.0
    spaced = angles[0] + step * np.arange(len(angles))
    if np.abs(spaced - angles).max() > 1e-9:
        raise ValueError(f"{path}: a LaserScan needs evenly spaced beam angles")
    return float(angles[0]), step


def _yaw_quaternion(theta: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(theta / 2), math.cos(theta / 2))


def _write_ros1(
    path: Path, store: Any, msgtypes: dict[str, str], records: Iterator[tuple[str, int, Any]]
) -> None:
    from rosbags.rosbag1 import Writer  # here: rosbags loads only for a bag

    with Writer(path) as writer:
        connections = {
            topic: writer.add_connection(
                topic, msgtype, typestore=store, latching=1 if topic == TF_STATIC_TOPIC else None
            )
            for topic, msgtype in msgtypes.items()
        }
        for topic, stamp, msg in records:
            writer.write(connections[topic], stamp, store.serialize_ros1(msg, msgtypes[topic]))


def _write_ros2(
    path: Path,
    store: Any,
    msgtypes: dict[str, str],
    records: Iterator[tuple[str, int, Any]],
    storage: str,
) -> None:
    from rosbags.rosbag2 import StoragePlugin, Writer  # here: rosbags only for a bag

    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=Writer.VERSION_LATEST, storage_plugin=plugin) as writer:
        connections = {
            topic: writer.add_connection(topic, msgtype, typestore=store)
            for topic, msgtype in msgtypes.items()
        }
        for topic, stamp, msg in records:
            writer.write(connections[topic], stamp, store.serialize_cdr(msg, msgtypes[topic]))
