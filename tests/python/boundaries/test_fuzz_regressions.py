# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Inputs the fuzz targets of tests/fuzz (or their oracle applied by hand) found: each reader
now refuses them with one clear error naming the file, or reads them."""

from __future__ import annotations

import base64
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml

from kiseki.apps.teach.keyboard import KeyScript
from kiseki.apps.teach.taught_route import load_route
from kiseki.io.ros_map import load_map
from kiseki.sim.scene import load_scene

REGRESSIONS = Path(__file__).resolve().parents[2] / "fuzz" / "cpp" / "seeds"

# fuzz_keys.py, first run: a key script with bytes that are not UTF-8 (was UnicodeDecodeError)
KEYS_NOT_UTF8 = base64.b64decode(
    "IyB0aTAgbSBzcAo1LjAgYSBh5eXl5eUgYSBhIGEKNy4wIHNwYWNlIHcgdyB3CjkuMCBtIHEKIHEK"
)


def test_a_key_script_that_is_not_utf8_is_refused_naming_the_file(tmp_path):
    path = tmp_path / "keys.txt"
    path.write_bytes(KEYS_NOT_UTF8)
    with pytest.raises(ValueError, match="not a key script") as err:
        KeyScript(path)
    assert not isinstance(err.value, UnicodeDecodeError) and str(path) in str(err.value)


@pytest.mark.parametrize("nesting", ["[" * 3000, "{a: " * 3000, "- " * 3000])
@pytest.mark.parametrize("reader", ["map", "scene", "waypoints"])
def test_yaml_nested_deeper_than_the_recursion_limit_is_invalid_yaml(tmp_path, nesting, reader):
    path = tmp_path / "deep.yaml"
    path.write_text(f"image: {nesting}\n" if nesting[0] != "-" else nesting + "x\n")
    read = {
        "map": load_map,
        "scene": load_scene,
        "waypoints": lambda p: load_route(p, "band", ["P0"]),
    }[reader]
    with pytest.raises(ValueError, match="nested too deeply") as err:
        read(path)
    assert str(path) in str(err.value)


def _waypoints(tmp_path: Path, band: dict) -> Path:
    doc = {"maps": {"band": band}, "waypoints": [{"name": "P0", "x": 0, "y": 0, "theta": 0}]}
    path = tmp_path / "waypoints.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


@pytest.mark.parametrize("file", [5, ["map.yaml"], "", None])
def test_a_waypoint_file_whose_map_file_is_not_a_name_is_refused(tmp_path, file):
    path = _waypoints(tmp_path, {"file": file, "image_sha1": "0" * 40})
    with pytest.raises(ValueError) as err:
        load_route(path, "band", ["P0"])  # was TypeError: PosixPath / int
    assert str(err.value).startswith(f"{path}: maps.band.file: ")
    assert f"got {file!r}" in str(err.value)


def test_a_missing_taught_map_names_the_waypoint_file_that_refers_to_it(tmp_path):
    path = _waypoints(tmp_path, {"file": "gone.yaml", "image_sha1": "0" * 40})
    with pytest.raises(FileNotFoundError) as err:
        load_route(path, "band", ["P0"])
    assert str(tmp_path / "gone.yaml") in str(err.value) and str(path) in str(err.value)


def band_disagreements(cells: np.ndarray, hits: np.ndarray) -> tuple[int, int]:
    """(cells a ray hits that are not occupied, occupied cells farther than one cell from any
    hit one). The margin: the octree's 0.2 m voxels straddle the 0.25 m cells, so a voxel can
    overlap a cell without covering its centre, but it covers the centre of a neighbouring cell
    it overlaps; a voxel's cells are thus all within one cell (8-neighbourhood) of a hit one."""
    padded = np.pad(hits, 1)
    near = np.zeros_like(hits)
    for dy in range(3):
        for dx in range(3):
            near |= padded[dy : dy + hits.shape[0], dx : dx + hits.shape[1]]
    occupied = cells == 100
    return int((hits & ~occupied).sum()), int((occupied & ~near).sum())


def test_an_octree_whose_last_voxel_reaches_the_key_limit_rasterizes(tmp_path):
    """fuzz_octree (libFuzzer): a .bt whose bounds end on OctoMap's addressable limit made the
    band rasterisation dereference a null tree (SIGSEGV). The band must now hold every cell a
    downward ray from above the band hits inside it, and nothing beyond them but the margin of
    band_disagreements (an independent oracle: ray casting through each cell's centre)."""
    bt = REGRESSIONS / "octree" / "regression-last-voxel-at-key-limit.bt"
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        f"octomap: {bt}\nbounds: {{min: [-5, -5, 0], max: [5, 5, 2]}}\ngrid_resolution: 0.25\n"
    )
    code = textwrap.dedent(
        f"""
        import numpy as np
        from kiseki.sim.scene import load_scene
        scene = load_scene({str(scene)!r})
        grid = scene.ground_truth(0.0, 2.0)
        cells = grid.cells
        ys, xs = np.mgrid[0 : grid.height, 0 : grid.width]
        res, o = grid.resolution, grid.origin
        top = 1.999
        origins = np.column_stack([o.x + (xs.ravel() + 0.5) * res, o.y + (ys.ravel() + 0.5) * res,
                                   np.full(xs.size, top)])
        directions = np.tile([0.0, 0.0, -1.0], (xs.size, 1))
        hits = scene.world.cast_many(origins, directions, top).reshape(cells.shape) < top - 1e-9
        np.savez({str(tmp_path / "band.npz")!r}, cells=cells, hits=hits)
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]  # a SIGSEGV would have killed pytest
    band = np.load(tmp_path / "band.npz")
    cells, hits = band["cells"], band["hits"]
    assert hits.sum() > 0 and band_disagreements(cells, hits) == (0, 0)
    assert band_disagreements(np.full_like(cells, 100), hits)[1] > 0  # the oracle can refuse


@pytest.mark.parametrize(
    ("thresh", "pixels", "expected"), [(0, (255, 0), [-1, 100]), (1, (0, 255), [-1, 0])]
)
def test_scale_mode_with_equal_thresholds_leaves_the_pixel_on_them_unknown(
    tmp_path, thresh, pixels, expected
):
    """fuzz_map_image (libFuzzer, UBSan): in scale mode with occupied_thresh == free_thresh a
    pixel exactly on the thresholds divided 0 by 0 and cast NaN to int8 (undefined; it read as
    free here). It is neither free nor occupied: unknown, as in trinary mode."""
    (tmp_path / "m.pgm").write_bytes(b"P5\n2 1\n255\n" + bytes(pixels))
    path = tmp_path / "m.yaml"
    path.write_text(
        "image: m.pgm\nmode: scale\nresolution: 0.1\norigin: [0, 0, 0]\n"
        f"occupied_thresh: {thresh}\nfree_thresh: {thresh}\n"
    )
    assert load_map(path).cells.tolist() == [expected]


@pytest.mark.parametrize("kind", ["[3.6, 1.9]", "{box: 1}"])
def test_a_scene_object_whose_type_is_not_a_name_is_refused(tmp_path, kind):
    """fuzz_scene: `type: [3.6, 1.9]` (a hand edit gone wrong) raised TypeError: unhashable."""
    path = tmp_path / "scene.yaml"
    path.write_text(
        "objects:\n  - {type: wall, from: [0, 0], to: [6, 0], height: 2.5}\n"
        f"  - {{type: {kind}, size: [0.6, 0.3, 0.2]}}\n"
    )
    with pytest.raises(ValueError, match=r"objects\[1\]: unknown type") as err:
        load_scene(path)
    assert str(path) in str(err.value)
