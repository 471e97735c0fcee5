# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""ROS 1 bags and ROS 2 bags (sqlite3 or MCAP storage) as laser scans, read and written with the
pure-Python ``rosbags`` library, so no ROS installation is needed.

Reading (:func:`read_bag_scans`) returns the same :class:`~kiseki.scans.LaserScans` as
the CARMEN reader, in the laser frame, as kiseki's filters expect:

* scans: ``sensor_msgs/msg/LaserScan`` (ROS 1 ``sensor_msgs/LaserScan``) on ``scan_topic``,
  ordered by their ``header.stamp``, which gives ``times``. Beam ``i`` is at
  ``angle_min + i * angle_increment`` (float32 fields in the message); ``max_range`` is the
  ``range_max`` of the first scan. Every scan must have the first scan's beam count, angles and
  ``header.frame_id`` (the laser frame). Ranges are float32 and follow kiseki's rule
  (``kiseki.scans``): NaN, ``-inf``, negative and zero readings are invalid, kept as NaN and
  counted (``LaserScans.invalid_ranges``); ``+inf`` (REP 117's "nothing within range") is a no
  return, stored as ``max_range``. A ``range_max`` that is not finite and positive is an error.
* odometry: ``nav_msgs/msg/Odometry`` on ``odom_topic`` (odometry frame = its ``header.frame_id``,
  base frame = its ``child_frame_id``); when the bag has no such topic, the ``/tf`` transform that
  moves the laser frame or the first of its ``/tf_static`` parents (the base frame) relative to
  its ``/tf`` parent (the odometry frame). Poses are interpolated to each scan's stamp (linear in
  x and y, shortest arc in the heading) and composed with the laser's mount.
* mount: the base -> laser frame transform, composed from ``/tf_static`` (several hops are
  followed, e.g. ``base_footprint -> base_link -> laser``); identity when the laser frame is the
  base frame. A missing transform is a :class:`~kiseki.errors.LogFormatError`.
* poses (reference): with ``reference_topic``, the ``nav_msgs/msg/Odometry`` poses on that topic
  (e.g. a simulator's ground truth), interpolated and composed with the mount of their
  ``child_frame_id`` like the odometry; all NaN without a ``reference_topic``.

Everything is planar: x, y and the yaw of each pose and transform (roll, pitch and z dropped).
Scans stamped before the first or after the last odometry pose are dropped, since odometry is not
extrapolated; with a ``reference_topic`` the same holds for the reference poses. Odometry or
reference poses that are NaN or infinite at a scan, and an odometry jump of more than
``kiseki.scans.MAX_ODOMETRY_JUMP`` between two consecutive scans, are errors naming the scan
(its index among the scans read, from 0, and its stamp). Frame names are
compared without a leading ``/`` (ROS 1 style ``/base_link`` is ``base_link``).

Writing (:func:`kiseki.datasets.rosbag_writer.write_bag`) converts a :class:`LaserScans`
(e.g. a CARMEN log) into a bag with ``rosbags``' own writers: LaserScan messages, the odometry
of ``base_link`` in ``odom``, the mount on ``/tf_static`` and, when the scans have reference
poses, ``base_link`` in ``map`` on the reference topic. Each message is stamped (and logged) at
its scan's time.

Recognising a bag, checking its files, opening it and reading the messages of its topics within
kiseki's limits is :mod:`kiseki.datasets.rosbag_files` (``BAG_KINDS`` and ``is_ros_bag`` are
importable from here too). The limits (``MAX_BAG_CHUNK_BYTES``, ``MAX_BAG_FILE_BYTES``,
``MAX_BAG_MESSAGE_BYTES``) live there alone, where the reader's checks read them: read or set
them in :mod:`kiseki.datasets.rosbag_files`. Writing is :mod:`kiseki.datasets.rosbag_writer`;
what both share about ROS messages (frames, stamps, quaternions, planar poses) is
:mod:`kiseki.datasets.ros_messages`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from kiseki._support.moved import moved_names
from kiseki.datasets.ros_messages import (
    NS_PER_S,
    NotARotationError,
    compose,
    frame_name,
    wrap_angle,
    yaw,
    yaw_or_nan,
)
from kiseki.datasets.rosbag_files import (
    BAG_KINDS,
    check_bag_files,
    is_ros_bag,
    open_bag,
    read_messages,
)
from kiseki.errors import LogFormatError
from kiseki.scans import (
    LaserScans,
    apply_range_rule,
    beams_of_one_turn,
    check_log_max_range,
    check_odometry_jumps,
)

