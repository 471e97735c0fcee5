# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The ROS bag reader's limits live in one place, ``kiseki.datasets.rosbag_files``: lowering one
there changes what :func:`~kiseki.datasets.read_bag_scans` refuses, and
``kiseki.datasets.rosbag`` holds no copy of them (its old names read rosbag_files' value at the
time, with a DeprecationWarning)."""

from __future__ import annotations

import pytest

from _helpers.room_log import room_scans
from kiseki.datasets import read_bag_scans, rosbag, rosbag_files, write_bag
from kiseki.errors import LogFormatError

LIMITS = ("MAX_BAG_CHUNK_BYTES", "MAX_BAG_FILE_BYTES", "MAX_BAG_MESSAGE_BYTES")


def test_a_limit_lowered_in_rosbag_files_is_the_one_the_reader_and_the_old_name_see(
    tmp_path, monkeypatch
):
    scans = room_scans(12, first=1)
    bag = write_bag(scans, tmp_path / "x.bag", "ros1")
    assert len(read_bag_scans(bag)) == len(scans)
    monkeypatch.setattr(rosbag_files, "MAX_BAG_MESSAGE_BYTES", 4000)
    with pytest.raises(LogFormatError, match=r"x\.bag: the messages on /scan, /odom.* hold more"):
        read_bag_scans(bag)
    for name in LIMITS:
        assert name in rosbag_files.__all__ and name not in rosbag.__all__
        assert name not in vars(rosbag)  # no copy, taken at import, to be mistaken for the limit
        moved = f"moved to kiseki.datasets.rosbag_files.{name}"
        with pytest.warns(DeprecationWarning, match=moved):
            assert getattr(rosbag, name) == getattr(rosbag_files, name)
    with pytest.warns(DeprecationWarning):
        assert rosbag.MAX_BAG_MESSAGE_BYTES == 4000  # the live value, not the one at import


@pytest.mark.parametrize("name", LIMITS)
def test_a_limit_set_by_its_old_name_is_refused_naming_where_to_set_it(name):
    """``rosbag.MAX_BAG_FILE_BYTES = ...`` set a module attribute that the reader, which reads
    rosbag_files', never looked at: a limit raised that way was silently not raised."""
    before = getattr(rosbag_files, name)
    with pytest.raises(AttributeError) as caught:
        setattr(rosbag, name, before * 2)
    assert str(caught.value) == (
        f"kiseki.datasets.rosbag.{name} moved to kiseki.datasets.rosbag_files.{name}; set it "
        "there (here it would change nothing)"
    )
    assert name not in vars(rosbag) and getattr(rosbag_files, name) == before


def test_names_that_stayed_in_the_module_are_set_as_before(monkeypatch):
    monkeypatch.setattr(rosbag, "ODOM_FRAME", "odom_combined")
    assert rosbag.ODOM_FRAME == "odom_combined"
