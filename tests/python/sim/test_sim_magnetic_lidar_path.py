# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The ch. 5 route (data/worlds/magnetic_lidar_path.yaml) measured against the numbers its file
states on its ``#@`` lines: each pipe's peak at the sensor, the longest stretch without a peak,
and the 70 m stretch where the laser, as the file mounts it, returns no beam."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from kiseki.sim.magnetic import MagneticWorld
from kiseki.sim.scene import load_scene
from kiseki.sim.setup import build_robot, build_sensors

PATH = Path(__file__).resolve().parents[3] / "data" / "worlds" / "magnetic_lidar_path.yaml"


def stated(path: Path) -> dict:
    lines = path.read_text(encoding="utf-8").splitlines()
    return yaml.safe_load("\n".join(ln[2:] for ln in lines if ln.startswith("#@")))


@pytest.fixture(scope="module")
def figures():
    want = stated(PATH)
    scene = load_scene(PATH)
    world = MagneticWorld.from_dict(scene.magnetic, str(PATH))
    lo, hi = want["route_x"]
    xs = np.round(np.arange(lo, hi + 1e-9, 0.1), 9)
    pts = np.column_stack([xs, 0 * xs, 0 * xs + want["sensor_height"]])
    d = np.linalg.norm(world.static_field_at(pts) - world.earth_field, axis=1)
    inner = (d[1:-1] > d[:-2]) & (d[1:-1] >= d[2:]) & (d[1:-1] > want["peak_threshold"])
    (laser,) = [s for s in build_sensors(scene, build_robot(scene, 0), 0, 0.1) if s.kind == "laser"]
    grid = scene.ground_truth(laser.mount.z - 0.02, laser.mount.z + 0.02)
    xr = np.round(np.arange(lo, hi + 1e-9, 0.05), 9)
    poses = np.array([laser.mount.planar((x, 0.0, 0.0)) for x in xr])
    p = laser.device.params
    ranges = grid.cast_scans(poses, p.angles, max_range=p.max_range)
    return {
        "want": want,
        "xs": xs,
        "d": d,
        "peaks": xs[1:-1][inner],
        "xr": xr,
        "blind": (ranges >= p.max_range).all(axis=1),
        "laser": p,
    }


def test_every_pipe_gives_the_stated_peak_and_no_other(figures):
    want, xs, d = figures["want"], figures["xs"], figures["d"]
    stated_x = np.array([x for x, _ in want["peaks"]])
    sizes = np.array([d[np.abs(xs - x) <= 1.5].max() for x in stated_x])
    np.testing.assert_allclose(sizes, [s for _, s in want["peaks"]], rtol=want["peak_tolerance"])
    lo, hi = want["peak_range"]
    assert np.all((sizes >= lo) & (sizes <= hi)), sizes
    assert len(figures["peaks"]) == len(stated_x), figures["peaks"]
    np.testing.assert_allclose(figures["peaks"], stated_x, atol=0.3)
    stops = np.concatenate([[xs[0]], figures["peaks"], [xs[-1]]])
    assert np.diff(stops).max() <= want["max_gap"]


def test_the_laser_sees_nothing_exactly_over_the_stated_stretch(figures):
    blind, xr = figures["blind"], figures["xr"]
    lo, hi = figures["want"]["blind"]["x"]
    tol = figures["want"]["blind"]["tolerance"]
    assert figures["laser"].field_of_view_deg == 180.0 and figures["laser"].max_range == 30.0
    where = xr[blind]
    assert abs(where.min() - lo) <= tol and abs(where.max() - hi) <= tol, (where.min(), where.max())
    # one stretch, no gap in it, about the thesis' 70 m (X = -40 .. 30 m)
    assert blind[(xr >= where.min()) & (xr <= where.max())].all()
    assert 68.0 <= where.max() - where.min() <= 72.0
    # outside it the laser does see something
    assert not blind[(xr < lo - tol) | (xr > hi + tol)].any()
