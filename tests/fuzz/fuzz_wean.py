# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Fuzz the CMU Wean Hall readers: the BeeSoft ``.dat`` map (``--target map``, the default,
through kiseki.io.ros_map.load_map) and the robotdata logs (``--target log``,
kiseki.datasets.read_wean_log); see fuzz_common.py."""

from __future__ import annotations

import gzip
from pathlib import Path

from fuzz_common import head_lines, main, pick_target, shared_data

from kiseki.datasets.wean_log import read_wean_log
from kiseki.io.ros_map import load_map

TINY_MAP = (
    b"robot_specifications->global_mapsize_x 40\nrobot_specifications->global_mapsize_y 30\n"
    b"robot_specifications->resolution 10\n\nglobal_map[0]: 3 4\n"
    b"-1 -1 0.5\n1.0 0.0 0.25\n-1 0.9 1\n0.1 0.2 0.3\n"
)


def map_window(path: Path, x0: int, y0: int, size_x: int, size_y: int) -> bytes:
    """The real header of a Wean map with a size_x by size_y window of its values."""
    text = gzip.decompress(path.read_bytes()).decode("latin-1").split("\n")
    start = next(i for i, line in enumerate(text) if line.startswith("global_map[0]"))
    res = 10
    header = [
        f"robot_specifications->global_mapsize_x {size_x * res}",
        f"robot_specifications->global_mapsize_y {size_y * res}",
        *(line for line in text[2:start] if line.strip() and "mapsize" not in line),
        "",
        f"global_map[0]: {size_y} {size_x}",
    ]
    rows = [" ".join(text[start + 1 + x].split()[y0 : y0 + size_y]) for x in range(x0, x0 + size_x)]
    return ("\n".join(header + rows) + "\n").encode()


def map_seeds(_folder: Path):
    yield TINY_MAP
    yield gzip.compress(TINY_MAP, mtime=0)
    shared = shared_data()
    if shared is not None:
        window = map_window(shared / "cmu_wean" / "wean.dat.gz", 91, 406, 6, 5)
        yield window
        yield gzip.compress(window, mtime=0)


def log_seeds(_folder: Path):
    yield b"O 1 2 0.5 0.1\nL 1 2 0.5 26 2 0.5 " + b"100 " * 180 + b"0.2\n"
    shared = shared_data()
    if shared is not None:
        for name in ("robotdata1.log.gz", "robotdata2.log.gz"):
            text = head_lines(shared / "cmu_wean" / name, 4)
            yield text
            yield gzip.compress(text, mtime=0)


if __name__ == "__main__":
    if pick_target(("map", "log")) == "map":
        main(load_map, map_seeds, suffix=".dat")
    else:
        main(read_wean_log, log_seeds, suffix=".log")
