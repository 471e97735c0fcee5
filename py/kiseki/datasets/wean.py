# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Reader for the CMU Wean Hall map (BeeSoft ``.dat`` format, plain text or gzip).

Format: header lines ``robot_specifications->name value`` (``resolution`` in cm per cell), then
``global_map[0]: size_y size_x``, then ``size_x * size_y`` numbers, x the outer loop (each text
line is one x, as in the original reader ``bee-map.c``, which fills ``prob[x][y]``). A stored value
``v`` in [0, 1] is known, a negative one unknown (the file uses -1).

Value convention: ``v`` is the probability that the cell is FREE, so occupancy = 1 - v, although
``instruct.txt`` calls it "a probability for occupancy". Evidence from ``wean.dat.gz``:

* 72.8 % of the cells are unknown; of the known ones 78 % have v >= 0.6 and 18 % are exactly
  1.0, but only 5.7 % exactly 0.0. The seen part of a building is mostly free space, walls thin;
* drawn with white = high v, the map reproduces ``wean.gif`` (white corridors, thin black walls):
  of the cells read here as occupied (> 0.65), 85 % fall on dark gif pixels; of the free ones
  (< 0.196), 95 % on bright pixels; with occupancy = v instead, 2 % and 8 %;
* BeeSoft/Rhino tools write this format as ``1 - prob`` and read it back as ``1.0 - temp``; the
  CMU 16-831 starter code also uses 1 - v.

Orientation: ``occupancy[y, x]``, row 0 at y = 0. Shown with row 0 at the bottom it matches
``wean.gif``: cropped to the known area and resampled onto the gif, the known cells overlap the
gif's non-background pixels with IoU 0.99; drawn upside down (row 0 on top) the IoU is 0.32, and
mirrored left-right 0.50. The header's ``autoshifted_x/y`` offsets (0 in Wean) are not applied.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki._support.inputs import MIB
from kiseki._support.numbers_text import NumberTextError, float_array, parse_float
from kiseki._support.schema import MAGNITUDE_LIMIT
from kiseki.datasets._files import read_maybe_gzipped
from kiseki.errors import MapFormatError

__all__ = ["MAX_MAP_BYTES", "WeanMap", "read_wean_map"]

MAX_MAP_BYTES = 256 * MIB
"""A map's text (after gunzip) is read up to this size: ``wean.dat.gz`` holds 4.3 MB of text for
its 800 x 800 cells, so 256 MiB is about 40 million cells."""

_HEADER_LINE = re.compile(r"robot_specifications->(\w+)\s+(\S+)")
_SIZE_LINE = re.compile(r"global_map\[0\]:\s+(\d+)\s+(\d+)")


@dataclass(frozen=True, eq=False)
class WeanMap:
    """Occupancy grid: ``occupancy[y, x]`` in [0, 1], NaN where unknown; row 0 at y = 0."""

    occupancy: np.ndarray  # (H, W) float64
    resolution: float  # metres per cell

    def to_cells(self, occupied_thresh: float = 0.65, free_thresh: float = 0.196) -> np.ndarray:
        """ROS-style int8 cells: 100 if p > occupied_thresh, 0 if p < free_thresh, else -1."""
        if not 0.0 <= free_thresh <= occupied_thresh <= 1.0:
            msg = f"need 0 <= free_thresh <= occupied_thresh <= 1, got {free_thresh}, "
            raise ValueError(msg + f"{occupied_thresh}")
        cells = np.full(self.occupancy.shape, -1, dtype=np.int8)
        with np.errstate(invalid="ignore"):
            cells[self.occupancy > occupied_thresh] = 100
            cells[self.occupancy < free_thresh] = 0
        return cells


def read_wean_map(path: str | os.PathLike) -> WeanMap:
    """Read a BeeSoft ``.dat`` map such as ``wean.dat.gz`` (gzip detected by magic bytes)."""
    path = Path(path)
    text = _read_text(path)
    resolution_cm, size_y, size_x, body, line = _parse_header(path, text)
    stored = _parse_values(path, body, line, size_x * size_y).reshape(size_x, size_y)  # [x, y]
    occupancy = np.where(stored < 0, np.nan, 1.0 - stored).T
    return WeanMap(occupancy=np.ascontiguousarray(occupancy), resolution=resolution_cm / 100.0)


