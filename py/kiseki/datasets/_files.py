# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reading dataset files that may be gzipped, whatever their extension."""

from __future__ import annotations

from pathlib import Path

from kiseki._support.inputs import GZIP_MAGIC, read_input

__all__ = ["GZIP_MAGIC", "read_maybe_gzipped"]


def read_maybe_gzipped(path: Path, error: type[Exception], what: str, limit: int) -> str:
    """The file's text (latin-1), gunzipped when it starts with the gzip magic bytes, read
    within ``limit`` bytes (decompressed; :func:`kiseki._support.inputs.read_input`, which states
    the limit for ``what``); a truncated or corrupt stream, a special file or a text past the limit
    raises ``error`` naming the file."""
    return read_input(path, what, limit, error, unzip="gzip").decode("latin-1")
