# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The ROS map YAML model and the map-building settings: a valid file reads to the values
written in it, a bad key, type, NaN or unknown key is named with the file and the value, and
an image stating more cells than the map limit is refused before it is decoded, the limit in
the message."""

from __future__ import annotations

import dataclasses
import struct
import zlib
from pathlib import Path

import pytest
import yaml

from kiseki import MapFormatError
from kiseki.io.map_schema import MapBuildSettings
from kiseki.io.ros_map import load_map, read_map_metadata
from kiseki.mapping import MAX_MAP_CELLS, MapBuildConfig

ROOT = Path(__file__).resolve().parents[3]
CORRIDOR = ROOT / "data" / "maps" / "factory_corridor.yaml"


def test_the_corridor_map_reads_to_the_values_of_its_file():
    raw = yaml.safe_load(CORRIDOR.read_text())
    meta = read_map_metadata(CORRIDOR)
    assert meta.image == CORRIDOR.parent / raw["image"]
    assert meta.resolution == raw["resolution"] and meta.origin == tuple(raw["origin"])
    assert (meta.mode, meta.negate) == (raw["mode"], bool(raw["negate"]))
    assert (meta.occupied_thresh, meta.free_thresh) == (raw["occupied_thresh"], raw["free_thresh"])


def _write(tmp_path: Path, **fields) -> Path:
    doc = {"image": "m.pgm", "resolution": 0.05, "origin": [0.0, 0.0, 0.0], **fields}
    path = tmp_path / "m.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"resolution": 0}, "resolution: must be greater than or equal to 0.0001, got 0"),
        ({"resolution": 1e-300}, "resolution: must be greater than or equal to 0.0001, got 1e-300"),
        ({"resolution": True}, "resolution: must be a valid number, got True"),
        ({"origin": [0, 0]}, "origin: must be a list [x, y, yaw], got [0, 0]"),
        ({"origin": [0, float("nan"), 0]}, "origin[1]: must be a finite number, got nan"),
        ({"origin": [0, "1", 0]}, "origin[1]: must be a valid number, got '1'"),
        ({"negate": 2}, "negate: must be 0 or 1 (or false / true), got 2"),
        ({"negate": 1.0}, "negate: must be 0 or 1 (or false / true), got 1.0"),
        ({"mode": "binary"}, "mode: must be 'trinary', 'scale' or 'raw', got 'binary'"),
        ({"occupied_thresh": 1.5}, "occupied_thresh: must be less than or equal to 1, got 1.5"),
        ({"free_thresh": 0.7}, "free_thresh: must not exceed occupied_thresh (0.65), got 0.7"),
        ({"image": ""}, "image: string should have at least 1 character, got ''"),
        ({"image": None}, "image: must be a valid string, got None"),
        ({"resolutoin": 0.1}, "resolutoin: unknown key"),
    ],
)
def test_a_bad_map_yaml_names_the_file_the_key_and_the_value(tmp_path, fields, message):
    with pytest.raises(MapFormatError) as info:
        read_map_metadata(_write(tmp_path, **fields))
    assert str(info.value) == f"{tmp_path / 'm.yaml'}: {message}"


def test_negate_and_the_thresholds_read_as_written(tmp_path):
    meta = read_map_metadata(_write(tmp_path, negate=True, free_thresh=0.65, mode="raw"))
    assert (meta.negate, meta.free_thresh, meta.occupied_thresh, meta.mode) == (
        True,
        0.65,
        0.65,
        "raw",
    )
    assert read_map_metadata(_write(tmp_path, negate=0)).negate is False


def _png_header(width: int, height: int) -> bytes:
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    chunk = b"IHDR" + ihdr
    return (
        b"\x89PNG\r\n\x1a\n"
        + struct.pack(">I", len(ihdr))
        + chunk
        + struct.pack(">I", zlib.crc32(chunk))
    )


@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("m.pgm", b"P5\n20000 5001\n255\n" + bytes(64)),
        ("m.png", _png_header(20000, 5001)),
    ],
)
def test_an_image_over_the_cell_limit_is_refused_before_decoding(tmp_path, name, content):
    (tmp_path / name).write_bytes(content)
    with pytest.raises(MapFormatError) as info:
        load_map(_write(tmp_path, image=name))
    assert str(info.value) == (
        f"{tmp_path / name} (the image of {tmp_path / 'm.yaml'}) is 20000 x 5001 pixels: "
        "more than the limit of 1e+08 map cells"
    )
    assert MAX_MAP_CELLS == 20000 * 5000 == 10**8


def test_an_image_at_the_cell_limit_passes_the_header_check(tmp_path):
    # 20000 x 5000 is the limit: the header passes and the decoder reports the missing pixels
    (tmp_path / "m.pgm").write_bytes(b"P5\n20000 5000\n255\n" + bytes(64))
    with pytest.raises(MapFormatError, match="a truncated PGM"):
        load_map(_write(tmp_path))


def test_map_build_settings_read_to_the_config_built_by_hand():
    assert {f.name for f in dataclasses.fields(MapBuildConfig)} == set(
        MapBuildSettings.model_fields
    )
    values = {"resolution": 0.1, "clear_on_no_return": True, "prob_hit": 0.8, "margin": 0}
    assert MapBuildConfig.from_dict(values) == MapBuildConfig(
        resolution=0.1, clear_on_no_return=True, prob_hit=0.8, margin=0.0
    )
    assert MapBuildConfig.from_dict({}) == MapBuildConfig()


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"resolutoin": 0.1}, "resolutoin: unknown key"),
        ({"resolution": None}, "resolution: must be a valid number, got None"),
        ({"prob_hit": 1.0}, "prob_hit: must be less than 1, got 1.0"),
        ({"margin": float("nan")}, "margin: must be a finite number, got nan"),
        ({"clear_on_no_return": 1}, "clear_on_no_return: must be a valid boolean, got 1"),
        ({"usable_range": "30"}, "usable_range: must be a valid number, got '30'"),
        ({"prob_miss": "0.4"}, "prob_miss: must be a valid number, got '0.4'"),
    ],
)
def test_bad_map_build_settings_name_the_source_the_key_and_the_value(values, message):
    with pytest.raises(ValueError) as info:
        MapBuildConfig.from_dict(values, "build.yaml")
    assert str(info.value) == f"build.yaml: {message}"