def _read_text(path: Path) -> str:
    return read_maybe_gzipped(path, MapFormatError, "BeeSoft .dat maps", MAX_MAP_BYTES)


def _parse_header(path: Path, text: str) -> tuple[float, int, int, str, int]:
    """Return (resolution in cm, size_y, size_x, text after the size line, its first line)."""
    specs: dict[str, tuple[str, int]] = {}  # name: (value, line)
    pos = 0
    for lineno, line in enumerate(text.split("\n"), start=1):
        end = pos + len(line) + 1
        stripped = line.strip()
        if stripped.startswith("global_map[0]"):
            size = _SIZE_LINE.fullmatch(stripped)
            if size is None or min(int(size[1]), int(size[2])) == 0:
                raise MapFormatError(f"{path}:{lineno}: bad map size line {stripped!r}")
            resolution = _header_resolution(path, specs, int(size[1]), int(size[2]))
            return resolution, int(size[1]), int(size[2]), text[end:], lineno + 1
        spec = _HEADER_LINE.fullmatch(stripped)
        if stripped and spec is None:
            raise MapFormatError(f"{path}:{lineno}: unexpected header line {stripped[:60]!r}")
        if spec is not None:
            specs[spec[1]] = (spec[2], lineno)
        pos = end
    raise MapFormatError(f"{path}: no 'global_map[0]: size_y size_x' line")


def _spec_number(path: Path, specs: dict[str, tuple[str, int]], name: str) -> float | None:
    if name not in specs:
        return None
    text, line = specs[name]
    try:
        value = parse_float(text)
    except ValueError:
        value = float("nan")
    if not np.isfinite(value):
        raise MapFormatError(f"{path}:{line}: robot_specifications->{name} {text!r} is bad")
    return value


def _header_resolution(
    path: Path, specs: dict[str, tuple[str, int]], size_y: int, size_x: int
) -> float:
    resolution = _spec_number(path, specs, "resolution")
    if resolution is None or resolution <= 0:
        raise MapFormatError(f"{path}: missing or non-positive robot_specifications->resolution")
    if not 1e-2 <= resolution <= 100 * MAGNITUDE_LIMIT:  # cm: a ROS map's 1e-4 .. 1e9 m per cell
        raise MapFormatError(
            f"{path}: robot_specifications->resolution {resolution:g} cm is outside "
            "0.01 .. 1e11 cm (a ROS map's 1e-4 .. 1e9 m per cell)"
        )
    for axis, cells in (("x", size_x), ("y", size_y)):
        extent = _spec_number(path, specs, f"global_mapsize_{axis}")
        if extent is not None and extent != cells * resolution:
            msg = f"{path}: global_mapsize_{axis} {extent:g} cm != {cells} cells * {resolution:g}"
            raise MapFormatError(msg)
    return resolution


def _parse_values(path: Path, body: str, first_line: int, count: int) -> np.ndarray:
    """The ``count`` values of the text ``body``, which starts at line ``first_line``."""
    tokens = body.split()
    if len(tokens) != count:
        raise MapFormatError(f"{path}: {len(tokens)} map values, the header promises {count}")
    try:
        values = float_array(tokens)
    except NumberTextError as bad:
        line = first_line + _line_of_token(body, bad.row)
        raise MapFormatError(f"{path}:{line}: non-numeric map value {bad.token!r}") from None
    invalid = ~((values >= -1.0) & (values <= 1.0))  # also catches NaN
    if invalid.any():
        index = int(np.argmax(invalid))
        line = first_line + _line_of_token(body, index)
        msg = f"{path}:{line}: map value {tokens[index]!r} (number {index}) is outside [-1, 1]"
        raise MapFormatError(msg)
    return values


def _line_of_token(body: str, index: int) -> int:
    """The line (0 for the first) of ``body`` that holds its token number ``index``."""
    seen = 0
    for k, line in enumerate(body.split("\n")):
        seen += len(line.split())
        if seen > index:
            return k
    return body.count("\n")
