# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""ROS map_server format: hand-written YAML + PGM/PNG files that follow the ROS docs, read with
an independent numpy version of nav2's rules; kiseki's saved maps read by that same reference."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from PIL import Image

from kiseki import MapFormatError, OccupancyGrid, Pose2, load_map, save_map
from kiseki.io.ros_map import read_map_metadata


def write_pgm(path, pixels: np.ndarray, maxval: int = 255) -> None:
    """A binary (P5) PGM written by hand, as map_saver writes them."""
    h, w = pixels.shape
    data = pixels.astype(">u2" if maxval > 255 else np.uint8).tobytes()
    path.write_bytes(f"P5\n# CREATOR: test\n{w} {h}\n{maxval}\n".encode() + data)


def nav2_reference(pixels: np.ndarray, mode: str, negate: bool, occ_t: float, free_t: float):
    """nav2 map_server's loading rules in numpy; pixels (h, w) grey or (h, w, c) RGB[A]."""
    px = pixels.astype(float) / 255.0
    if px.ndim == 2:
        px = px[..., None]
    alpha = px.shape[2] in (2, 4)
    colour = px[..., : px.shape[2] - 1] if alpha else px
    opacity = px[..., -1] if alpha else np.ones(px.shape[:2])
    shade = colour.mean(axis=2)
    if mode == "trinary" and alpha:
        shade = (colour.sum(axis=2) + opacity) / (colour.shape[2] + 1)
    if mode == "raw":
        v = np.round(shade * 255)
        out = np.where((v >= 0) & (v <= 100), v, -1)
    else:
        occ = shade if negate else 1 - shade
        mid = np.rint((occ - free_t) / (occ_t - free_t) * 100) if mode == "scale" else -1
        out = np.where(occ > occ_t, 100, np.where(occ < free_t, 0, mid))
        if mode == "scale":
            out = np.where(opacity < 1, -1, out)
    return np.flipud(out).astype(np.int8)  # image row 0 is the top: grid row 0 is the bottom


def write_yaml(path, **fields) -> None:
    path.write_text(yaml.safe_dump(fields))


@pytest.mark.parametrize("mode", ["trinary", "scale", "raw"])
@pytest.mark.parametrize("negate", [0, 1])
def test_grey_pgm_all_modes(tmp_path, mode, negate):
    pixels = np.arange(0, 256, dtype=np.uint8)[np.arange(64) * 4 % 256].reshape(8, 8)
    write_pgm(tmp_path / "m.pgm", pixels)
    write_yaml(
        tmp_path / "m.yaml",
        image="m.pgm",
        resolution=0.05,
        origin=[-1.0, 2.0, 0.3],
        mode=mode,
        negate=negate,
        occupied_thresh=0.65,
        free_thresh=0.25,
    )
    grid = load_map(tmp_path / "m.yaml")
    ref = nav2_reference(pixels, mode, bool(negate), 0.65, 0.25)
    np.testing.assert_array_equal(grid.cells, ref)
    assert grid.resolution == 0.05
    assert (grid.origin.x, grid.origin.y, grid.origin.theta) == pytest.approx((-1.0, 2.0, 0.3))


@pytest.mark.parametrize("mode", ["trinary", "scale"])
def test_rgba_png_uses_alpha_as_nav2(tmp_path, mode):
    rng = np.random.default_rng(0)
    rgba = rng.integers(0, 256, (6, 7, 4), dtype=np.uint8)
    rgba[..., 3] = np.where(rng.random((6, 7)) < 0.3, 0, 255)
    Image.fromarray(rgba, "RGBA").save(tmp_path / "m.png")
    write_yaml(
        tmp_path / "m.yaml",
        image="m.png",
        resolution=0.1,
        origin=[0, 0, 0],
        mode=mode,
        negate=0,
        occupied_thresh=0.65,
        free_thresh=0.196,
    )
    np.testing.assert_array_equal(
        load_map(tmp_path / "m.yaml").cells, nav2_reference(rgba, mode, False, 0.65, 0.196)
    )