__all__ = [
    "BAG_KINDS",
    "is_ros_bag",
    "read_bag_scans",
]

# write_bag moved to kiseki.datasets.rosbag_writer (and is kiseki.datasets.write_bag as before);
# the limits are rosbag_files' (copies here, set, changed nothing the reader checks). The old
# names answer for one release with a DeprecationWarning (kiseki._support.moved), the limits
# with rosbag_files' value at the time; assigning one here is refused, naming rosbag_files.
_LIMITS = ("MAX_BAG_CHUNK_BYTES", "MAX_BAG_FILE_BYTES", "MAX_BAG_MESSAGE_BYTES")
_MOVED = {"write_bag": "kiseki.datasets.rosbag_writer"}
__getattr__ = moved_names(__name__, _MOVED | dict.fromkeys(_LIMITS, "kiseki.datasets.rosbag_files"))

LASER_SCAN = "sensor_msgs/msg/LaserScan"
ODOMETRY = "nav_msgs/msg/Odometry"
TF_MESSAGES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")  # ROS 2 / ROS 1, same layout
TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"

ODOM_FRAME = "odom"
BASE_FRAME = "base_link"
MAP_FRAME = "map"


# --- reading ---


@dataclass
class _Track:
    """Timed planar poses of one frame (``child``) in another (``parent``), by stamp."""

    parent: str
    child: str
    ns: list[int]
    poses: list[tuple[float, float, float]]


