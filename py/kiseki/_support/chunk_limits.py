# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The compressed chunks of MCAP files and ROS 1 bags, measured before a library reads them.

The ``mcap`` and ``rosbags`` readers decompress a chunk whole, in one call (``zstandard``,
``lz4.frame``, ``bz2.decompress``), however large it turns out to be: a chunk of a few KB can
claim, or hold, gigabytes. :func:`check_mcap_chunks` and :func:`check_ros1_chunks` walk a
file's records from its start (opcode and length for MCAP, header and data lengths for ROS 1) and
decompress every compressed chunk in pieces (:func:`kiseki._support.inputs.decompressed_size`),
counting and dropping the output: a chunk past ``chunk_limit``, or all of them together past
``total_limit``, raises ``error`` stating the limit. Each piece returns to the interpreter, so a
long walk is interruptible. The walk stops quietly where the framing ends or breaks (a file cut
short or corrupt): the reader itself reports that. Uncompressed chunks cost a seek each."""

from __future__ import annotations

import io
import os
import struct
from pathlib import Path

from kiseki._support.inputs import decompressed_size, describe_bytes

__all__ = ["check_mcap_chunks", "check_ros1_chunks"]

_MCAP_MAGIC = b"\x89MCAP0\r\n"
_MCAP_CHUNK = 0x06
_MCAP_FOOTER = 0x02
_ROS1_MAGIC = b"#ROSBAG V2.0\n"
_ROS1_CHUNK = b"\x05"
_MAX_ROS1_HEADER = 1 << 20  # a record header holds a few short fields


def _refuse(path, what: str, limit: int, scope: str, error: type[Exception]) -> Exception:
    """``path: a chunk decompresses to more than 256 MiB (kiseki's limit for chunks of ...)``."""
    limit_text = f"{describe_bytes(limit)} (kiseki's limit for {what})"
    verb = "decompresses" if scope == "a chunk" else "decompress"
    return error(f"{path}: {scope} {verb} to more than {limit_text}")


def check_mcap_chunks(
    path: str | os.PathLike,
    what: str,
    chunk_limit: int,
    total_limit: int,
    error: type[Exception] = ValueError,
) -> int:
    """The total decompressed size of the Chunk records of the MCAP file at ``path`` (see the
    module text); ``error`` when one chunk is past ``chunk_limit`` or all are past
    ``total_limit``. A file that is not an MCAP returns 0 (its reader says what it is)."""
    path = Path(path)
    total = 0
    with open(path, "rb") as f:
        size = f.seek(0, os.SEEK_END)
        f.seek(0)
        if f.read(len(_MCAP_MAGIC)) != _MCAP_MAGIC:
            return 0
        at = len(_MCAP_MAGIC)
        while at + 9 <= size:
            opcode, length = struct.unpack("<BQ", f.read(9))
            end = at + 9 + length
            if opcode == _MCAP_FOOTER or end > size:
                break
            if opcode == _MCAP_CHUNK:
                limit = min(chunk_limit, total_limit - total)
                count = _mcap_chunk(f, end, limit)
                if count > chunk_limit:
                    raise _refuse(path, f"chunks of {what}", chunk_limit, "a chunk", error)
                total += count
                if total > total_limit:
                    raise _refuse(path, what, total_limit, "its chunks", error)
            at = end
            f.seek(at)
    return total


def _mcap_chunk(f, end: int, limit: int) -> int:
    """The decompressed size of the Chunk record whose body the file ``f`` is at, counted up
    to ``limit + 1`` (0 for a corrupt record: the reader reports it)."""
    head = f.read(32)  # message start and end times, uncompressed size and CRC, name length
    if len(head) < 32:
        return 0
    (name_length,) = struct.unpack_from("<I", head, 28)
    if f.tell() + name_length + 8 > end:
        return 0
    compression = f.read(name_length).decode("utf-8", "replace")
    (records_length,) = struct.unpack("<Q", f.read(8))
    if f.tell() + records_length > end:
        return 0
    if not compression:
        return records_length
    if compression == "zstd":
        # here: zstandard loads only for a compressed chunk (mcap's decompressor, which sizes
        # its output by the frame header)
        import zstandard

        start = f.tell()
        try:
            claimed = zstandard.frame_content_size(f.read(min(records_length, 18)))
        except zstandard.ZstdError:
            return 0
        f.seek(start)
        if claimed > limit:
            return limit + 1
    return _counted(f, records_length, compression, limit)


def _counted(f, length: int, compression: str, limit: int) -> int:
    """What the next ``length`` bytes of ``f`` decompress to, bounded (0 if corrupt)."""
    try:
        return decompressed_size(io.BufferedReader(_Window(f, length)), compression, limit)
    except Exception:  # noqa: BLE001 (each decompressor has its own errors; the reader reports)
        return 0


class _Window(io.RawIOBase):
    """The next ``length`` bytes of a binary file."""

    def __init__(self, file, length: int) -> None:
        self._file = file
        self._left = length

    def readable(self) -> bool:
        return True

    def readinto(self, buffer) -> int:
        data = self._file.read(min(len(buffer), self._left))
        buffer[: len(data)] = data
        self._left -= len(data)
        return len(data)


def check_ros1_chunks(
    path: str | os.PathLike,
    what: str,
    chunk_limit: int,
    error: type[Exception] = ValueError,
) -> None:
    """Raises ``error`` when a compressed chunk (bz2 or lz4) of the ROS 1 bag at ``path``
    decompresses to more than ``chunk_limit`` bytes (``rosbags`` holds one chunk at a time).
    A file that is not a ROS 1 bag is left to its reader."""
    path = Path(path)
    with open(path, "rb") as f:
        size = f.seek(0, os.SEEK_END)
        f.seek(0)
        if f.read(len(_ROS1_MAGIC)) != _ROS1_MAGIC:
            return
        at = len(_ROS1_MAGIC)
        while at + 8 <= size:
            (header_length,) = struct.unpack("<I", f.read(4))
            if header_length > _MAX_ROS1_HEADER or at + 4 + header_length + 4 > size:
                return  # not a record header: the reader reports it
            header = _ros1_fields(f.read(header_length))
            (data_length,) = struct.unpack("<I", f.read(4))
            start = at + 8 + header_length
            if start + data_length > size:
                return
            compression = header.get(b"compression", b"none").decode("ascii", "replace")
            compressed = header.get(b"op") == _ROS1_CHUNK and compression != "none"
            if compressed and _counted(f, data_length, compression, chunk_limit) > chunk_limit:
                raise _refuse(path, f"chunks of {what}", chunk_limit, "a chunk", error)
            at = start + data_length
            f.seek(at)


def _ros1_fields(header: bytes) -> dict[bytes, bytes]:
    """The ``name=value`` fields of a ROS 1 record header (each after its u32 length)."""
    fields: dict[bytes, bytes] = {}
    at = 0
    while at + 4 <= len(header):
        (length,) = struct.unpack_from("<I", header, at)
        field = header[at + 4 : at + 4 + length]
        name, _, value = field.partition(b"=")
        fields[name] = value
        at += 4 + length
    return fields
