# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reading dataset files that may be gzipped, whatever their extension."""

from __future__ import annotations

import gzip
import zlib
from pathlib import Path

__all__ = ["read_maybe_gzipped"]

GZIP_MAGIC = b"\x1f\x8b"


def read_maybe_gzipped(path: Path, error: type[Exception]) -> str:
    """The file's text (latin-1), gunzipped when it starts with the gzip magic bytes; a
    truncated or corrupt stream raises ``error`` naming the file."""
    data = path.read_bytes()
    if data.startswith(GZIP_MAGIC):
        try:
            data = gzip.decompress(data)
        except (EOFError, OSError, zlib.error) as exc:
            raise error(f"{path}: truncated or corrupt gzip stream ({exc})") from exc
    return data.decode("latin-1")
