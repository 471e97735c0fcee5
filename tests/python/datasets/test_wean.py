# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the CMU Wean Hall map reader: a tiny synthetic map, bad input, the real map."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

from kiseki.datasets.wean import WeanMap, read_wean_map
from kiseki.errors import MapFormatError

HEADER = """robot_specifications->global_mapsize_x  10
robot_specifications->global_mapsize_y  15
robot_specifications->resolution 5
robot_specifications->autoshifted_x 0

global_map[0]: 3 2
"""
# global_map[0]: size_y=3 size_x=2; one text line per x, holding the 3 y values.
BODY = "0.000 0.250 -1.000\n1.000 0.500 0.900\n"
# occupancy[y, x] = 1 - stored[x][y], NaN where stored < 0.
EXPECTED = np.array([[1.0, 0.0], [0.75, 0.5], [np.nan, 1.0 - 0.9]])


def write(path: Path, text: str, compress: bool = False) -> Path:
    data = text.encode()
    path.write_bytes(gzip.compress(data) if compress else data)
    return path


@pytest.mark.parametrize("compress", [False, True])
def test_tiny_map_orientation_and_values(tmp_path: Path, compress: bool) -> None:
    wean = read_wean_map(write(tmp_path / "tiny.dat", HEADER + BODY, compress))
    assert isinstance(wean, WeanMap)
    assert wean.occupancy.shape == (3, 2)
    assert wean.occupancy.dtype == np.float64
    assert wean.occupancy.flags.c_contiguous
    np.testing.assert_array_equal(wean.occupancy, EXPECTED)
    assert wean.resolution == 0.05


def test_to_cells(tmp_path: Path) -> None:
    wean = read_wean_map(write(tmp_path / "tiny.dat", HEADER + BODY))
    cells = wean.to_cells()
    assert cells.dtype == np.int8
    np.testing.assert_array_equal(cells, [[100, 0], [100, -1], [-1, 0]])
    np.testing.assert_array_equal(wean.to_cells(0.4, 0.3), [[100, 0], [100, 100], [-1, 0]])
    np.testing.assert_array_equal(wean.to_cells(0.8, 0.0), [[100, -1], [-1, -1], [-1, -1]])
    with pytest.raises(ValueError, match="free_thresh"):
        wean.to_cells(0.2, 0.5)