def test_sixteen_bit_pgm_and_defaults(tmp_path):
    pixels = np.array([[0, 65535], [13107, 52428]], dtype=np.uint16)
    write_pgm(tmp_path / "m.pgm", pixels, maxval=65535)
    write_yaml(tmp_path / "m.yaml", image="m.pgm", resolution=0.5, origin=[0, 0, 0])
    # no thresholds given: kiseki's defaults (0.65 / 0.196); 13107 -> occ 0.8, 52428 -> occ 0.2
    np.testing.assert_array_equal(load_map(tmp_path / "m.yaml").cells, [[100, -1], [100, 0]])


def test_trinary_save_follows_map_saver_and_round_trips(tmp_path):
    rng = np.random.default_rng(1)
    cells = rng.choice(np.array([0, 100, -1], dtype=np.int8), size=(20, 30))
    grid = OccupancyGrid(cells, 0.05, Pose2(-3.0, 1.5, 0.0))
    yaml_path = save_map(grid, tmp_path / "saved.yaml")
    doc = yaml.safe_load(yaml_path.read_text())
    assert doc == {
        "image": "saved.pgm",
        "mode": "trinary",
        "resolution": 0.05,
        "origin": [-3.0, 1.5, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    raw = (tmp_path / "saved.pgm").read_bytes()
    assert raw.startswith(b"P5")
    pixels = np.frombuffer(raw[-600:], dtype=np.uint8).reshape(20, 30)
    np.testing.assert_array_equal(
        np.flipud(pixels), np.select([cells == 0, cells == 100], [254, 0], 205)
    )
    back = load_map(yaml_path)
    np.testing.assert_array_equal(back.cells, cells)
    np.testing.assert_array_equal(nav2_reference(pixels, "trinary", False, 0.65, 0.196), cells)
    assert not list(tmp_path.glob(".*"))  # no temporary files left behind


def test_scale_and_raw_saves(tmp_path):
    cells = np.array([[-1, 0, 30], [50, 100, 80]], dtype=np.int8)
    grid = OccupancyGrid(cells, 0.1)
    raw = load_map(save_map(grid, tmp_path / "raw.yaml", mode="raw"))
    np.testing.assert_array_equal(raw.cells, cells)
    scale = load_map(save_map(grid, tmp_path / "scale.yaml", mode="scale"))
    rgba = np.asarray(Image.open(tmp_path / "scale.png"))
    np.testing.assert_array_equal(scale.cells, nav2_reference(rgba, "scale", False, 0.65, 0.196))
    assert scale.cells[0, 0] == -1 and scale.cells[1, 1] == 100 and scale.cells[0, 1] == 0


def test_demo_map_in_repository_loads(project_data):
    grid = load_map(project_data / "maps" / "factory_corridor.yaml")
    assert (grid.width, grid.height, grid.resolution) == (330, 80, 0.05)
    assert set(np.unique(grid.cells)) == {0, 100}


def test_cmu_wean_dat_loads(shared_data):
    grid = load_map(shared_data / "cmu_wean" / "wean.dat.gz")
    assert (grid.width, grid.height) == (800, 800) and grid.resolution == pytest.approx(0.1)
    counts = {v: int(np.count_nonzero(grid.cells == v)) for v in (-1, 0, 100)}
    assert counts[0] > counts[100] > 0 and counts[-1] > 0


def _valid(tmp_path, **override):
    write_pgm(tmp_path / "m.pgm", np.full((4, 4), 254, dtype=np.uint8))
    fields = dict(
        image="m.pgm",
        resolution=0.05,
        origin=[0, 0, 0],
        negate=0,
        occupied_thresh=0.65,
        free_thresh=0.196,
    )
    fields.update(override)
    for key in [k for k, v in fields.items() if v is None]:
        del fields[key]
    write_yaml(tmp_path / "m.yaml", **fields)
    return tmp_path / "m.yaml"


@pytest.mark.parametrize(
    ("override", "error", "match"),
    [
        ({"resolution": -0.05}, MapFormatError, "resolution"),
        ({"resolution": "fine"}, MapFormatError, "resolution"),
        ({"resolution": None}, MapFormatError, "missing"),
        ({"origin": [0, 0]}, MapFormatError, "origin"),
        ({"origin": [0, float("nan"), 0]}, MapFormatError, "finite"),
        ({"mode": "binary"}, MapFormatError, "mode"),
        ({"negate": 2}, MapFormatError, "negate"),
        ({"occupied_thresh": 1.5}, MapFormatError, "occupied_thresh"),
        ({"free_thresh": 0.9}, MapFormatError, "free_thresh"),
        ({"image": "missing.pgm"}, FileNotFoundError, "missing.pgm"),
    ],
)
def test_bad_yaml_fields(tmp_path, override, error, match):
    path = _valid(tmp_path, **override)
    with pytest.raises(error, match=match) as info:
        load_map(path)
    assert "m.yaml" in str(info.value)


def test_bad_files(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere.yaml"):
        load_map(tmp_path / "nowhere.yaml")
    (tmp_path / "empty.yaml").write_text("")
    with pytest.raises(MapFormatError, match="empty.yaml"):
        load_map(tmp_path / "empty.yaml")
    (tmp_path / "broken.yaml").write_text("image: [unclosed\n")
    with pytest.raises(MapFormatError, match="invalid YAML"):
        load_map(tmp_path / "broken.yaml")
    with pytest.raises(MapFormatError, match="unknown map format"):
        load_map(tmp_path / "map.bmp")
    path = _valid(tmp_path)
    (tmp_path / "m.pgm").write_bytes(b"P5\n40 40\n255\n" + bytes(100))  # truncated
    with pytest.raises(MapFormatError, match="m.yaml.*decode"):
        load_map(path)
    (tmp_path / "m.pgm").write_bytes(bytes(range(256)) * 4)  # not an image at all
    with pytest.raises(MapFormatError, match="m.pgm"):
        load_map(path)
    assert read_map_metadata(_valid(tmp_path)).image == tmp_path / "m.pgm"


def test_bad_saves(tmp_path):
    grid = OccupancyGrid(3, 3, 0.1)
    with pytest.raises(ValueError, match="PNG"):
        save_map(grid, tmp_path / "a.yaml", mode="scale", image_format="pgm")
    with pytest.raises(FileNotFoundError, match="does not exist"):
        save_map(grid, tmp_path / "no" / "a.yaml")
    with pytest.raises(ValueError, match="yaml"):
        save_map(grid, tmp_path / "a.pgm")
    with pytest.raises(ValueError, match="mode"):
        save_map(grid, tmp_path / "a.yaml", mode="fancy")


@pytest.mark.parametrize(("text", "value"), [("5e-2", 0.05), ("5E-2", 0.05), ("+1e-1", 0.1)])
def test_yaml_1_2_numbers_are_numbers_as_nav2_reads_them(tmp_path, text, value):
    write_pgm(tmp_path / "m.pgm", np.full((3, 4), 254, dtype=np.uint8))
    (tmp_path / "m.yaml").write_text(
        f"image: m.pgm\nresolution: {text}\norigin: [-1e1, 0.0, 0]\nfree_thresh: 2e-1\n"
    )
    meta = read_map_metadata(tmp_path / "m.yaml")
    assert meta.resolution == value and meta.origin == (-10.0, 0.0, 0.0)
    assert meta.free_thresh == 0.2
    assert load_map(tmp_path / "m.yaml").resolution == value
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: '5e-2'\norigin: [0, 0, 0]\n")
    with pytest.raises(MapFormatError, match="resolution: must be a valid number, got '5e-2'"):
        read_map_metadata(tmp_path / "m.yaml")  # quoted: a string in YAML 1.2 too


@pytest.mark.parametrize("value", [120, -2, -128, 101])
def test_save_map_refuses_cells_outside_minus_one_to_hundred(tmp_path, value):
    grid = OccupancyGrid(4, 3, 0.1)
    grid.cells[2, 1] = value
    with pytest.raises(ValueError, match=rf"a\.yaml: the grid has 1 cells outside -1\.\.100 "
                       rf"\(cell x=1, y=2 holds {value}\)"):  # fmt: skip
        save_map(grid, tmp_path / "a.yaml")
    assert list(tmp_path.iterdir()) == []  # neither the YAML nor the image
