# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Fuzz the CARMEN log reader (kiseki.datasets.read_carmen_log); see fuzz_common.py."""

from __future__ import annotations

import gzip
from pathlib import Path

from fuzz_common import head_lines, main, shared_data

from kiseki.datasets.carmen import read_carmen_log

# A ROBOTLASER1 with 3 beams and 1 remission (CARMEN's field order).
ROBOTLASER1 = (
    b"ROBOTLASER1 0 -1.57 3.14 1.57 50 0.01 0 3 1.0 2.0 3.0 1 0.5 "
    b"0 0 0 1 2 0.1 0 0 0.5 0.5 0 12.5 host 12.6\n"
)


def pick(path: Path) -> bytes:
    """One line of each message kind near the start of a log, and its max-range PARAM."""
    lines = head_lines(path, 400).splitlines(keepends=True)
    chosen: dict[bytes, bytes] = {}
    for line in lines:
        kind = line.split(b" ", 1)[0]
        if kind == b"PARAM" and b"robot_front_laser_max" not in line:
            continue
        chosen.setdefault(kind, line)
    return b"".join(chosen.values())


def seeds(_folder: Path):
    yield ROBOTLASER1
    yield ROBOTLASER1.replace(b"ROBOTLASER1", b"ODOM 0 0 0 0 0 0 1 host 1\nROBOTLASER1")
    shared = shared_data()
    if shared is None:
        yield b"FLASER 3 1.0 2.0 3.0 0 0 0 0 0 0 1.5 host 1.6\nODOM 0 0 0 0 0 0 1.5 host 1.6\n"
        return
    for log in sorted((shared / "carmen").glob("*.log.gz")):
        text = pick(log)
        yield text
        yield gzip.compress(text, mtime=0)


if __name__ == "__main__":
    main(read_carmen_log, seeds, suffix=".log")
