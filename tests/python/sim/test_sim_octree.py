# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""OctoMap worlds: a box scene exported as an OctoMap tree and read back by OctoMap's own tool,
and the recorded Freiburg 079 octree as a scene, against OctoMap's own list of its voxels."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import yaml

from kiseki import _core
from kiseki.sim.scene import load_scene
from kiseki.sim.sensors import DepthCamera, DepthCameraParams, Mount

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"


def test_octree_export_and_the_real_building(shared_data, tmp_path):
    scene = load_scene(WORLDS / "rubble_a.yaml")
    tree = _core.OctreeWorld.from_boxes(scene.world, 0.05)
    tree.write_binary(str(tmp_path / "a.bt"))
    back = _core.OctreeWorld.read_binary(str(tmp_path / "a.bt"))
    assert back.occupied_leaves == tree.occupied_leaves > 10000
    if shutil.which("bt2vrml"):  # octomap-tools (installed by the set-up) opens the export
        done = subprocess.run(["bt2vrml", str(tmp_path / "a.bt")], capture_output=True, text=True)
        assert f"Finished writing {tree.occupied_leaves} voxels" in done.stdout
    geb = tmp_path / "geb.yaml"
    geb.write_text(
        yaml.safe_dump({"name": "geb079", "octomap": str(shared_data / "octomap" / "geb079.bt")})
    )
    building = load_scene(geb)
    lo, hi = building.world.bounds
    assert np.allclose(hi - lo, [39, 15, 3], atol=[3, 3, 1.5])  # 39 x 15 x 3 m (data README)
    grid = building.ground_truth(0.3, 1.5)
    assert 0.02 < np.mean(grid.cells == 100) < 0.5
    free = np.argwhere(grid.cells == 0)
    xy = grid.cell_to_world(free[len(free) // 2][::-1][None].astype(float))[0]
    camera = DepthCamera(DepthCameraParams(), Mount(0.0, 0.0, 1.0), seed=0)
    depth = camera.render(building.world, (xy[0], xy[1], 0.0), noise=False)
    assert np.mean(depth > 0) > 0.3  # the camera sees the real building's walls


def occupied_leaves_by_octomap(bt: Path) -> tuple[np.ndarray, np.ndarray]:
    """The centres and sizes of a .bt file's occupied leaves as OctoMap's own bt2vrml lists
    them (one VRML box each)."""
    done = subprocess.run(["bt2vrml", str(bt)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    text = bt.with_name(bt.name + ".wrl").read_text()
    found = re.findall(r"translation (\S+) (\S+) (\S+)\s+children \[ Shape \{ geometry Box "
                       r"\{ size (\S+) ", text)  # fmt: skip
    table = np.array(found, dtype=float)
    return table[:, :3], table[:, 3]


def band_against_leaves(grid, centres, sizes, z_min: float, z_max: float) -> tuple[int, int]:
    """How a band's grid disagrees with a list of occupied leaves: the cells under the leaves
    inside the band that are not occupied, and the occupied cells under no leaf that meets the
    band. A leaf's cells: those its footprint covers, less a quarter of the smaller of a leaf
    and a cell at each edge (a leaf whose edge just touches a cell need not mark it)."""
    occupied = grid.cells == 100
    lo, res = np.array([grid.origin.x, grid.origin.y]), grid.resolution

    def cell(xy: np.ndarray) -> np.ndarray:
        return np.floor((xy - lo) / res).astype(int)

    half = sizes / 2
    within = (centres[:, 2] - half >= z_min) & (centres[:, 2] + half <= z_max)
    assert within.sum() > 10_000
    missed = np.zeros_like(occupied)
    for c, h in zip(centres[within, :2], half[within], strict=True):
        edge = min(res, 2 * h) / 4 + 1e-6  # and a micrometre for rounding
        (x0, y0), (x1, y1) = cell(c - h + edge), cell(c + h - edge)
        x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, grid.width - 1), min(y1, grid.height - 1)
        missed[y0 : y1 + 1, x0 : x1 + 1] |= ~occupied[y0 : y1 + 1, x0 : x1 + 1]
    meets = (centres[:, 2] + half > z_min) & (centres[:, 2] - half < z_max)
    allowed = np.zeros_like(occupied)
    for c, h in zip(centres[meets, :2], half[meets], strict=True):
        (x0, y0), (x1, y1) = cell(c - h + 1e-6), cell(c + h - 1e-6)
        allowed[max(y0, 0) : y1 + 1, max(x0, 0) : x1 + 1] = True
    return int(missed.sum()), int((occupied & ~allowed).sum())


@pytest.mark.skipif(shutil.which("bt2vrml") is None, reason="octomap-tools is not installed")
def test_the_real_buildings_band_is_where_octomap_lists_its_voxels(shared_data, tmp_path):
    """The 0.3-1.5 m band of the Freiburg 079 floor on a 0.3 m grid, against the occupied leaves
    OctoMap's bt2vrml lists: every cell under a leaf inside the band is occupied, and every
    occupied cell lies under a leaf that meets the band. Control: the 2.0-2.6 m band's grid
    (above the doors) checked against the 0.3-1.5 m leaves fails both ways."""
    bt = tmp_path / "geb079.bt"
    bt.write_bytes((shared_data / "octomap" / "geb079.bt").read_bytes())
    geb = tmp_path / "geb.yaml"
    geb.write_text(yaml.safe_dump({"name": "geb079", "octomap": str(bt)}))
    building = load_scene(geb)
    centres, sizes = occupied_leaves_by_octomap(bt)
    assert len(centres) == building.world.occupied_leaves > 100_000
    band = building.ground_truth(0.3, 1.5, 0.3)
    assert (band.cells == 100).sum() > 1000
    assert band_against_leaves(band, centres, sizes, 0.3, 1.5) == (0, 0)
    above = building.ground_truth(2.0, 2.6, 0.3)
    missed, extra = band_against_leaves(above, centres, sizes, 0.3, 1.5)
    assert missed > 100 and extra > 100, (missed, extra)  # cells now, not leaves
