# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A ROS map's image that OpenCV's decoders cannot read, from the command line: the header
check names the map and its image in one line, where OpenCV and libpng printed lines of their
own first; images the decoders do read (comments, CR line ends, data after a PNG's IEND chunk)
still load, to the same pixels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from _helpers.boundaries_cli import digests, one_error, run
from _helpers.room_log import room
from kiseki import save_map


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    save_map(room(), tmp_path / "room.yaml")
    return tmp_path


_HEADER = "a PGM header is width, height and maxval (numbers), found "
_BAD_IMAGES = {  # the image's bytes; the line's end after "cannot decode image bad.pgm: "
    "no maxval": (b"P5\n120 80\n", _HEADER + "'120 80'"),
    "negative width": (b"P5\n-3 80\n255\n", _HEADER + "'-3 80 255'"),
    "maxval 0": (b"P5\n2 2\n0\n" + bytes(4), "a PGM's maxval is 1..65535, found 0"),
    "a word among pixels": (b"P2\n2 2\n255\n1 2 x 4\n", "a text PGM with b'x 4\\n' in its pixels"),
    "too few text pixels": (b"P2\n2 2\n255\n1 2\n3\n", "a truncated PGM (3 of the 4 pixels)"),
}


@pytest.mark.parametrize("case", sorted(_BAD_IMAGES))
def test_a_map_image_opencv_cannot_read_is_one_line_without_its_codecs_lines(inputs, case):
    """OpenCV printed "imread_(...): can't read header: ..." (and libpng "libpng error: ...")
    on stderr before kiseki's error: two or three lines where the rule is one."""
    content, why = _BAD_IMAGES[case]
    (inputs / "bad.pgm").write_bytes(content)
    (inputs / "bad.yaml").write_text(
        (inputs / "room.yaml").read_text().replace("room.pgm", "bad.pgm")
    )
    before = digests(inputs)
    line = one_error(run("map", "info", "bad.yaml", cwd=inputs))
    assert line == f"kiseki: error: bad.yaml: cannot decode image bad.pgm: {why}"
    assert digests(inputs) == before


def test_a_cut_png_is_one_line_and_whole_text_pgms_still_load(inputs):
    from kiseki.io.ros_map import read_image, write_image

    pixels = read_image(inputs / "room.pgm")
    write_image(inputs / "room.png", pixels)
    png = (inputs / "room.png").read_bytes()
    meta = (inputs / "room.yaml").read_text()
    # cut inside IHDR (its width and height short: a struct.error before), then later; the
    # IEND chunk's last byte lost is enough
    for keep in (20, 100, len(png) - 1):
        (inputs / "cut.png").write_bytes(png[:keep])
        (inputs / "cut.yaml").write_text(meta.replace("room.pgm", "cut.png"))
        line = one_error(run("map", "info", "cut.yaml", cwd=inputs))
        assert line == (
            "kiseki: error: cut.yaml: cannot decode image cut.png: a truncated PNG (it does not "
            "end with the IEND chunk)"
        )
    # the same pixels as a whole PNG (also with 2 kB after its IEND chunk, which libpng
    # ignores), as a text PGM with a comment, and as one with CR line ends and a comment among
    # its pixels (OpenCV skips both) read as the P5 map does
    (inputs / "tail.png").write_bytes(png + bytes(range(256)) * 8)
    text = " ".join(str(v) for v in pixels.ravel()).encode()
    (inputs / "text.pgm").write_bytes(b"P2\n# a comment\n120 80\n255\n" + text + b"\n")
    half = len(text) // 2 + text[len(text) // 2 :].index(b" ")
    (inputs / "cr.pgm").write_bytes(
        b"P2\r# a comment\r120 80\r255\r" + text[:half] + b"\r# between\r" + text[half:] + b"\r"
    )
    for name in ("room.png", "tail.png", "text.pgm", "cr.pgm"):
        (inputs / "same.yaml").write_text(meta.replace("room.pgm", name))
        assert run("map", "info", "same.yaml", cwd=inputs).returncode == 0
        np.testing.assert_array_equal(read_image(inputs / name), pixels)


def test_a_text_pgm_ending_at_its_last_value_and_an_empty_image(inputs):
    """A text PGM without a line end after its last value is a whole image (values are
    separated by white space): OpenCV's decoder failed on it with its own line; an empty image
    file said "cannot decode image" with no reason."""
    from kiseki.io.ros_map import read_image

    pixels = read_image(inputs / "room.pgm")
    text = " ".join(str(v) for v in pixels.ravel()).encode()
    (inputs / "end.pgm").write_bytes(b"P2\n120 80\n255\n" + text)  # no line end after the last
    meta = (inputs / "room.yaml").read_text()
    (inputs / "end.yaml").write_text(meta.replace("room.pgm", "end.pgm"))
    done = run("map", "info", "end.yaml", cwd=inputs)
    assert (done.returncode, done.stderr) == (0, "")
    assert done.stdout == run("map", "info", "room.yaml", cwd=inputs).stdout
    np.testing.assert_array_equal(read_image(inputs / "end.pgm"), pixels)
    (inputs / "empty.pgm").write_bytes(b"")
    (inputs / "empty.yaml").write_text(meta.replace("room.pgm", "empty.pgm"))
    assert one_error(run("map", "info", "empty.yaml", cwd=inputs)).endswith(
        "empty.pgm: cannot decode image (an empty file)"
    )
    (inputs / "folder.pgm").mkdir()  # a folder opened, and its size read as 2^63: bad_alloc
    with pytest.raises(RuntimeError, match="folder.pgm: cannot open image file .not a regular"):
        read_image(inputs / "folder.pgm")
