# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Map files: the ROS map_server format (YAML + PGM/PNG image) and the CMU Wean Hall .dat map.

Loading follows nav2's map_server rules for every field the format defines (``image``,
``resolution``, ``origin``, ``negate``, ``occupied_thresh``, ``free_thresh``, ``mode`` trinary /
scale / raw). Saving follows nav2's map_saver, except that ``free_thresh`` defaults to 0.196
(the ROS 1 map_saver value) so that the 205-grey of unknown cells loads back as unknown; nav2's
0.25 would turn it into free space. Files are written to a temporary name and renamed, so an
interrupted save never leaves a half-written map behind.
"""

from __future__ import annotations

import errno
import os
import struct
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from kiseki import _core
from kiseki._support.atomic import atomic_write_all
from kiseki._support.inputs import GIB, YAML_LIMIT, check_input, read_input_text
from kiseki._support.schema import SchemaError, parse
from kiseki._support.yaml import safe_load_12, yaml_problem
from kiseki.core import Pose2
from kiseki.errors import MapFormatError
from kiseki.grid import OCCUPIED, UNKNOWN, OccupancyGrid
from kiseki.io.map_schema import MODES, RosMapYaml
from kiseki.mapping import MAX_MAP_CELLS

__all__ = [
    "MAX_IMAGE_BYTES",
    "MapMetadata",
    "load_map",
    "map_files",
    "read_image",
    "read_map_metadata",
    "save_map",
    "write_image",
]


MAX_IMAGE_BYTES = 1 * GIB
"""A map image file holds at most this: MAX_MAP_CELLS pixels of 16-bit RGBA (8 bytes each), or
of a text PGM (at most 6 bytes each), fit; its header's pixel count is checked before decoding."""


@dataclass(frozen=True)
class MapMetadata:
    """The fields of a ROS map YAML file."""

    image: Path
    resolution: float
    origin: tuple[float, float, float]
    mode: str = "trinary"
    negate: bool = False
    occupied_thresh: float = 0.65
    free_thresh: float = 0.196


def _parse_yaml(path: Path) -> RosMapYaml:
    try:
        text = read_input_text(path, "ROS map YAML files", YAML_LIMIT, MapFormatError)
    except UnicodeDecodeError as err:
        raise MapFormatError(
            f"{path}: not a map YAML file (not UTF-8 text: byte {err.start} is "
            f"0x{err.object[err.start]:02x})"
        ) from err
    try:
        doc = safe_load_12(text)  # resolution: 5e-2 is a number, as nav2 reads it
    except yaml.YAMLError as err:
        raise MapFormatError(f"{path}: invalid YAML ({yaml_problem(err)})") from err
    if not isinstance(doc, dict):
        raise MapFormatError(f"{path}: expected a YAML mapping with image, resolution and origin")
    try:
        return parse(RosMapYaml, doc, path)
    except SchemaError as err:
        raise MapFormatError(str(err)) from None


def read_map_metadata(path: str | os.PathLike) -> MapMetadata:
    """Reads and checks a ROS map YAML file (:class:`kiseki.io.map_schema.RosMapYaml`; the image
    path is resolved next to it). MapFormatError names the file, the key and the value."""
    path = Path(path)
    check_input(path, error=MapFormatError)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: map YAML file not found")
    doc = _parse_yaml(path)
    image = Path(doc.image)
    image = image if image.is_absolute() else path.parent / image
    if image.is_dir():  # 'image: .' read 'image file . not found' of a folder that is there
        raise MapFormatError(f"{path}: image {doc.image!r} is a folder, not a map image")
    return MapMetadata(
        image=image,
        resolution=doc.resolution,
        origin=doc.origin,
        mode=doc.mode,
        negate=doc.negate,
        occupied_thresh=doc.occupied_thresh,
        free_thresh=doc.free_thresh,
    )


_PNG = b"\x89PNG\r\n\x1a\n"
_PNG_MAX_CHUNKS = 1_000_000  # a PNG of more chunks than this is left to the decoder to judge
_IMAGE_HEADER_BYTES = 65536  # a PGM header with its comments fits in this


def _check_cells(path: Path, image: Path, width: int, height: int) -> None:
    if width * height > MAX_MAP_CELLS:
        raise MapFormatError(
            f"{image} (the image of {path}) is {width} x {height} pixels: more than the "
            f"limit of {MAX_MAP_CELLS:.0e} map cells"
        )


_PNG_CUT = "a truncated PNG (it does not end with the IEND chunk)"


def _png_is_whole(f, size: int) -> bool:
    """Whether an open PNG file holds its IEND chunk, found by walking the chunks' headers
    (length, type) from the signature; bytes after it are the reader's to ignore, as libpng
    does. libpng prints its own lines on stderr for a file cut short before OpenCV reports the
    failure. A file of more than _PNG_MAX_CHUNKS chunks is left to the decoder."""
    at = len(_PNG)
    for _ in range(_PNG_MAX_CHUNKS):
        f.seek(at)
        head = f.read(8)
        if len(head) < 8:
            return False
        length = struct.unpack(">I", head[:4])[0]
        if head[4:8] == b"IEND":
            return at + 12 <= size
        at += 12 + length  # length, type, data, CRC
    return True


