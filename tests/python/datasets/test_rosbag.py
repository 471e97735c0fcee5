# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the ROS bag reader and writer: the Intel log written as ROS 1, ROS 2 sqlite3 and
ROS 2 MCAP bags and read back, odometry from /tf, interpolation, kiseki runs told apart from
ROS 2 MCAP bags, bad input, and the command line on a bag."""

from __future__ import annotations

import math
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from typer.testing import CliRunner

from kiseki.cli import app, main
from kiseki.datasets import (
    BAG_KINDS,
    is_ros_bag,
    open_scans,
    read_bag_scans,
    read_carmen_log,
    write_bag,
)
from kiseki.io.runlog import RunWriter, read_run
from kiseki.scans import LaserScans

MOUNT = (0.1, -0.05, 0.02)
PREFIX = 200
TF = "tf2_msgs/msg/TFMessage"


def bag_name(kind: str) -> str:
    return "intel.bag" if kind == "ros1" else f"intel-{kind}"


def angle_error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pose differences with the heading difference wrapped to [-pi, pi)."""
    d = np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)
    d[:, 2] = np.remainder(d[:, 2] + np.pi, 2 * np.pi) - np.pi
    return np.abs(d)


@pytest.fixture(scope="module")
def intel(shared_data: Path) -> LaserScans:
    s = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz").scans
    assert np.all(np.diff(s.times[:PREFIX]) > 0)  # the prefix has no time step back
    return LaserScans(
        times=s.times[:PREFIX].copy(),
        poses=s.poses[:PREFIX].copy(),
        odometry=s.odometry[:PREFIX].copy(),
        ranges=np.ascontiguousarray(s.ranges[:PREFIX]),
        angles=s.angles.copy(),
        max_range=s.max_range,
    )