def test_minimal_header_without_map_sizes(tmp_path: Path) -> None:
    text = "robot_specifications->resolution 5\nglobal_map[0]: 3 2\n" + BODY
    wean = read_wean_map(write(tmp_path / "m.dat", text))
    np.testing.assert_array_equal(wean.occupancy, EXPECTED)


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match="nothere.dat"):
        read_wean_map(tmp_path / "nothere.dat")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "no 'global_map"),
        (BODY, r":1: unexpected header line '0\.000 0\.250"),
        (HEADER.replace("global_map[0]: 3 2\n", "") + BODY, r":6: unexpected header line"),
        (HEADER.replace("global_map[0]: 3 2", "global_map[0]: 3") + BODY, ":6: bad map size"),
        (HEADER.replace("3 2", "0 2") + BODY, ":6: bad map size"),
        (HEADER.replace("resolution 5", "resolution five") + BODY, ":3: .*resolution 'five' is"),
        # PEP 515 underscores are not numbers in a .dat map (float() read 1_0 as 10)
        (HEADER.replace("resolution 5", "resolution 1_0") + BODY, ":3: .*resolution '1_0' is"),
        (HEADER.replace("x  10", "x  1_0") + BODY, ":1: .*global_mapsize_x '1_0' is bad"),
        (HEADER.replace("resolution 5", "resolution 0") + BODY, "non-positive .*resolution"),
        (HEADER.replace("robot_specifications->resolution 5\n", "") + BODY, "missing"),
        # read as 1e298 m per cell (hypotheses with 300-digit coordinates), or 1e-302 m
        (HEADER.replace("resolution 5", "resolution 1e300") + BODY, "1e\\+300 cm is outside"),
        (HEADER.replace("resolution 5", "resolution 1e-300") + BODY, "1e-300 cm is outside"),
        (HEADER.replace("global_mapsize_x  10", "global_mapsize_x 20") + BODY, "global_mapsize_x"),
        (HEADER.replace("robot_specifications->", "robot_spec->") + BODY, ":1: unexpected"),
        (HEADER + BODY.replace(" 0.900", ""), "5 map values, the header promises 6"),
        (HEADER + BODY + "0.5\n", "7 map values, the header promises 6"),
        (HEADER + BODY.replace("0.900", "0.9O0"), ":8: non-numeric map value '0.9O0'"),
        (HEADER + BODY.replace("0.900", "0.9_0"), ":8: non-numeric map value '0.9_0'"),
        (HEADER + BODY.replace("0.000", "0_0"), ":7: non-numeric map value '0_0'"),
        (HEADER + BODY.replace("0.900", "1.500"), r":8: .*'1\.500' \(number 5\) is outside"),
        (HEADER + BODY.replace("-1.000", "-2.000"), r":7: .*'-2\.000' \(number 2\) is outside"),
        (HEADER + BODY.replace("0.250", "nan"), r":7: .*'nan' \(number 1\) is outside"),
    ],
)
def test_bad_map(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(MapFormatError, match=rf"bad\.dat.*{message}"):
        read_wean_map(write(tmp_path / "bad.dat", text))


def test_truncated_gzip(tmp_path: Path) -> None:
    data = gzip.compress((HEADER + BODY).encode() + b"\n" * 5000)
    path = tmp_path / "cut.dat.gz"
    path.write_bytes(data[: len(data) - 12])
    with pytest.raises(MapFormatError, match=r"cut\.dat\.gz: truncated or corrupt gzip"):
        read_wean_map(path)


# --- the real map ------------------------------------------------------------------------------


@pytest.fixture
def wean_map(shared_data: Path) -> WeanMap:
    return read_wean_map(shared_data / "cmu_wean" / "wean.dat.gz")


def test_real_map_shape_and_cells(wean_map: WeanMap) -> None:
    occupancy = wean_map.occupancy
    assert occupancy.shape == (800, 800)
    assert wean_map.resolution == 0.1
    # Values as zcat shows them: text line 8 + x (7 header lines), column y.
    assert occupancy[315, 400] == 1.0 - 0.789
    assert occupancy[373, 650] == 1.0 - 0.799
    assert np.isnan(occupancy[314, 400])
    known = ~np.isnan(occupancy)
    assert np.all((occupancy[known] >= 0) & (occupancy[known] <= 1))
    # Fractions measured on the file (unknown 72.8 %, free 7.6 %, occupied 3.2 %), +-~20 %.
    assert 0.70 < 1 - known.mean() < 0.76
    cells = wean_map.to_cells()
    assert 0.06 < np.mean(cells == 0) < 0.09
    assert 0.02 < np.mean(cells == 100) < 0.045
    # A building's seen area is mostly free: 15 % of the known cells are more likely occupied.
    assert 0.10 < np.mean(occupancy[known] > 0.5) < 0.20


def gif_agreement(display: np.ndarray, gif_rgb: np.ndarray) -> tuple[float, float, float]:
    """Compare a map drawn top row first with wean.gif: (IoU of known area, occupied cells on
    dark pixels, free cells on bright pixels)."""
    content = gif_rgb[17:441, 1:801].astype(int)  # cut the window's 17-px title bar and frame
    background = (content[..., 2] > 200) & (content[..., :2].max(axis=-1) < 50)  # blue: unknown
    gray = content.mean(axis=-1)
    dark, bright = ~background & (gray < 100), ~background & (gray > 200)
    known = ~np.isnan(display)
    rows, cols = np.flatnonzero(known.any(axis=1)), np.flatnonzero(known.any(axis=0))
    crop = display[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1]
    height, width = background.shape  # the gif shows the known area scaled to its window
    rows = np.arange(height) * crop.shape[0] // height
    cols = np.arange(width) * crop.shape[1] // width
    resampled = crop[np.ix_(rows, cols)]
    seen = ~np.isnan(resampled)
    iou = np.sum(seen & ~background) / np.sum(seen | ~background)
    with np.errstate(invalid="ignore"):
        occupied, free = resampled > 0.65, resampled < 0.196
    return float(iou), float(dark[occupied].mean()), float(bright[free].mean())


def test_real_map_matches_wean_gif(wean_map: WeanMap, shared_data: Path) -> None:
    image = pytest.importorskip("PIL.Image")
    with image.open(shared_data / "cmu_wean" / "wean.gif") as gif:
        rgb = np.asarray(gif.convert("RGB"))
    assert rgb.shape == (447, 802, 3)
    occupancy = wean_map.occupancy

    # Row 0 at y = 0 drawn at the bottom. Measured: IoU 0.99, 85 % of the occupied cells on dark
    # pixels (12 % of the gif's map pixels are dark), 95 % of the free ones on bright pixels
    # (33 % are bright).
    iou, on_dark, on_bright = gif_agreement(occupancy[::-1], rgb)
    assert iou > 0.95 and on_dark > 0.75 and on_bright > 0.85

    # Every other reading of the file fails the same test by a wide margin (measured: IoU <= 0.5
    # for wrong orientations; occupied on dark <= 0.13 for all, 0.02 for occupancy = stored v).
    wrong = {
        "upside down": occupancy,
        "mirrored": occupancy[::-1, ::-1],
        "transposed": occupancy.T[::-1],
        "stored value as occupancy": 1.0 - occupancy[::-1],
    }
    for name, display in wrong.items():
        iou, on_dark, on_bright = gif_agreement(display, rgb)
        assert on_dark < 0.3 and on_bright < 0.5, name
        if name != "stored value as occupancy":
            assert iou < 0.6, name
