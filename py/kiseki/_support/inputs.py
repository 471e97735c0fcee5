# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Inputs are read within bounds: every reader of a user's file passes it here first.

* **Only regular files and folders.** A character or block device (``/dev/zero``), a FIFO or a
  socket, or a link to one, is refused with one line naming the path and what it is, from
  ``os.stat`` alone: opening a FIFO blocks until a writer comes, and reading a device may never
  end. A path where nothing is passes (the reader says in its own words what is missing).
* **A stated size limit per format.** A file read whole is refused past its format's limit, and
  a compressed one (gzip, bzip2, zstd, lz4) past the limit of what it decompresses to. Sizes are
  counted while reading, in pieces of :data:`CHUNK` bytes, never trusted from a header (a
  header's claim may refuse a file early, never let one through): a file that grows while it
  is read, or a stream that decompresses to more than it claims, is stopped at the limit. The
  message states the limit (``intel.log.gz: decompresses to more than 1 GiB (kiseki's limit for
  CARMEN logs)``).
* **Interruptible.** Each piece is one short call into C; between two of them the interpreter
  runs the SIGINT and SIGTERM handlers, so an interruption ends a long read within a fraction of
  a second. (Python's own ``read()`` of a whole file is one C loop that does not return until
  the end of the file: on ``/dev/zero`` it never returns and never lets a handler run.)

Readers state their limits as module constants and call :func:`check_input` (files opened by
another library, or by kiseki's C++ core, are checked this way before their path is passed on),
:func:`read_input` or :func:`read_input_text`."""

from __future__ import annotations

import bz2
import gzip
import io
import os
import stat
import zipfile
import zlib
from pathlib import Path
from typing import IO, Literal

import numpy as np

__all__ = [
    "CHUNK",
    "CSV_LIMIT",
    "GIB",
    "GZIP_MAGIC",
    "MIB",
    "YAML_LIMIT",
    "check_input",
    "check_npz",
    "decompressed_size",
    "describe_bytes",
    "read_input",
    "read_input_text",
    "special_kind",
]

MIB = 1 << 20
GIB = 1 << 30
CHUNK = MIB  # bytes per read: at disk or decompression speed, well under a second each

YAML_LIMIT = 16 * MIB
"""Scene, map, waypoint, configuration and map-description YAML files: kiseki's largest are a
few hundred KB (a waypoint file of 10,000 marks is about 2 MB), and PyYAML reads about 1 MB/s."""

CSV_LIMIT = 256 * MIB
"""Command, trajectory, points and magnetic-sample CSV files: a million rows (the row limit of
the command, trajectory and points files) of 9 numbers is about 100 MB."""

GZIP_MAGIC = b"\x1f\x8b"
_KINDS = (
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISSOCK, "a socket"),
)


def special_kind(mode: int) -> str:
    """What a file that is neither a regular file nor a folder is, from its ``st_mode``: ``a
    character device``, ``a FIFO (named pipe)``, ... (``a special file`` when none of those)."""
    return next((name for test, name in _KINDS if test(mode)), "a special file")


def describe_bytes(count: int) -> str:
    """``2 GiB``, ``256 MiB``, ``1.5 GiB``, ``4096 bytes``: a limit as messages state it."""
    for unit, name in ((GIB, "GiB"), (MIB, "MiB"), (1 << 10, "KiB")):
        if count >= unit:
            return f"{count / unit:.4g} {name}"
    return f"{count} bytes"


def check_input(
    path: str | os.PathLike,
    what: str = "",
    limit: int | None = None,
    error: type[Exception] = ValueError,
) -> os.stat_result | None:
    """The ``os.stat`` of ``path`` (links followed), or None when nothing is there. Raises
    ``error`` naming the path when it is neither a regular file nor a folder, and, with a
    ``limit``, when it is a regular file of more than ``limit`` bytes (``what``: the plural
    name of the format, as the message states the limit for it)."""
    try:
        info = os.stat(path)
    except FileNotFoundError:
        return None
    except NotADirectoryError:  # a path through a file: nothing is there either
        return None
    mode = info.st_mode
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        kind = special_kind(mode)
        target = ""
        if os.path.islink(path):
            target = f" (a link to {os.path.realpath(path)})"
        raise error(f"{path}: {kind}{target}, not a regular file or folder")
    if limit is not None and stat.S_ISREG(mode) and info.st_size > limit:
        raise error(f"{path}: larger than {_limit_text(limit, what)}")
    return info


def _limit_text(limit: int, what: str) -> str:
    return f"{describe_bytes(limit)} (kiseki's limit for {what})" if what else describe_bytes(limit)


def read_input(
    path: str | os.PathLike,
    what: str,
    limit: int,
    error: type[Exception] = ValueError,
    unzip: Literal["gzip", "bz2"] | None = None,
) -> bytes:
    """The bytes of the regular file at ``path``, read in pieces and counted: more than
    ``limit`` raises ``error`` stating the limit for ``what`` (the plural name of the format).
    ``unzip="gzip"``: gunzipped when the file starts with gzip's magic bytes; ``"bz2"``: the
    file is bzip2 (``.bz2``); either way ``limit`` bounds the decompressed size, and a
    truncated or corrupt stream raises ``error`` naming the file. A missing file raises
    FileNotFoundError; a folder IsADirectoryError."""
    path = Path(path)
    check_input(path, what, limit, error)
    with open(path, "rb") as raw:
        if unzip == "gzip" and raw.read(len(GZIP_MAGIC)) != GZIP_MAGIC:
            unzip = None
        raw.seek(0)
        if unzip is None:
            data = _read_counted(raw, limit)
            if data is None:  # grown since check_input, or a size the system does not know
                raise error(f"{path}: larger than {_limit_text(limit, what)}")
            return data
        try:
            with _decompressing(raw, unzip) as stream:
                data = _read_counted(stream, limit)
        except (EOFError, OSError, zlib.error) as exc:
            name = "gzip" if unzip == "gzip" else "bzip2"
            raise error(f"{path}: truncated or corrupt {name} stream ({exc})") from exc
    if data is None:
        raise error(f"{path}: decompresses to more than {_limit_text(limit, what)}")
    return data


def _read_counted(stream: IO[bytes], limit: int) -> bytes | None:
    """``stream`` read to its end in CHUNK pieces, or None once it holds more than ``limit``
    bytes (what was read is dropped)."""
    pieces: list[bytes] = []
    total = 0
    while piece := stream.read(min(CHUNK, limit + 1 - total)):
        total += len(piece)
        if total > limit:
            return None
        pieces.append(piece)
    return b"".join(pieces)


def read_input_text(
    path: str | os.PathLike,
    what: str,
    limit: int,
    error: type[Exception] = ValueError,
    encoding: str = "utf-8",
) -> str:
    """:func:`read_input` decoded (``UnicodeDecodeError`` passes to the caller, which names
    what the file should have been); newlines are kept as written."""
    return read_input(path, what, limit, error).decode(encoding)


def check_npz(
    path: str | os.PathLike, what: str, limit: int, error: type[Exception] = ValueError
) -> None:
    """Refuses (``error``) an ``.npz`` file larger than ``limit``, or whose arrays hold more than
    ``limit`` bytes together, counted from each array's ``.npy`` header (numpy allocates an
    array by its header's shape before reading it; ``zipfile`` never reads a member past its
    stated size). A file that is not a zip of ``.npy`` arrays is left to ``numpy.load``."""

    check_input(path, what, limit, error)
    headers = {
        (1, 0): np.lib.format.read_array_header_1_0,
        (2, 0): np.lib.format.read_array_header_2_0,
    }
    total = 0
    try:
        with zipfile.ZipFile(path) as archive:
            for info in archive.infolist():
                with archive.open(info) as member:
                    version = np.lib.format.read_magic(member)
                    if version in headers:
                        shape, _, dtype = headers[version](member)
                        total += int(np.prod(shape, dtype=object)) * dtype.itemsize
                if total > limit:
                    break
    except (zipfile.BadZipFile, ValueError, OSError, EOFError):
        return  # numpy.load says what is wrong
    if total > limit:
        raise error(f"{path}: its arrays hold more than {_limit_text(limit, what)}")


def decompressed_size(source: IO[bytes] | bytes, compression: str, limit: int) -> int:
    """The size that ``source`` (a compressed stream: ``gzip``, ``bz2``, ``zstd`` or ``lz4``,
    several members or frames one after another too; or one ``zlib`` stream) decompresses to,
    counted in CHUNK pieces of output that are dropped: once past ``limit``, ``limit + 1``.
    A corrupt stream raises its decompressor's error (``OSError``, ``EOFError``,
    ``zlib.error``, ``RuntimeError``, ``zstandard.ZstdError``)."""
    if isinstance(source, bytes | bytearray | memoryview):
        source = io.BytesIO(source)
    if compression == "zlib":
        return _inflated_size(source.read(), limit)
    with _decompressing(source, compression) as stream:
        total = 0
        while piece := stream.read(CHUNK):
            total += len(piece)
            if total > limit:
                return limit + 1
        return total


def _decompressing(source: IO[bytes], compression: str) -> IO[bytes]:
    """A file object reading ``source`` decompressed; ``read(n)`` decompresses at most about
    ``n`` bytes at a time."""
    if compression == "gzip":
        return gzip.GzipFile(fileobj=source, mode="rb")
    if compression == "bz2":
        return bz2.BZ2File(source, mode="rb")
    if compression == "zstd":
        # here: zstandard (a dependency of mcap) loads only for a compressed input
        import zstandard

        return zstandard.ZstdDecompressor().stream_reader(source, read_across_frames=True)
    if compression == "lz4":
        import lz4.frame  # here: lz4 (mcap's, rosbags') loads only for an lz4 input

        return lz4.frame.LZ4FrameFile(source, mode="rb")
    raise ValueError(f"unknown compression {compression!r}")


def _inflated_size(data: bytes, limit: int) -> int:
    """The size one zlib stream (a MATLAB v5 compressed element) inflates to, bounded."""
    inflate = zlib.decompressobj()
    total = 0
    while True:
        out = inflate.decompress(data, CHUNK)
        total += len(out)
        if total > limit:
            return limit + 1
        data = inflate.unconsumed_tail
        if inflate.eof or (not data and len(out) < CHUNK):
            return total
