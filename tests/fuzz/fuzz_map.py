# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Fuzz the ROS map reader kiseki.io.ros_map.load_map: the YAML file (``--target yaml``, the
default, with a small valid image beside it) or the image it names (``--target image``, decoded
by the C++ core's OpenCV reader, with a fixed YAML); see fuzz_common.py."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from fuzz_common import PROJECT_DATA, main, pick_target
from PIL import Image

from kiseki.io.ros_map import load_map

CORRIDOR = PROJECT_DATA / "maps" / "factory_corridor"


def corridor_crop(width: int = 12, height: int = 9) -> np.ndarray:
    """A corner of the project's factory corridor map (free, occupied and unknown pixels)."""
    data = CORRIDOR.with_suffix(".pgm").read_bytes()
    magic, size, maxval, pixels = data.split(b"\n", 3)
    cols, rows = (int(v) for v in size.split())
    assert magic == b"P5" and maxval == b"255"
    image = np.frombuffer(pixels, dtype=np.uint8, count=cols * rows).reshape(rows, cols)
    y, x = np.argwhere(image == 0)[0]  # a wall
    return np.ascontiguousarray(image[max(0, y - 2) : y - 2 + height, x : x + width])


def pgm(image: np.ndarray, maxval: int = 255) -> bytes:
    rows, cols = image.shape
    body = image.astype(">u2").tobytes() if maxval > 255 else image.tobytes()
    return f"P5\n{cols} {rows}\n{maxval}\n".encode() + body


def png(image: np.ndarray, mode: str) -> bytes:
    out = io.BytesIO()
    Image.fromarray(image, mode=mode).save(out, format="PNG")
    return out.getvalue()


def image_seeds(_folder: Path):
    grey = corridor_crop()
    yield pgm(grey)
    yield pgm(grey.astype(np.uint16) * 257, maxval=65535)
    rows, cols = grey.shape
    ascii_body = "\n".join(" ".join(str(v) for v in row) for row in grey)
    yield f"P2\n{cols} {rows}\n255\n{ascii_body}\n".encode()
    yield png(grey, "L")
    alpha = np.where(grey == 205, 0, 255).astype(np.uint8)
    yield png(np.dstack([grey, grey, grey, alpha]), "RGBA")
    yield png(np.dstack([grey, grey, grey]), "RGB")


def yaml_seeds(_folder: Path):
    text = CORRIDOR.with_suffix(".yaml").read_text().replace("factory_corridor.pgm", "tiny.pgm")
    yield text.encode()
    yield text.replace("tiny.pgm", "tiny.png").replace("trinary", "scale").encode()
    yield text.replace("trinary", "raw").replace("negate: 0", "negate: 1").encode()
    yield b"image: tiny.pgm\nresolution: 5e-2\norigin: [0, 0, 0]\n"


def prepare_yaml(files: Path) -> None:
    grey = corridor_crop()
    (files / "tiny.pgm").write_bytes(pgm(grey))
    alpha = np.where(grey == 205, 0, 255).astype(np.uint8)
    (files / "tiny.png").write_bytes(png(np.dstack([grey, grey, grey, alpha]), "RGBA"))


def prepare_image(files: Path) -> None:
    text = CORRIDOR.with_suffix(".yaml").read_text()
    (files / "map.yaml").write_text(text.replace("factory_corridor.pgm", "input.img"))


def read_image_map(path: Path) -> object:
    return load_map(path.parent / "map.yaml")


if __name__ == "__main__":
    if pick_target(("yaml", "image")) == "yaml":
        main(
            load_map, yaml_seeds, suffix=".yaml", prepare=prepare_yaml, packages=("kiseki", "yaml")
        )
    else:
        main(read_image_map, image_seeds, suffix=".img", prepare=prepare_image)