@pytest.fixture(scope="module")
def bags(intel: LaserScans, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("bags")
    return {
        kind: write_bag(intel, folder / bag_name(kind), kind, mount=MOUNT) for kind in BAG_KINDS
    }


def assert_same_scans(read: LaserScans, written: LaserScans, reference: bool = True) -> None:
    assert len(read) == len(written)
    assert read.ranges.dtype == np.float32 and read.ranges.flags.c_contiguous
    assert np.array_equal(read.ranges, written.ranges)
    # angle_min and angle_increment are float32 in a LaserScan: beam angles to float32 rounding
    assert np.abs(read.angles - written.angles).max() < 1e-6
    assert read.max_range == written.max_range
    assert np.abs(read.times - written.times).max() <= 1e-9
    assert angle_error(read.odometry, written.odometry).max() < 1e-6
    if reference:
        assert angle_error(read.poses, written.poses).max() < 1e-6
    else:
        assert np.isnan(read.poses).all() and not read.has_reference_poses


# --- round trips of the Intel log ---


@pytest.mark.parametrize("kind", BAG_KINDS)
def test_round_trip(bags: dict[str, Path], intel: LaserScans, kind: str) -> None:
    bag = bags[kind]
    assert is_ros_bag(bag)
    assert bag.is_file() == (kind == "ros1")
    assert_same_scans(read_bag_scans(bag, reference_topic="/ground_truth"), intel)
    assert_same_scans(read_bag_scans(bag), intel, reference=False)
    assert_same_scans(open_scans(bag, reference_topic="/ground_truth"), intel)


@pytest.mark.parametrize("kind", ["ros2-sqlite3", "ros2-mcap"])
def test_ros2_storage_file_alone_is_a_bag(bags: dict[str, Path], intel: LaserScans, kind: str):
    (storage,) = [p for p in bags[kind].iterdir() if p.suffix in (".db3", ".mcap")]
    assert is_ros_bag(storage)
    assert_same_scans(open_scans(storage, reference_topic="/ground_truth"), intel)


def test_written_bag_has_the_ros_messages(bags: dict[str, Path]) -> None:
    """The bag as any rosbags user sees it: types, frames, the mount, base_link odometry."""
    with AnyReader([bags["ros2-mcap"]]) as reader:
        types = {name: info.msgtype for name, info in reader.topics.items()}
        assert types == {
            "/scan": "sensor_msgs/msg/LaserScan",
            "/odom": "nav_msgs/msg/Odometry",
            "/ground_truth": "nav_msgs/msg/Odometry",
            "/tf_static": TF,
        }
        found: dict[str, Any] = {}
        for connection, _, raw in reader.messages():
            found.setdefault(connection.topic, reader.deserialize(raw, connection.msgtype))
    (mount,) = found["/tf_static"].transforms
    assert (mount.header.frame_id, mount.child_frame_id) == ("base_link", "laser")
    assert mount.transform.translation.x == pytest.approx(MOUNT[0])
    assert 2 * math.asin(mount.transform.rotation.z) == pytest.approx(MOUNT[2])
    odom = found["/odom"]
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")
    assert found["/ground_truth"].header.frame_id == "map"
    assert found["/scan"].header.frame_id == "laser"


def test_kiseki_run_is_not_a_ros_bag(tmp_path: Path) -> None:
    run = tmp_path / "run.mcap"
    with RunWriter(run) as w:
        for k in range(5):
            w.write_odometry("/odom", 0.1 * k, (0.1 * k, 0.0, 0.0))
            w.write_pose("/ground_truth", 0.1 * k, (0.1 * k, 0.0, 0.0))
            ranges = np.full(7, 2.0 + k, dtype=np.float32)
            w.write_laser_scan("/scan", 0.1 * k, (0.1 * k, 0.0, 0.0), np.linspace(-1, 1, 7), ranges)
    assert not is_ros_bag(run)
    scans = open_scans(run)
    expected = read_run(run).laser_scans()
    assert len(scans) == 5 and np.array_equal(scans.ranges, expected.ranges)
    assert np.array_equal(scans.poses, expected.poses)
    cut = tmp_path / "cut.mcap"  # a run cut without its summary is still a run
    cut.write_bytes(run.read_bytes()[: run.stat().st_size // 2])
    assert not is_ros_bag(cut)
    with pytest.raises(ValueError, match="not a ROS bag"):
        open_scans(run, scan_topic="/laser")
    with pytest.raises(ValueError, match="not a ROS bag"):
        read_bag_scans(run)


# --- bags written with rosbags directly ---


class RawBag:
    """Messages written with the plain rosbags writers (ROS 1 or ROS 2 MCAP)."""

    def __init__(self, kind: str) -> None:
        self.ros1 = kind == "ros1"
        self.store = get_typestore(Stores.ROS1_NOETIC if self.ros1 else Stores.ROS2_HUMBLE)
        if TF not in self.store.types:
            self.store.register(
                get_types_from_msg("geometry_msgs/TransformStamped[] transforms", TF)
            )
        self.t = self.store.types
        self.records: list[tuple[str, str, int, Any]] = []

    def header(self, ns: int, frame: str) -> Any:
        stamp = self.t["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)
        extra = {"seq": 0} if self.ros1 else {}
        return self.t["std_msgs/msg/Header"](stamp=stamp, frame_id=frame, **extra)

    def pose(self, x: float, y: float, theta: float) -> tuple[Any, Any]:
        g = "geometry_msgs/msg/"
        q = self.t[g + "Quaternion"](x=0.0, y=0.0, z=math.sin(theta / 2), w=math.cos(theta / 2))
        return self.t[g + "Vector3"](x=x, y=y, z=0.0), q

    def scan(self, topic: str, ns: int, frame: str, ranges: Iterable[float], step=0.01) -> None:
        beams = np.asarray(list(ranges), dtype=np.float32)
        msg = self.t["sensor_msgs/msg/LaserScan"](
            header=self.header(ns, frame),
            angle_min=-0.5,
            angle_max=-0.5 + step * (len(beams) - 1),
            angle_increment=step,
            time_increment=0.0,
            scan_time=0.0,
            range_min=0.0,
            range_max=10.0,
            ranges=beams,
            intensities=np.zeros(0, dtype=np.float32),
        )
        self.records.append((topic, "sensor_msgs/msg/LaserScan", ns, msg))

    def odometry(self, topic: str, ns: int, frame: str, child: str, pose: Iterable[float]):
        g = "geometry_msgs/msg/"
        position, q = self.pose(*pose)
        point = self.t[g + "Point"](x=position.x, y=position.y, z=0.0)
        zero = self.t[g + "Vector3"](x=0.0, y=0.0, z=0.0)
        msg = self.t["nav_msgs/msg/Odometry"](
            header=self.header(ns, frame),
            child_frame_id=child,
            pose=self.t[g + "PoseWithCovariance"](
                pose=self.t[g + "Pose"](position=point, orientation=q), covariance=np.zeros(36)
            ),
            twist=self.t[g + "TwistWithCovariance"](
                twist=self.t[g + "Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
            ),
        )
        self.records.append((topic, "nav_msgs/msg/Odometry", ns, msg))

    def tf(self, topic: str, ns: int, transforms: list[tuple[str, str, Iterable[float]]]) -> None:
        g = "geometry_msgs/msg/"
        stamped = []
        for parent, child, pose in transforms:
            translation, rotation = self.pose(*pose)
            stamped.append(
                self.t[g + "TransformStamped"](
                    header=self.header(ns, parent),
                    child_frame_id=child,
                    transform=self.t[g + "Transform"](translation=translation, rotation=rotation),
                )
            )
        self.records.append((topic, TF, ns, self.t[TF](transforms=stamped)))

    def write(self, path: Path) -> Path:
        types = {topic: msgtype for topic, msgtype, _, _ in self.records}
        if self.ros1:
            writer: Any = Writer1(path)
            serialize = self.store.serialize_ros1
        else:
            writer = Writer2(path, version=9, storage_plugin=StoragePlugin.MCAP)
            serialize = self.store.serialize_cdr
        with writer:
            conns = {
                topic: writer.add_connection(topic, msgtype, typestore=self.store)
                for topic, msgtype in types.items()
            }
            for topic, msgtype, ns, msg in sorted(self.records, key=lambda r: r[2]):
                writer.write(conns[topic], ns, serialize(msg, msgtype))
        return path


@pytest.mark.parametrize("kind", ["ros1", "ros2-mcap"])
def test_odometry_from_tf(
    bags: dict[str, Path], intel: LaserScans, tmp_path: Path, kind: str
) -> None:
    """The /odom messages of a written bag turned into /tf odom -> base_footprint, with the
    mount split over two /tf_static hops (base_footprint -> base_link -> laser)."""
    raw = RawBag(kind)
    with AnyReader([bags["ros2-mcap"]]) as reader:
        for connection, ns, data in reader.messages():
            msg = reader.deserialize(data, connection.msgtype)
            if connection.topic == "/scan":
                raw.scan("/scan", ns, "/laser" if raw.ros1 else "laser", msg.ranges)
            elif connection.topic == "/odom":
                p = msg.pose.pose
                theta = 2 * math.atan2(p.orientation.z, p.orientation.w)
                pose = (p.position.x, p.position.y, theta)
                raw.tf("/tf", ns, [("odom", "base_footprint", pose)])
    # base_footprint -> base_link -> laser composes to MOUNT
    hop = (0.04, 0.0, 0.0)
    rest = (MOUNT[0] - hop[0], MOUNT[1], MOUNT[2])
    first = int(round(intel.times[0] * 1e9))
    raw.tf(
        "/tf_static", first, [("base_footprint", "base_link", hop), ("base_link", "laser", rest)]
    )
    bag = raw.write(tmp_path / ("tf.bag" if raw.ros1 else "tf"))
    scans = read_bag_scans(bag)
    assert len(scans) == len(intel)
    assert angle_error(scans.odometry, intel.odometry).max() < 1e-6
    assert np.array_equal(scans.ranges, intel.ranges)


def test_interpolation_and_scans_outside_the_odometry_are_dropped(tmp_path: Path) -> None:
    """Linear in x, y; shortest arc in theta across +-pi; identity mount for a base-frame laser."""
    raw = RawBag("ros2-mcap")
    s = 10**9
    raw.odometry("/odom", 1 * s, "odom", "base_link", (0.0, 0.0, 2.8))
    raw.odometry("/odom", 2 * s, "odom", "base_link", (1.0, 2.0, -3.0))
    for t in (0.5, 1.0, 1.25, 1.75, 2.0, 2.5):
        raw.scan("/scan", int(t * s), "base_link", [1.0, 2.0, 3.0])
    raw.odometry("/truth", int(1.2 * s), "map", "base_link", (5.0, 5.0, 0.0))
    raw.odometry("/truth", int(1.8 * s), "map", "base_link", (5.0, 6.0, 0.0))
    bag = raw.write(tmp_path / "interp")
    scans = read_bag_scans(bag)
    assert scans.times.tolist() == [1.0, 1.25, 1.75, 2.0]
    arc = 2 * math.pi - 5.8  # from 2.8 to -3.0 the short way, through pi
    expected = [
        (0.0, 0.0, 2.8),
        (0.25, 0.5, 2.8 + 0.25 * arc),
        (0.75, 1.5, math.remainder(2.8 + 0.75 * arc, math.tau)),
        (1.0, 2.0, -3.0),
    ]
    assert angle_error(scans.odometry, np.array(expected)).max() < 1e-12
    assert scans.angles[1] - scans.angles[0] == pytest.approx(0.01)
    assert scans.max_range == 10.0
    with_truth = read_bag_scans(bag, reference_topic="/truth")  # scans outside /truth dropped
    assert with_truth.times.tolist() == [1.25, 1.75]
    assert np.allclose(with_truth.poses, [(5.0, 5.0 + 1 / 12, 0.0), (5.0, 5.0 + 11 / 12, 0.0)])


# --- bad input ---


def test_missing_scan_topic_lists_the_topics(bags: dict[str, Path]) -> None:
    with pytest.raises(ValueError, match="no scan topic '/laser'") as err:
        read_bag_scans(bags["ros1"], scan_topic="/laser")
    message = str(err.value)
    assert str(bags["ros1"]) in message
    assert (
        "/scan (sensor_msgs/msg/LaserScan)" in message
        and "/odom (nav_msgs/msg/Odometry)" in message
    )


@pytest.mark.parametrize("kind", ["ros1", "ros2-mcap"])
def test_empty_bag(tmp_path: Path, kind: str) -> None:
    bag = RawBag(kind).write(tmp_path / ("empty.bag" if kind == "ros1" else "empty"))
    assert is_ros_bag(bag)
    with pytest.raises(ValueError, match="empty bag") as err:
        read_bag_scans(bag)
    assert str(bag) in str(err.value)


def test_wrong_message_types(bags: dict[str, Path], tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="'/odom' has type nav_msgs/msg/Odometry, expected sensor"):
        read_bag_scans(bags["ros2-sqlite3"], scan_topic="/odom")
    with pytest.raises(ValueError, match="'/scan' has type sensor_msgs/msg/LaserScan, expected"):
        read_bag_scans(bags["ros2-sqlite3"], odom_topic="/scan")
    with pytest.raises(ValueError, match="'/scan' has type sensor_msgs/msg/LaserScan, expected"):
        read_bag_scans(bags["ros2-sqlite3"], reference_topic="/scan")


def test_no_odometry(tmp_path: Path) -> None:
    raw = RawBag("ros2-mcap")
    raw.scan("/scan", 10**9, "laser", [1.0, 2.0])
    bag = raw.write(tmp_path / "no-odom")
    with pytest.raises(ValueError, match="no odometry: neither '/odom' nor '/tf'") as err:
        read_bag_scans(bag)
    assert str(bag) in str(err.value) and "/scan (sensor_msgs/msg/LaserScan)" in str(err.value)


def test_missing_mount_and_changing_beams(tmp_path: Path) -> None:
    raw = RawBag("ros2-mcap")
    raw.odometry("/odom", 1, "odom", "base_link", (0.0, 0.0, 0.0))
    raw.odometry("/odom", 3, "odom", "base_link", (1.0, 0.0, 0.0))
    raw.scan("/scan", 2, "laser", [1.0, 2.0])
    with pytest.raises(
        ValueError, match="no transform from 'base_link' to the laser frame 'laser'"
    ):
        read_bag_scans(raw.write(tmp_path / "no-mount"))
    raw.scan("/scan", 3, "laser", [1.0, 2.0, 3.0])
    bag = raw.write(tmp_path / "beams")
    with pytest.raises(ValueError, match="scan 1 on '/scan' has other beams") as err:
        read_bag_scans(bag)
    assert str(err.value).startswith(f"{bag}: ")


def test_not_a_bag(tmp_path: Path) -> None:
    text = tmp_path / "notes.txt"
    text.write_text("hello\n")
    fake = tmp_path / "fake.bag"
    fake.write_text("#ROSBAG V1.2\n")
    folder = tmp_path / "folder"
    folder.mkdir()
    for path in (text, fake, folder):
        assert not is_ros_bag(path)
        with pytest.raises(ValueError, match="not a ROS bag") as err:
            read_bag_scans(path)
        assert str(path) in str(err.value)
    with pytest.raises(ValueError, match="not a ROS bag"):
        open_scans(fake)
    with pytest.raises(FileNotFoundError, match="missing.bag"):
        read_bag_scans(tmp_path / "missing.bag")


@pytest.mark.parametrize("kind", BAG_KINDS)
def test_write_bag_refuses_an_existing_target(intel: LaserScans, tmp_path: Path, kind: str):
    target = tmp_path / "taken"
    target.write_text("keep me")
    with pytest.raises(FileExistsError, match="taken"):
        write_bag(intel, target, kind)
    assert target.read_text() == "keep me"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["taken"]


@pytest.mark.parametrize("kind", BAG_KINDS)
def test_failed_write_leaves_no_bag(intel: LaserScans, tmp_path: Path, kind: str) -> None:
    ranges = intel.ranges.astype(object)
    ranges[100, 0] = "no number"  # fails halfway through the bag
    bad = LaserScans(intel.times, intel.poses, intel.odometry, ranges, intel.angles, 81.83)
    with pytest.raises(ValueError):
        write_bag(bad, tmp_path / "half", kind)
    assert list(tmp_path.iterdir()) == []


def test_write_bag_checks_its_input(intel: LaserScans, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="bag kind"):
        write_bag(intel, tmp_path / "x", "ros3")
    uneven = LaserScans(
        intel.times, intel.poses, intel.odometry, intel.ranges, intel.angles**2, 81.83
    )
    with pytest.raises(ValueError, match="evenly spaced"):
        write_bag(uneven, tmp_path / "x", "ros2-mcap")
    assert list(tmp_path.iterdir()) == []


# --- the command line ---


def test_cli_map_from_a_ros2_mcap_bag(bags: dict[str, Path], tmp_path: Path) -> None:
    out = tmp_path / "map.yaml"
    args = ["map", "from-log", str(bags["ros2-mcap"]), "-o", str(out)]
    done = CliRunner().invoke(app, [*args, "--reference-topic", "/ground_truth"])
    assert done.exit_code == 0, done.output
    assert out.is_file() and "from 200 scans" in done.output
    assert "on or" in done.output  # the endpoint agreement is printed


def test_cli_map_from_a_bag_without_reference_names_the_option(
    bags: dict[str, Path], tmp_path: Path
) -> None:
    out = tmp_path / "map.yaml"
    done = CliRunner().invoke(app, ["map", "from-log", str(bags["ros2-mcap"]), "-o", str(out)])
    assert done.exit_code != 0 and isinstance(done.exception, ValueError)
    assert "no reference poses" in str(done.exception)
    assert "--reference-topic" in str(done.exception)
    assert not out.exists()


def test_cli_wrong_scan_topic_is_one_line(
    bags: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    args = ["map", "from-log", str(bags["ros2-mcap"]), "-o", str(tmp_path / "m.yaml")]
    done = CliRunner().invoke(app, [*args, "--scan-topic", "/nope"])
    assert done.exit_code != 0 and isinstance(done.exception, ValueError)
    monkeypatch.setattr(sys, "argv", ["kiseki", *args, "--scan-topic", "/nope"])
    with pytest.raises(SystemExit) as stop:
        main()
    assert stop.value.code == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kiseki: error: "), lines
    assert "no scan topic '/nope'" in lines[0] and "/scan (sensor_msgs/msg/LaserScan)" in lines[0]
    assert not (tmp_path / "m.yaml").exists()


def test_a_bag_made_from_a_carmen_log_localizes_to_the_logs_trajectory(
    intel: LaserScans, tmp_path: Path
) -> None:
    """The same filter, seed and map on the log and on a ROS 2 MCAP bag made from it (the laser
    mounted off the robot's centre, so the bag's odometry is of base_link and the reader puts
    the mount back): the same trajectory. Bit for bit only until a particle's beam end lands in
    another cell: a LaserScan stores its angles as float32 (7e-8 rad off the log's), and a
    particle filter amplifies any difference once it changes a resampling draw; so the two
    trajectories agree to centimetres, and to micrometres over the first scans."""
    from kiseki.filters import LocalizeConfig, localize
    from kiseki.mapping import MapBuildConfig, build_map

    grid = build_map(
        intel.poses, intel.ranges, intel.angles, intel.max_range, MapBuildConfig(resolution=0.05)
    )
    bag = write_bag(intel, tmp_path / "intel-ros2", kind="ros2-mcap", mount=MOUNT)
    from_bag = read_bag_scans(bag, reference_topic="/ground_truth")
    config = LocalizeConfig(method="likelihood-field", odometry_noise=0.1, seed=3)
    log_run = localize(intel, grid, config).estimates
    bag_run = localize(from_bag, grid, config).estimates
    np.testing.assert_allclose(bag_run[:20], log_run[:20], atol=1e-4)
    assert np.abs(bag_run - log_run)[:, :2].max() < 0.1
    assert angle_error(bag_run, log_run)[:, 2].max() < math.radians(2.0)
    drift = np.abs(log_run - intel.poses)[:, :2].max()
    assert drift < 0.3  # and it is a localization, not dead reckoning gone astray
