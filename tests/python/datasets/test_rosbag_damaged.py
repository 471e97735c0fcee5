# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Damaged ROS 2 bags, each one line naming the bag or its file: a bag compressed file by file
(metadata.yaml: compression_mode file, zstd) reads as the same bag uncompressed; cut short, or
not compressed as its metadata says, it printed "Aborted." or a traceback; a .db3 bag with a
damaged topics table named no file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
import zstandard

from _helpers.room_log import room_scans
from kiseki.datasets import read_bag_scans, write_bag
from kiseki.errors import LogFormatError
from kiseki.scans import LaserScans


def _scans(n: int = 12) -> LaserScans:
    return room_scans(n, first=1)


def _compress_files(bag: Path, cut: bool = False, plain: bool = False) -> Path:
    """The bag with its storage file zstd-compressed (or only declared so: ``plain``), as
    rosbag2 writes with compression_mode file; ``cut``: the compressed file's second half lost."""
    meta = bag / "metadata.yaml"
    doc = yaml.safe_load(meta.read_text())
    info = doc["rosbag2_bagfile_information"]
    (storage,) = info["relative_file_paths"]
    data = (bag / storage).read_bytes()
    packed = data if plain else zstandard.ZstdCompressor().compress(data)
    (bag / storage).unlink()
    (bag / f"{storage}.zstd").write_bytes(packed[: len(packed) // 2] if cut else packed)
    info["compression_mode"], info["compression_format"] = "file", "zstd"
    info["relative_file_paths"] = [f"{storage}.zstd"]
    for entry in info.get("files", []):
        entry["path"] = f"{entry['path']}.zstd"
    meta.write_text(yaml.safe_dump(doc))
    return bag


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    return write_bag(_scans(), tmp_path / "bag", "ros2-mcap")


def test_a_file_compressed_bag_reads_as_the_bag_itself(bag: Path) -> None:
    want = read_bag_scans(bag)
    got = read_bag_scans(_compress_files(bag))
    assert len(got) == len(want) == 12
    np.testing.assert_array_equal(got.ranges, want.ranges)
    np.testing.assert_array_equal(got.odometry, want.odometry)


def test_a_cut_compressed_file_is_one_line_naming_the_bag(bag: Path) -> None:
    _compress_files(bag, cut=True)
    with pytest.raises(LogFormatError) as caught:
        read_bag_scans(bag)
    assert str(caught.value).startswith(f"{bag}: a compressed file of the bag is cut short")


def test_a_file_the_metadata_calls_zstd_but_is_not_is_named(bag: Path) -> None:
    _compress_files(bag, plain=True)
    with pytest.raises(LogFormatError) as caught:
        read_bag_scans(bag)
    assert str(caught.value).startswith(f"{bag}/bag.mcap.zstd: not a whole zstd file")


def test_a_damaged_sqlite_bag_is_one_line_naming_the_bag(tmp_path: Path) -> None:
    """A topic type that is not UTF-8 in a .db3 bag said only "'utf-8' codec can't decode
    byte 0xff in position 0", naming no file."""
    import sqlite3

    bag = write_bag(_scans(), tmp_path / "bag", "ros2-sqlite3")
    (db,) = bag.glob("*.db3")
    with sqlite3.connect(db) as connection:
        connection.execute("update topics set type = CAST(X'ff6f6f' AS TEXT) where name = '/scan'")
    with pytest.raises(LogFormatError) as caught:
        read_bag_scans(bag)
    assert str(caught.value).startswith(f"{bag}: unreadable ROS bag ('utf-8' codec")


def test_other_files_in_a_compressed_bags_folder_are_left_alone(bag: Path) -> None:
    """Only the storage files metadata.yaml lists are compressed: a notes file beside them was
    refused as "not a whole zstd file"."""
    _compress_files(bag)
    (bag / "notes.txt").write_text("recorded on the second floor\n")
    assert len(read_bag_scans(bag)) == 12


def test_a_storage_file_listed_twice_is_refused(bag: Path) -> None:
    """rosbags read each message of a file that metadata.yaml lists twice twice over (80 scans
    from 40)."""
    meta = bag / "metadata.yaml"
    doc = yaml.safe_load(meta.read_text())
    info = doc["rosbag2_bagfile_information"]
    info["relative_file_paths"] = info["relative_file_paths"] * 2
    meta.write_text(yaml.safe_dump(doc))
    with pytest.raises(LogFormatError) as caught:
        read_bag_scans(bag)
    assert str(caught.value).startswith(f"{meta}: relative_file_paths lists bag.mcap more than")
