# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A bag's geometry as ROS defines it: poses carry unit quaternions (scaled or zero ones gave
other headings without a word: map endpoint agreement 96.7 % -> 20-25 %, exit 0) and a scan's
beams span one turn at most; each is refused naming the bag."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import kiseki.datasets.rosbag as rosbag
import kiseki.datasets.rosbag_writer as rosbag_writer
from _helpers.room_log import room_scans
from kiseki.datasets import read_bag_scans, write_bag
from kiseki.errors import LogFormatError
from kiseki.scans import LaserScans


def _scans(n: int = 8) -> LaserScans:
    return room_scans(n, turn=0.5, first=1)


@pytest.mark.parametrize("kind", ["ros1", "ros2-mcap"])
def test_unit_quaternions_read_back_and_others_are_refused(tmp_path: Path, kind: str, monkeypatch):
    scans = _scans()
    ext = ".bag" if kind == "ros1" else ""
    good = read_bag_scans(
        write_bag(scans, tmp_path / f"good{ext}", kind), reference_topic="/ground_truth"
    )
    np.testing.assert_allclose(good.odometry, scans.odometry, atol=1e-6)
    unit = rosbag_writer._yaw_quaternion
    for scale in (1000.0, 0.0, 1.01):
        monkeypatch.setattr(
            rosbag_writer, "_yaw_quaternion", lambda t, s=scale: tuple(s * v for v in unit(t))
        )
        bag = write_bag(scans, tmp_path / f"bad-{scale:g}{ext}", kind)
        monkeypatch.setattr(rosbag_writer, "_yaw_quaternion", unit)
        with pytest.raises(LogFormatError) as caught:
            read_bag_scans(bag)
        assert str(caught.value).startswith(f"{bag}: an orientation (")
        assert f"of norm {scale * 1.0:.6g} is not a unit quaternion" in str(caught.value)
    # within the tolerance (float32 quaternions, rounding): read, normalised
    monkeypatch.setattr(
        rosbag_writer, "_yaw_quaternion", lambda t: tuple(1.0004 * v for v in unit(t))
    )
    near = read_bag_scans(write_bag(scans, tmp_path / f"near{ext}", kind))
    np.testing.assert_allclose(near.odometry, scans.odometry, atol=1e-6)


@pytest.mark.parametrize("angles", [np.zeros(91), 1000.0 * np.arange(91), 1e30 + np.arange(91)])
def test_beams_beyond_one_turn_are_refused(tmp_path: Path, angles) -> None:
    """An angle_increment of 0 put every beam on one ray; 1000 rad, or an angle_min of 1e30,
    read as given."""
    scans = _scans()
    bag = write_bag(
        LaserScans(scans.times, scans.poses, scans.odometry, scans.ranges, angles, 8.0),
        tmp_path / "b.bag",
        "ros1",
    )
    with pytest.raises(LogFormatError) as caught:
        read_bag_scans(bag)
    assert str(caught.value).startswith(f"{bag}: the first scan on '/scan' has angle_min")
    assert str(caught.value).endswith(
        "not beams of one turn at most (angle_min within +-2 pi, a non-zero increment)"
    )


def test_a_frame_the_scans_do_not_use_may_hold_any_quaternion() -> None:
    """tf2 warns about a zero quaternion on, say, an arm's frame and goes on; so does kiseki,
    refusing it only where the laser's mount or the odometry goes through it."""
    from types import SimpleNamespace as Ns

    def transform(parent, child, q):
        header = Ns(frame_id=parent, stamp=Ns(sec=0, nanosec=0))
        translation, rotation = Ns(x=0.1, y=0.0, z=0.0), Ns(x=0.0, y=0.0, z=q[0], w=q[1])
        return Ns(
            header=header,
            child_frame_id=child,
            transform=Ns(translation=translation, rotation=rotation),
        )

    messages = [
        Ns(
            transforms=[
                transform("base_link", "laser", (0.0, 1.0)),
                transform("base_link", "arm", (0.0, 0.0)),
            ]
        )
    ]
    static = rosbag._static_transforms(messages)
    np.testing.assert_allclose(
        rosbag._mount(Path("b"), static, "base_link", "laser"), [0.1, 0.0, 0.0]
    )
    assert np.isnan(static["arm"][1][2])
    assert np.isnan(rosbag._mount(Path("b"), static, "base_link", "arm")[2])


@pytest.mark.parametrize("range_max", [1e10, 0.0])
def test_a_range_max_past_the_bound_is_refused_naming_the_bag(tmp_path: Path, range_max) -> None:
    """A range_max of 1e10 was read, then refused by the range rule naming no file."""
    scans = _scans()
    object.__setattr__(scans, "max_range", range_max)  # past what LaserScans itself takes
    bag = write_bag(scans, tmp_path / "b.bag", "ros1")
    with pytest.raises(LogFormatError) as caught:
        read_bag_scans(bag)
    assert str(caught.value).startswith(f"{bag}: the first scan on '/scan': range_max: ")
    assert "max_range must be a finite number in (0, 1e+09] m" in str(caught.value)