def _check_image_header(path: Path, image: Path) -> None:
    """What OpenCV's decoders would report with lines of their own on stderr (before failing)
    is refused here, naming both files: a PGM (P5 or P2) whose header is not width, height and
    maxval, a binary PGM cut short, a text PGM with a word that is not a pixel value or with too
    few of them, a PNG without its closing IEND chunk (cut short). A PGM or PNG whose header
    states more than MAX_MAP_CELLS pixels is refused before it is decoded."""

    def refused(why: str) -> MapFormatError:
        return MapFormatError(f"{path}: cannot decode image {image}: {why}")

    with open(image, "rb") as f:
        head = f.read(_IMAGE_HEADER_BYTES)
        size = os.fstat(f.fileno()).st_size
        if head.startswith(_PNG):
            if head[12:16] == b"IHDR":
                if len(head) < 24:  # struct.error ("unpack requires a buffer of 8 bytes")
                    raise refused(_PNG_CUT)
                _check_cells(path, image, *struct.unpack(">II", head[16:24]))
            if not _png_is_whole(f, size):
                raise refused(_PNG_CUT)
            return
        if not head.startswith((b"P5", b"P2")):
            return  # other formats: the decoder's error
        fields: list[bytes] = []
        at = 2
        while len(fields) < 3 and at < len(head):
            if head[at : at + 1] == b"#":  # a comment runs to the end of its line (LF or CR)
                ends = [e for e in (head.find(b"\n", at), head.find(b"\r", at)) if e >= 0]
                at = min(ends) + 1 if ends else len(head)
            elif head[at : at + 1].isspace():
                at += 1
            else:
                end = at
                while end < len(head) and not head[end : end + 1].isspace():
                    end += 1
                fields.append(head[at:end])
                at = end
        if len(fields) < 3 or not all(x.isdigit() for x in fields):
            found = " ".join(x.decode("latin-1") for x in fields[:3]) or "nothing"
            raise refused(f"a PGM header is width, height and maxval (numbers), found {found!r}")
        width, height, maxval = (int(x) for x in fields)
        _check_cells(path, image, width, height)
        if not 1 <= maxval <= 65535:
            raise refused(f"a PGM's maxval is 1..65535, found {maxval}")
        if head.startswith(b"P2"):  # text: every word after the header a pixel value
            f.seek(at)
            words = _text_pixels(f, refused)
            if words is not None and words < width * height:
                raise refused(f"a truncated PGM ({words} of the {width * height} pixels)")
            return
        need = width * height * (1 if maxval < 256 else 2)
        have = size - (at + 1)  # one whitespace byte after maxval
    if have < need:
        raise refused(
            f"a truncated PGM ({max(have, 0)} of the {need} pixel bytes of {width} x {height})"
        )


def _text_pixels(f, refused: Callable[[str], MapFormatError]) -> int | None:
    """The words of a text PGM's pixels from the file's position on, read 16 MB at a time;
    refused at a byte that is neither a digit nor white space. None when a comment (#) lies
    among them, which OpenCV's reader skips: the count is then the decoder's to judge."""
    space = np.frombuffer(b" \t\n\r\x0b\x0c", np.uint8)
    words, after_digit = 0, False
    while chunk := f.read(16 * 1024 * 1024):
        if b"#" in chunk:
            return None
        body = np.frombuffer(chunk, dtype=np.uint8)
        digit = (body >= ord("0")) & (body <= ord("9"))
        other = ~digit & ~np.isin(body, space)
        if other.any():
            where = int(np.argmax(other))
            raise refused(f"a text PGM with {body[where : where + 20].tobytes()!r} in its pixels")
        starts = digit.copy()
        starts[1:] &= ~digit[:-1]
        starts[0] &= not after_digit
        words += int(starts.sum())
        after_digit = bool(digit[-1])
    return words


def _load_ros_map(path: Path) -> OccupancyGrid:
    meta = read_map_metadata(path)
    try:
        check_input(meta.image, "map images", MAX_IMAGE_BYTES, MapFormatError)
    except MapFormatError as err:
        raise MapFormatError(f"{path}: image {err}") from None
    if not meta.image.is_file():
        raise FileNotFoundError(f"{path}: image file {meta.image} not found")
    _check_image_header(path, meta.image)
    try:
        image = read_image(meta.image)
    except RuntimeError as err:
        raise MapFormatError(f"{path}: {err}") from err
    return _core.occupancy_from_image(
        image,
        meta.resolution,
        Pose2(*meta.origin),
        mode=meta.mode,
        negate=meta.negate,
        occupied_thresh=meta.occupied_thresh,
        free_thresh=meta.free_thresh,
    )


