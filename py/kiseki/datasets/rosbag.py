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

Why one file over 400 lines: one reader for ROS 1 and ROS 2 bags (rosbags' three storages),
with the checks of their files, scans, odometry and /tf that the three share. Writing is
:mod:`kiseki.datasets.rosbag_writer`; what both share about ROS messages (frames, stamps,
quaternions, planar poses) is :mod:`kiseki.datasets.ros_messages`.
"""

from __future__ import annotations

import os
import sqlite3
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from kiseki._support.chunk_limits import check_mcap_chunks, check_ros1_chunks
from kiseki._support.inputs import (
    GIB,
    MIB,
    YAML_LIMIT,
    check_input,
    decompressed_size,
    describe_bytes,
    read_input_text,
)
from kiseki._support.moved import moved_names
from kiseki._support.yaml import safe_load_12
from kiseki.datasets.ros_messages import (
    NS_PER_S,
    NotARotationError,
    compose,
    frame_name,
    wrap_angle,
    yaw,
    yaw_or_nan,
)
from kiseki.errors import LogFormatError
from kiseki.scans import (
    LaserScans,
    apply_range_rule,
    beams_of_one_turn,
    check_odometry_jumps,
)

__all__ = [
    "BAG_KINDS",
    "MAX_BAG_CHUNK_BYTES",
    "MAX_BAG_FILE_BYTES",
    "MAX_BAG_MESSAGE_BYTES",
    "is_ros_bag",
    "read_bag_scans",
]

# write_bag moved to kiseki.datasets.rosbag_writer (and is kiseki.datasets.write_bag as before);
# the old name answers for one release with a DeprecationWarning (kiseki._support.moved)
__getattr__ = moved_names(__name__, {"write_bag": "kiseki.datasets.rosbag_writer"})

BAG_KINDS = ("ros1", "ros2-sqlite3", "ros2-mcap")

MAX_BAG_MESSAGE_BYTES = 2 * GIB
"""The messages read (scans, odometry, transforms; not the bag's other topics) hold at most this
together: every one is kept, deserialized. A 1081-beam laser at 40 Hz writes 2 GiB in 3.4 hours."""
MAX_BAG_CHUNK_BYTES = 256 * MIB
"""A compressed chunk of a bag (ROS 1 bz2 or lz4, ROS 2 MCAP zstd or lz4) decompresses to at most
this: ``rosbags`` decompresses a chunk whole (recorders write chunks of 768 KB by default)."""
MAX_BAG_FILE_BYTES = 64 * GIB
"""A ROS 2 bag compressed file by file (``compression_mode: file``) has storage files that
decompress to at most this: ``rosbags`` writes them decompressed to a temporary folder."""

LASER_SCAN = "sensor_msgs/msg/LaserScan"
ODOMETRY = "nav_msgs/msg/Odometry"
TF_MESSAGES = ("tf2_msgs/msg/TFMessage", "tf/msg/tfMessage")  # ROS 2 / ROS 1, same layout
TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"

ODOM_FRAME = "odom"
BASE_FRAME = "base_link"
MAP_FRAME = "map"

_ROS1_MAGIC = b"#ROSBAG V2.0\n"
_SQLITE_MAGIC = b"SQLite format 3\x00"
_MCAP_MAGIC = b"\x89MCAP0\r\n"


# --- recognising bags ---


def is_ros_bag(path: str | os.PathLike) -> bool:
    """Whether ``path`` is a ROS 1 ``.bag`` file, a ROS 2 bag folder (with ``metadata.yaml``) or a
    ROS 2 storage file (``.db3``, or ``.mcap`` with CDR messages: kiseki's own simulated runs are
    MCAP too, with JSON messages). Reads only the head (and the MCAP summary) of a file."""
    path = Path(path)
    if path.is_dir():
        return (path / "metadata.yaml").is_file()
    suffix = path.suffix.lower()
    if suffix not in (".bag", ".db3", ".mcap") or not path.is_file():
        return False  # a FIFO would block, a device not end
    try:
        with path.open("rb") as f:
            head = f.read(len(_SQLITE_MAGIC))
    except OSError:
        return False
    if suffix == ".bag":
        return head.startswith(_ROS1_MAGIC)
    if suffix == ".db3":
        return head == _SQLITE_MAGIC
    return head.startswith(_MCAP_MAGIC) and _is_ros2_mcap(path)


def _is_ros2_mcap(path: Path) -> bool:
    """A ROS 2 MCAP: its channels' message encoding is ``cdr``; without channels (an empty bag),
    its header profile is ``ros2``."""
    # here, not at the top: the MCAP and rosbags libraries load only for a bag, so that
    # `import kiseki.datasets` stays fast
    from mcap.exceptions import McapError
    from mcap.reader import make_reader
    from mcap.records import Channel, Header
    from mcap.stream_reader import StreamReader

    try:
        with path.open("rb") as f:
            reader = make_reader(f)
            summary = reader.get_summary()
            if summary is not None and summary.channels:
                return any(c.message_encoding == "cdr" for c in summary.channels.values())
            profile = reader.get_header().profile
    except (McapError, OSError, ValueError, EOFError):
        profile = None
    # No summary (a cut file): the first channel record, streamed from the start (which
    # decompresses the chunks before it: first measured, within their limit).
    check_mcap_chunks(path, "MCAP files", MAX_BAG_CHUNK_BYTES, _NO_LIMIT, LogFormatError)
    try:
        with path.open("rb") as f:
            for record in StreamReader(f, skip_magic=False).records:
                if isinstance(record, Channel):
                    return record.message_encoding == "cdr"
                if isinstance(record, Header):
                    profile = record.profile
    except Exception:  # a corrupt tail ends the search, whatever the mcap reader raises
        pass
    return profile == "ros2"


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
    check_input(path, error=LogFormatError)
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such bag")
    if path.is_dir():  # every file of the folder, before rosbags opens one
        for entry in path.iterdir():
            check_input(entry, error=LogFormatError)
    if not is_ros_bag(path):
        raise LogFormatError(
            f"{path}: not a ROS bag (a ROS 1 .bag file, or a ROS 2 bag folder with metadata.yaml"
            " or its .db3 / .mcap file with CDR messages)"
        )
    _check_chunks(path)
    with _open_bag(path) as reader:
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
        messages: dict[str, list[Any]] = {topic: [] for topic in wanted}
        connections = [c for c in reader.connections if c.topic in messages]
        read = 0
        try:
            for connection, _, raw in reader.messages(connections=connections):
                read += len(raw)
                if read > MAX_BAG_MESSAGE_BYTES:
                    raise LogFormatError(
                        f"{path}: the messages on {', '.join(wanted)} hold more than "
                        f"{describe_bytes(MAX_BAG_MESSAGE_BYTES)} (kiseki's limit for the "
                        "messages read from ROS bags)"
                    )
                msg = reader.deserialize(raw, connection.msgtype)
                messages[connection.topic].append(msg)
        except LogFormatError:
            raise
        except Exception as exc:  # rosbags raises its own errors for corrupt data
            raise LogFormatError(f"{path}: unreadable messages ({exc})") from exc

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


_NO_LIMIT = 1 << 62


def _check_chunks(path: Path) -> None:
    """Measures, within MAX_BAG_CHUNK_BYTES and MAX_BAG_FILE_BYTES, what the bag's compressed
    chunks and files decompress to, before rosbags decompresses each of them whole."""
    files, compressed, listed = [path], False, set()
    if path.is_dir():
        meta = path / "metadata.yaml"
        text = read_input_text(meta, "ROS 2 bag metadata files", YAML_LIMIT, LogFormatError)
        try:
            info = safe_load_12(text)["rosbag2_bagfile_information"]
            compressed = str(info.get("compression_mode", "")).lower() == "file"
            compressed &= str(info.get("compression_format", "")).lower() == "zstd"
            names = [str(name) for name in info.get("relative_file_paths") or []]
            listed = set(names)
        except (yaml.YAMLError, KeyError, TypeError, AttributeError):
            names = []  # rosbags says what is wrong with it
        twice = sorted({name for name in names if names.count(name) > 1})
        if twice:  # rosbags read each of its messages twice, without a word
            raise LogFormatError(
                f"{meta}: relative_file_paths lists {twice[0]} more than once (its messages "
                "would be read as many times)"
            )
        files = sorted(entry for entry in path.iterdir() if entry.is_file() and entry != meta)
    for file in files:
        # the storage files the metadata lists are compressed (rosbags opens those only)
        if compressed and file.name in listed:
            try:
                with open(file, "rb") as raw:
                    size = decompressed_size(raw, "zstd", MAX_BAG_FILE_BYTES)
            except Exception as err:  # noqa: BLE001 (zstandard's errors have no common base)
                # the reader failed on these with a bare EOFError ("Aborted.") or a traceback
                why = str(err) or type(err).__name__
                raise LogFormatError(
                    f"{file}: not a whole zstd file, as the bag's metadata.yaml says its files "
                    f"are (compression_mode: file): {why}"
                ) from None
            if size > MAX_BAG_FILE_BYTES:
                raise LogFormatError(
                    f"{file}: decompresses to more than {describe_bytes(MAX_BAG_FILE_BYTES)} "
                    "(kiseki's limit for the files of ROS 2 bags)"
                )
        elif file.suffix.lower() == ".mcap":
            check_mcap_chunks(file, "ROS bags", MAX_BAG_CHUNK_BYTES, _NO_LIMIT, LogFormatError)
        elif file.suffix.lower() == ".bag":
            check_ros1_chunks(file, "ROS bags", MAX_BAG_CHUNK_BYTES, LogFormatError)


@contextmanager
def _open_bag(path: Path) -> Iterator[Any]:
    """An open ``rosbags`` AnyReader; its errors become LogFormatError naming the bag."""
    # here: rosbags loads only for a bag (see _is_ros2_mcap)
    from rosbags.highlevel import AnyReader, AnyReaderError
    from rosbags.typesys import Stores, get_typestore

    is_ros1 = path.is_file() and path.suffix.lower() == ".bag"
    store = get_typestore(Stores.ROS1_NOETIC if is_ros1 else Stores.ROS2_HUMBLE)
    try:
        reader = AnyReader([path], default_typestore=store)
        reader.open()
    except (AnyReaderError, UnicodeDecodeError, sqlite3.Error) as exc:  # a damaged .db3 file
        raise LogFormatError(f"{path}: unreadable ROS bag ({exc})") from exc
    except EOFError as exc:  # a compressed file cut short: the command line printed "Aborted."
        raise LogFormatError(f"{path}: a compressed file of the bag is cut short ({exc})") from exc
    try:
        yield reader
    except EOFError as exc:
        raise LogFormatError(f"{path}: a compressed file of the bag is cut short ({exc})") from exc
    finally:
        reader.close()


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
    max_range = float(np.float32(first.range_max))
    if not (np.isfinite(max_range) and max_range > 0):
        raise LogFormatError(
            f"{path}: the first scan on {topic!r} has range_max {first.range_max}: not a "
            "positive finite number"
        )
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
