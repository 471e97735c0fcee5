# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""`kiseki sim show`: the scene drawn from above, read back pixel by pixel (each height band in
its colour, at its size and place), and its OctoMap export against a count of voxel centres."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import yaml

from _helpers.pixels import largest_blob, rgb
from kiseki import _core

# three boxes, one per height band: (x0, x1, y0, y1, z0, z1) in metres; edges 0.01 m off the
# 0.05 m voxel grid so that no voxel centre lies on a (grown) face
BOXES = {
    "low": (1.01, 2.01, 1.01, 1.61, 0.0, 0.4),  # 0.05-0.6 m: black
    "table": (4.01, 5.21, 2.51, 3.11, 0.7, 0.9),  # 0.6-1.0 m: orange
    "high": (6.01, 6.81, 0.51, 1.91, 1.6, 2.0),  # above 1.0 m: grey
}
COLOURS = {"low": (0, 0, 0), "table": (230, 159, 0), "high": (176, 176, 176)}


def middle_of(box) -> np.ndarray:
    """The (x, y) middle of a box (x0, x1, y0, y1, z0, z1)."""
    return np.array([(box[0] + box[1]) / 2, (box[2] + box[3]) / 2])


def scene_file(tmp_path):
    objects = [
        {
            "type": "box",
            "center": [(x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2],
            "size": [x1 - x0, y1 - y0, z1 - z0],
        }
        for x0, x1, y0, y1, z0, z1 in BOXES.values()
    ]
    doc = {
        "name": "three_bands",
        "description": "one box per height band",
        "bounds": {"min": [0.0, 0.0, -0.1], "max": [8.0, 4.0, 3.0]},
        "floor": False,
        "grid_resolution": 0.05,
        "objects": objects,
    }
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def test_sim_show_draws_each_band_where_it_is_and_exports_the_voxels(tmp_path):
    scene = scene_file(tmp_path)
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "sim", "show", str(scene), "-o", "s.png"]
        + ["--octree", "s.bt", "--resolution", "0.05"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    assert "s.png: scene drawn; s.bt written" in " ".join(done.stdout.split())
    assert done.stderr == ""  # OctoMap's own writer printed " done." there
    image = rgb(tmp_path / "s.png")
    found = {band: largest_blob(image, colour, tol=4) for band, colour in COLOURS.items()}
    middle = {band: middle_of(box) for band, box in BOXES.items()}
    # the scale from the low and high boxes' centres, the same along x and y, y up
    (low, _), (high, _) = found["low"], found["high"]
    dx, dy = middle["high"] - middle["low"]
    scale = (high[0] - low[0]) / dx
    assert scale > 50 and (low[1] - high[1]) / dy == pytest.approx(scale, rel=0.02)
    for band, (centre, size) in found.items():
        x0, x1, y0, y1, *_ = BOXES[band]
        expected = low + scale * np.array([1, -1]) * (middle[band] - middle["low"])
        np.testing.assert_allclose(centre, expected, atol=3, err_msg=band)
        # drawn on the scene's 0.05 m grid: within a cell of the box's size
        np.testing.assert_allclose(size, scale * np.array([x1 - x0, y1 - y0]), atol=0.05 * scale)
    # the export: a voxel is occupied when its centre lies in a box grown by half a voxel, so
    # a ray along x (or y) through a box's middle stops where the first such voxel begins
    tree = _core.OctreeWorld.read_binary(str(tmp_path / "s.bt"))
    assert tree.resolution == pytest.approx(0.05)
    centres = (np.arange(-200, 200) + 0.5) * 0.05
    origins, directions, expected = [], [], []
    for box in BOXES.values():
        x0, _, y0, _, z0, z1 = box
        (mx, my), mz = middle_of(box), (z0 + z1) / 2
        for axis, lo in ((0, x0), (1, y0)):
            origin = [mx, my, mz]
            origin[axis] = 0.0
            origins.append(origin)
            directions.append(np.eye(3)[axis])
            expected.append(centres[centres >= lo - 0.025].min() - 0.025)
    hits = tree.cast_many(np.array(origins), np.array(directions), 20.0)
    np.testing.assert_allclose(hits, expected, atol=1e-6)
