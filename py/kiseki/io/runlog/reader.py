# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reading a run log (:func:`read_run`).

Reading (:func:`read_run`)
    The file is read from the start, record by record, without relying on the summary section:
    first the record framing is checked (opcode + length of each record) to find the end of the
    last complete record, then the complete records are parsed with the ``mcap`` stream reader
    (chunk CRCs checked). A file without its footer is a truncated file: :func:`read_run` warns
    (:class:`TruncatedRunWarning`) and returns the messages of the complete chunks, with
    ``SimRun.truncated`` set. For reference, the ``mcap`` 1.6 library itself does not read such a
    file: ``make_reader(...).iter_messages()`` needs the footer and fails (``EndOfFile``,
    ``RecordLengthLimitExceeded`` or ``OSError`` depending on the cut), and its
    ``NonSeekingReader`` yields the messages of the complete chunks before raising
    (``EndOfFile`` or ``struct.error``). A file that is not an MCAP, that was cut before its
    Header record, or whose complete records do not parse (bad CRC, bad JSON, ...) raises
    :class:`~kiseki.errors.LogFormatError` naming the file.

    Messages are decoded by their channel's message encoding: ``protobuf`` (the runs written now)
    and ``json`` (runs written before kiseki used protobuf, whose images and grids hold base64
    text) both read to the same scans, poses, images and grids.

    :meth:`SimRun.laser_scans` returns the same :class:`~kiseki.scans.LaserScans` as
    the CARMEN reader, so simulated runs replay through the interface of real logs.
"""

from __future__ import annotations

import io
import os
import struct
import warnings
from pathlib import Path
from typing import IO, Any

from mcap.exceptions import EndOfFile
from mcap.opcode import Opcode
from mcap.records import Channel, Header, Message, Metadata, Schema, Statistics
from mcap.stream_reader import StreamReader

from kiseki._support.chunk_limits import check_mcap_chunks
from kiseki._support.inputs import check_input
from kiseki.errors import LogFormatError
from kiseki.io.runlog._encoding import (
    _MAGIC,
    _Topic,
)
from kiseki.io.runlog.run import SimRun
from kiseki.io.runlog.schemas import (
    MAX_CHUNK_BYTES,
    MAX_RUN_BYTES,
    TruncatedRunWarning,
)

__all__ = ["read_run"]


class _Prefix(io.RawIOBase):
    """The first ``limit`` bytes of a binary file."""

    def __init__(self, file: IO[bytes], limit: int) -> None:
        self._file = file
        self.remaining = limit

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        view = memoryview(buffer).cast("B")
        size = min(len(view), self.remaining)
        data = self._file.read(size) if size else b""
        view[: len(data)] = data
        self.remaining -= len(data)
        return len(data)


def _complete_prefix(path: Path, file: IO[bytes]) -> tuple[int, bool]:
    """(bytes of complete records, including the closing magic when complete; whether the
    file ends with a footer and the magic), from the record framing alone."""
    size = file.seek(0, io.SEEK_END)
    file.seek(0)
    if file.read(len(_MAGIC)) != _MAGIC:
        raise LogFormatError(f"{path}: not an MCAP file (no MCAP magic at the start)")
    pos = len(_MAGIC)
    first = True
    while True:
        head = file.read(9)
        if len(head) < 9:
            return pos, False
        opcode, length = struct.unpack("<BQ", head)
        if first and opcode != Opcode.HEADER:
            raise LogFormatError(f"{path}: not an MCAP file (first record is not a Header)")
        first = False
        end = pos + 9 + length
        if end > size:
            return pos, False
        file.seek(end)
        if opcode == Opcode.FOOTER:
            tail = file.read(len(_MAGIC))
            if len(tail) < len(_MAGIC):
                return end, False
            if tail != _MAGIC:
                raise LogFormatError(f"{path}: corrupt MCAP (no magic after the footer)")
            return end + len(_MAGIC), True
        pos = end


def read_run(path: str | os.PathLike) -> SimRun:
    """Reads an MCAP run written by :class:`RunWriter` (or any MCAP; its JSON and protobuf
    topics are decoded, older kiseki runs' all-JSON ones too). FileNotFoundError if missing,
    LogFormatError if not an MCAP or corrupt; a file without its footer (writer killed) gives
    the complete chunks with a TruncatedRunWarning."""
    path = Path(path)
    if check_input(path, "kiseki run logs", MAX_RUN_BYTES, LogFormatError) is not None:
        check_mcap_chunks(path, "kiseki run logs", MAX_CHUNK_BYTES, MAX_RUN_BYTES, LogFormatError)
    topics: dict[str, _Topic] = {}
    metadata: dict[str, str] = {}
    schemas: dict[int, Schema] = {}
    channels: dict[int, _Topic] = {}
    statistics: Statistics | None = None
    header_seen = False
    count = 0
    with open(path, "rb") as file:
        limit, complete = _complete_prefix(path, file)
        file.seek(0)
        prefix = _Prefix(file, limit)
        reader = StreamReader(io.BufferedReader(prefix), validate_crcs=True)
        try:
            for record in reader.records:
                if isinstance(record, Header):
                    header_seen = True
                elif isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    if record.id in channels:
                        continue  # repeated in the summary section
                    if record.schema_id != 0 and record.schema_id not in schemas:
                        raise LogFormatError(
                            f"{path}: channel {record.topic!r} refers to missing schema"
                            f" {record.schema_id}"
                        )
                    name = schemas[record.schema_id].name if record.schema_id else ""
                    entry = topics.get(record.topic)
                    if entry is None:
                        entry = _Topic(
                            name,
                            record.message_encoding,
                            dict(record.metadata),
                            schemas.get(record.schema_id),
                        )
                        topics[record.topic] = entry
                    channels[record.id] = entry
                elif isinstance(record, Message):
                    if record.channel_id not in channels:
                        raise LogFormatError(
                            f"{path}: message on unknown channel {record.channel_id}"
                        )
                    channels[record.channel_id].raw.append((record.log_time, count, record.data))
                    count += 1
                elif isinstance(record, Metadata):
                    metadata.update(record.metadata)
                elif isinstance(record, Statistics):
                    statistics = record
        except EndOfFile as exc:
            if complete or prefix.remaining:
                raise LogFormatError(f"{path}: corrupt MCAP (a record overruns its end)") from exc
        except LogFormatError:
            raise
        except Exception as exc:
            # The mcap reader raises McapError subclasses, ValueError (CRC check), struct.error,
            # UnicodeDecodeError, zstandard.ZstdError, RuntimeError (lz4), ... on corrupt data.
            raise LogFormatError(f"{path}: corrupt MCAP ({type(exc).__name__}: {exc})") from exc
    if not header_seen:
        raise LogFormatError(f"{path}: truncated MCAP (cut before the end of its Header)")
    if statistics is not None and statistics.message_count != count:
        raise LogFormatError(
            f"{path}: the summary counts {statistics.message_count} messages, the file has {count}"
        )
    if not complete:
        warnings.warn(
            f"{path}: truncated MCAP (no footer; the writer was probably killed): read the"
            f" {count} messages of the complete chunks, up to byte {limit}",
            TruncatedRunWarning,
            stacklevel=2,
        )
    return SimRun(path, topics, metadata, truncated=not complete)
