# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A ROS bag as files, before :func:`kiseki.datasets.rosbag.read_bag_scans` turns its messages
into laser scans: recognised, checked, opened with the pure-Python ``rosbags`` library, and the
messages of the topics it asks for read, within kiseki's limits on what a bag may take.

* recognising: :func:`is_ros_bag` tells a ROS 1 ``.bag`` file, a ROS 2 bag folder (with
  ``metadata.yaml``) and a ROS 2 storage file (``.db3``, or ``.mcap`` with CDR messages) from
  their heads (and an MCAP file's summary or first channel), without ``rosbags``;
  :data:`BAG_KINDS` names the three kinds (:func:`kiseki.datasets.rosbag_writer.write_bag`
  writes each).
* checking (:func:`check_bag_files`): the path and, in a bag folder, each of its files pass
  kiseki's input checks; a ROS 2 bag folder's ``metadata.yaml`` lists no storage file twice;
  what the compressed chunks decompress to is measured within :data:`MAX_BAG_CHUNK_BYTES`, and
  the files of a bag compressed file by file within :data:`MAX_BAG_FILE_BYTES`, before
  ``rosbags`` decompresses any of them whole.
* opening (:func:`open_bag`) and reading (:func:`read_messages`, within
  :data:`MAX_BAG_MESSAGE_BYTES`): ``rosbags``' AnyReader, its errors (a damaged sqlite3 file, a
  compressed file cut short, corrupt messages) turned into :class:`~kiseki.errors.LogFormatError`
  naming the bag.
"""

from __future__ import annotations

import os
import sqlite3
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

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
from kiseki._support.yaml import safe_load_12
from kiseki.errors import LogFormatError

__all__ = [
    "BAG_KINDS",
    "MAX_BAG_CHUNK_BYTES",
    "MAX_BAG_FILE_BYTES",
    "MAX_BAG_MESSAGE_BYTES",
    "check_bag_files",
    "is_ros_bag",
    "open_bag",
    "read_messages",
]

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

_ROS1_MAGIC = b"#ROSBAG V2.0\n"
_SQLITE_MAGIC = b"SQLite format 3\x00"
_MCAP_MAGIC = b"\x89MCAP0\r\n"

_NO_LIMIT = 1 << 62


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


# --- checking and opening a bag's files ---


def check_bag_files(path: Path) -> None:
    """Raises unless ``path`` is a ROS bag that :func:`open_bag` may open: FileNotFoundError when
    it does not exist; LogFormatError when it (or, in a bag folder, one of its files) fails
    kiseki's input checks, is no ROS bag, has a ``metadata.yaml`` that lists a file twice, or has
    compressed chunks or files past MAX_BAG_CHUNK_BYTES or MAX_BAG_FILE_BYTES."""
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
def open_bag(path: Path) -> Iterator[Any]:
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


def read_messages(path: Path, reader: Any, wanted: list[str]) -> dict[str, list[Any]]:
    """The deserialized messages of the topics ``wanted`` of an open bag (:func:`open_bag`), by
    topic, within MAX_BAG_MESSAGE_BYTES; rosbags' errors become LogFormatError naming the bag."""
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
    return messages