def read_bag_scans(
    path: str | os.PathLike,
    scan_topic: str = "/scan",
    odom_topic: str = "/odom",
    reference_topic: str | None = None,
) -> LaserScans:
    """The laser scans of a ROS 1 or ROS 2 bag, with laser-frame odometry and, with
    ``reference_topic``, laser-frame reference poses (see the module docstring)."""
    path = Path(path)
    check_bag_files(path)
    with open_bag(path) as reader:
        topics = {name: info.msgtype for name, info in reader.topics.items()}
        if reader.message_count == 0:
            raise LogFormatError(f"{path}: empty bag (no messages)")
        if scan_topic not in topics:
            raise LogFormatError(
                f"{path}: no scan topic {scan_topic!r}; topics: {_describe(topics)}"
            )
        _check_type(path, topics, scan_topic, (LASER_SCAN,))
        use_tf = odom_topic not in topics
        if use_tf and TF_TOPIC not in topics:
            raise LogFormatError(
                f"{path}: no odometry: neither {odom_topic!r} nor {TF_TOPIC!r}; topics: "
                f"{_describe(topics)}"
            )
        wanted = [scan_topic, TF_TOPIC if use_tf else odom_topic]
        if reference_topic is not None:
            if reference_topic not in topics:
                raise LogFormatError(
                    f"{path}: no reference topic {reference_topic!r}; topics: {_describe(topics)}"
                )
            _check_type(path, topics, reference_topic, (ODOMETRY,))
            wanted.append(reference_topic)
        if not use_tf:
            _check_type(path, topics, odom_topic, (ODOMETRY,))
        for tf_topic in (TF_TOPIC, TF_STATIC_TOPIC):
            if tf_topic in topics:
                _check_type(path, topics, tf_topic, TF_MESSAGES)
                wanted.append(tf_topic)
        messages = read_messages(path, reader, wanted)

    scans = messages[scan_topic]
    if not scans:
        raise LogFormatError(f"{path}: no messages on the scan topic {scan_topic!r}")
    laser, ns, ranges, angles, max_range = _scan_arrays(path, scan_topic, scans)
    try:
        static = _static_transforms(messages.get(TF_STATIC_TOPIC, []))
        if use_tf:
            odom = _tf_odometry(path, messages[TF_TOPIC], static, laser, odom_topic)
        else:
            odom = _odometry_track(path, odom_topic, messages[odom_topic])
        tracks = [odom]
        if reference_topic is not None:
            tracks.append(_odometry_track(path, reference_topic, messages[reference_topic]))
    except NotARotationError as err:
        raise LogFormatError(f"{path}: {err}") from None
    keep = np.ones(len(ns), dtype=bool)
    for track in tracks:
        keep &= (ns >= track.ns[0]) & (ns <= track.ns[-1])
    if not keep.any():
        raise LogFormatError(
            f"{path}: no scan on {scan_topic!r} lies within the time span of the odometry"
            + (" and the reference poses" if reference_topic is not None else "")
        )
    ns = ns[keep]
    times = np.array([int(t) / NS_PER_S for t in ns], dtype=np.float64)
    laser_poses = []
    sources = [TF_TOPIC if use_tf else odom_topic, reference_topic][: len(tracks)]
    for track, source in zip(tracks, sources, strict=True):
        mount = _mount(path, static, track.child, laser)
        laser_poses.append(compose(_interpolate(track, ns), mount))
        bad = ~np.isfinite(laser_poses[-1]).all(axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            raise LogFormatError(
                f"{path}: the pose from {source!r} at scan {k} (t = {times[k]:.3f} s) is NaN "
                "or infinite (or a transform on its way has no unit quaternion)"
            )
    poses = laser_poses[1] if reference_topic is not None else np.full((len(ns), 3), np.nan)
    scans = LaserScans(
        times=times,
        poses=poses,
        odometry=laser_poses[0],
        ranges=apply_range_rule(ranges[keep], max_range),
        angles=angles,
        max_range=max_range,
    )
    check_odometry_jumps(path, scans.times, scans.odometry)
    return scans


def _describe(topics: dict[str, str | None]) -> str:
    return ", ".join(f"{name} ({kind})" for name, kind in sorted(topics.items())) or "none"


def _check_type(
    path: Path, topics: dict[str, str | None], topic: str, kinds: Sequence[str]
) -> None:
    if topics[topic] not in kinds:
        raise LogFormatError(
            f"{path}: topic {topic!r} has type {topics[topic]}, expected {' or '.join(kinds)}"
        )


def _stamp_ns(header: Any) -> int:
    return int(header.stamp.sec) * NS_PER_S + int(header.stamp.nanosec)


def _scan_arrays(
    path: Path, topic: str, scans: list[Any]
) -> tuple[str, np.ndarray, np.ndarray, np.ndarray, float]:
    """Laser frame, stamps (ns), ranges, beam angles and max range of the scans, by stamp."""
    first = scans[0]
    beams = len(first.ranges)
    if beams < 1:
        raise LogFormatError(f"{path}: the first scan on {topic!r} has no beams")
    laser = frame_name(first.header.frame_id)
    if not beams_of_one_turn(float(first.angle_min), float(first.angle_increment), beams):
        raise LogFormatError(
            f"{path}: the first scan on {topic!r} has angle_min {first.angle_min} and "
            f"angle_increment {first.angle_increment} rad for {beams} beams: not beams of one "
            "turn at most (angle_min within +-2 pi, a non-zero increment)"
        )
    for index, scan in enumerate(scans):
        if (
            len(scan.ranges) != beams
            or scan.angle_min != first.angle_min
            or scan.angle_increment != first.angle_increment
        ):
            raise LogFormatError(
                f"{path}: scan {index} on {topic!r} has other beams than the first scan "
                f"({len(scan.ranges)} from {scan.angle_min} step {scan.angle_increment} rad, "
                f"not {beams} from {first.angle_min} step {first.angle_increment} rad)"
            )
        if frame_name(scan.header.frame_id) != laser:
            raise LogFormatError(
                f"{path}: scan {index} on {topic!r} is in frame {scan.header.frame_id!r}, the "
                f"first scan in {laser!r}"
            )
    ns = np.array([_stamp_ns(scan.header) for scan in scans], dtype=np.int64)
    order = np.argsort(ns, kind="stable")
    ranges = np.empty((len(scans), beams), dtype=np.float32)
    for row, index in enumerate(order):
        ranges[row] = scans[index].ranges
    angle_min = float(first.angle_min)
    angles = angle_min + float(first.angle_increment) * np.arange(beams, dtype=np.float64)
    # one bound for every log's maximum range (a range_max of 1e10 was read, then refused by
    # the range rule naming no file)
    where = f"{path}: the first scan on {topic!r}: range_max"
    max_range = check_log_max_range(where, float(np.float32(first.range_max)))
    return laser, ns[order], ranges, angles, max_range


def _odometry_track(path: Path, topic: str, messages: list[Any]) -> _Track:
    if not messages:
        raise LogFormatError(f"{path}: no messages on {topic!r}")
    parent = frame_name(messages[0].header.frame_id)
    child = frame_name(messages[0].child_frame_id)
    track = _Track(parent, child, [], [])
    for index, msg in enumerate(messages):
        if (frame_name(msg.header.frame_id), frame_name(msg.child_frame_id)) != (parent, child):
            raise LogFormatError(
                f"{path}: message {index} on {topic!r} is {msg.child_frame_id!r} in "
                f"{msg.header.frame_id!r}, the first one {child!r} in {parent!r}"
            )
        pose = msg.pose.pose
        track.ns.append(_stamp_ns(msg.header))
        track.poses.append((float(pose.position.x), float(pose.position.y), yaw(pose.orientation)))
    return _sorted(track)


def _sorted(track: _Track) -> _Track:
    order = sorted(range(len(track.ns)), key=track.ns.__getitem__)
    return _Track(
        track.parent,
        track.child,
        [track.ns[i] for i in order],
        [track.poses[i] for i in order],
    )


def _transform_pose(transform: Any) -> tuple[float, float, float]:
    t = transform.transform
    return (float(t.translation.x), float(t.translation.y), yaw_or_nan(t.rotation))


def _static_transforms(messages: list[Any]) -> dict[str, tuple[str, tuple[float, float, float]]]:
    """child frame -> (parent frame, planar pose of the child in the parent); the last wins."""
    static: dict[str, tuple[str, tuple[float, float, float]]] = {}
    for msg in messages:
        for transform in msg.transforms:
            static[frame_name(transform.child_frame_id)] = (
                frame_name(transform.header.frame_id),
                _transform_pose(transform),
            )
    return static


def _tf_odometry(
    path: Path,
    messages: list[Any],
    static: dict[str, tuple[str, tuple[float, float, float]]],
    laser: str,
    odom_topic: str,
) -> _Track:
    """The /tf track of the base frame: the laser frame or its first /tf_static parent that
    /tf moves."""
    tracks: dict[tuple[str, str], _Track] = {}
    for msg in messages:
        for transform in msg.transforms:
            parent, child = (
                frame_name(transform.header.frame_id),
                frame_name(transform.child_frame_id),
            )
            track = tracks.setdefault((parent, child), _Track(parent, child, [], []))
            track.ns.append(_stamp_ns(transform.header))
            track.poses.append(_transform_pose(transform))
    moved: dict[str, list[_Track]] = {}
    for track in tracks.values():
        moved.setdefault(track.child, []).append(track)
    frame, seen = laser, set()
    while frame not in moved:
        seen.add(frame)
        if frame not in static or static[frame][0] in seen:
            raise LogFormatError(
                f"{path}: no odometry: no topic {odom_topic!r}, and {TF_TOPIC!r} moves neither "
                f"the laser frame {laser!r} nor one of its {TF_STATIC_TOPIC} parents"
            )
        frame = static[frame][0]
    if len(moved[frame]) > 1:
        parents = sorted(t.parent for t in moved[frame])
        raise LogFormatError(f"{path}: {TF_TOPIC!r} moves {frame!r} in several frames {parents}")
    return _sorted(moved[frame][0])


def _mount(
    path: Path, static: dict[str, tuple[str, tuple[float, float, float]]], base: str, laser: str
) -> np.ndarray:
    """Planar pose of the laser frame in the base frame, composed along /tf_static."""
    mount = np.zeros(3)
    frame, seen = laser, set()
    while frame != base:
        seen.add(frame)
        if frame not in static or static[frame][0] in seen:
            raise LogFormatError(
                f"{path}: no transform from {base!r} to the laser frame {laser!r} on "
                f"{TF_STATIC_TOPIC}"
            )
        parent, pose = static[frame]
        mount = compose(np.array([pose]), mount)[0]
        frame = parent
    return mount


def _interpolate(track: _Track, ns: np.ndarray) -> np.ndarray:
    """Poses of ``track`` at the stamps ``ns`` (within its span): linear in x and y,
    shortest arc in the heading."""
    times = np.array(track.ns, dtype=np.int64)
    poses = np.array(track.poses, dtype=np.float64)
    if len(times) == 1:
        return np.repeat(poses, len(ns), axis=0)
    i0 = (np.searchsorted(times, ns, side="right") - 1).clip(0, len(times) - 2)
    t0, t1 = times[i0], times[i0 + 1]
    span = (t1 - t0).astype(np.float64)
    a = np.where(span > 0, (ns - t0).astype(np.float64) / np.where(span > 0, span, 1.0), 1.0)
    p0, p1 = poses[i0], poses[i0 + 1]
    out = np.empty((len(ns), 3))
    out[:, :2] = p0[:, :2] + a[:, None] * (p1[:, :2] - p0[:, :2])
    out[:, 2] = wrap_angle(p0[:, 2] + a * wrap_angle(p1[:, 2] - p0[:, 2]))
    return out