def load_map(path: str | os.PathLike) -> OccupancyGrid:
    """Loads a map: a ROS map YAML (``.yaml``/``.yml``) or a CMU Wean ``.dat``/``.dat.gz``."""
    path = Path(path)
    name = path.name.lower()
    if name.endswith((".dat", ".dat.gz")):
        # here, not at the top: `import kiseki` loads this module, and the dataset readers'
        # package (the ROS bag and MCAP libraries) would make it slow
        from kiseki.datasets.wean import read_wean_map

        wean = read_wean_map(path)
        return OccupancyGrid(wean.to_cells(), wean.resolution)
    if path.is_dir():  # '' is '.' ('.: unknown map format')
        raise MapFormatError(f"{path}: a folder, not a map file (.yaml, .yml, .dat or .dat.gz)")
    if not name.endswith((".yaml", ".yml")):
        raise MapFormatError(f"{path}: unknown map format (expected .yaml, .yml, .dat or .dat.gz)")
    return _load_ros_map(path)


def read_image(path: str | os.PathLike) -> np.ndarray:
    """Reads an image file as stored (OpenCV's decoders: channels in B, G, R, A order, 8 or 16
    bits). Raises RuntimeError naming `path` when it cannot be opened or decoded."""
    # here, not at the top: OpenCV's codecs load GDAL and about 140 more libraries (0.1 s),
    # which `import kiseki` and every command that reads no image should not pay for
    from kiseki import _image_io

    try:
        with open(path, "rb") as f:
            cut = f.read(len(_PNG)) == _PNG and not _png_is_whole(f, os.fstat(f.fileno()).st_size)
    except OSError:
        cut = False  # the reader names what keeps the file from being read
    if cut:
        raise RuntimeError(f"{path}: cannot decode image ({_PNG_CUT})")
    return _image_io.read_image(str(path))


def write_image(path: str | os.PathLike, image: np.ndarray) -> None:
    """Writes an image file (OpenCV's encoders; the format by the extension). Raises OSError
    naming `path` when the file cannot be written whole, with the system's reason (a full disk:
    ENOSPC): the C++ writer checks every step, since cv::imwrite reports success for a PGM that
    a full disk has cut short, which an atomic rename would then put over a good map."""
    # here, not at the top: as in read_image
    from kiseki import _image_io

    try:
        _image_io.write_image(str(path), image)
    except RuntimeError as err:
        text = str(err)
        text = text.removeprefix(f"{path}: ")
        for code in (errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EACCES, errno.ENOENT):
            if text.endswith(os.strerror(code)):
                raise OSError(code, os.strerror(code), str(path)) from err
        raise OSError(errno.EIO, text, str(path)) from err


def save_map(
    grid: OccupancyGrid,
    path: str | os.PathLike,
    mode: str = "trinary",
    image_format: str | None = None,
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
) -> Path:
    """Saves a grid as ROS map YAML + image (``<stem>.pgm``, or ``.png`` in scale mode, which
    needs an alpha channel). Returns the YAML path. Both files are written before either
    replaces a previous map, so a failed save leaves the previous map whole."""
    path = Path(path)
    atomic_write_all(map_files(grid, path, mode, image_format, occupied_thresh, free_thresh))
    return path


def map_files(
    grid: OccupancyGrid,
    path: str | os.PathLike,
    mode: str = "trinary",
    image_format: str | None = None,
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
) -> list[tuple[Path, Callable[[str], object]]]:
    """The checked files of :func:`save_map`, image first, each with its writer, for
    `kiseki._support.atomic.atomic_write_all` (to save them together with other files)."""
    path = Path(path)
    if path.suffix.lower() not in (".yaml", ".yml"):
        raise ValueError(f"{path}: a ROS map must be saved to a .yaml file")
    if not path.parent.is_dir():
        raise FileNotFoundError(f"{path}: directory {path.parent} does not exist")
    if mode not in MODES:
        raise ValueError(f"mode must be one of {', '.join(MODES)}, got {mode!r}")
    image_format = (image_format or ("png" if mode == "scale" else "pgm")).lower()
    if image_format not in ("pgm", "png"):
        raise ValueError(f"image_format must be 'pgm' or 'png', got {image_format!r}")
    if mode == "scale" and image_format == "pgm":
        raise ValueError("scale mode stores unknown cells in an alpha channel: use PNG")
    cells = grid.cells
    bad = (cells < UNKNOWN) | (cells > OCCUPIED)
    if bad.any():
        y, x = np.argwhere(bad)[0]
        raise ValueError(
            f"{path}: the grid has {int(bad.sum())} cells outside -1..100 (cell x={x}, y={y} "
            f"holds {int(cells[y, x])}): nothing written"
        )
    image = _core.image_from_occupancy(
        grid, mode=mode, occupied_thresh=occupied_thresh, free_thresh=free_thresh
    )
    image_path = path.with_suffix(f".{image_format}")
    origin = grid.origin
    doc = {
        "image": image_path.name,
        "mode": mode,
        "resolution": float(grid.resolution),
        "origin": [float(origin.x), float(origin.y), float(origin.theta)],
        "negate": 0,
        "occupied_thresh": float(occupied_thresh),
        "free_thresh": float(free_thresh),
    }
    text = yaml.safe_dump(doc, sort_keys=False, default_flow_style=None)
    return [
        (image_path, lambda tmp: write_image(tmp, image)),
        (path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8")),
    ]
