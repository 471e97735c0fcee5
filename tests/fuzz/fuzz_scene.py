# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Fuzz the scene reader kiseki.sim.scene.load_scene (both variants); with ``--setup`` also
the robot and sensor set-up read from it (kiseki.sim.setup.build_robot, build_sensors: about
0.5 s an input, spent rasterising the scene to check the start pose, so CI leaves it out); see
fuzz_common.py. Seeds: the project's worlds (comment lines dropped), a scene on a small OctoMap."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from fuzz_common import PROJECT_DATA, main

from kiseki import _core
from kiseki.sim.scene import load_scene
from kiseki.sim.setup import build_robot, build_sensors

OCTOMAP_SCENE = b"""name: tiny
octomap: tiny.bt
bounds: {min: [-1, -1, 0], max: [3, 2, 1]}
grid_resolution: 0.1
robot: {type: omni, start: [0.0, 0.0, 0.0]}
sensors:
  - {type: laser, preset: speed_lrf, name: scan, mount: [0.2, 0.0, 0.3, 0.0]}
route: {waypoints: [[0.0, 0.0], [2.0, 0.0]], speed: 0.5}
"""


def seeds(_folder: Path):
    for world in sorted((PROJECT_DATA / "worlds").glob("*.yaml")):
        lines = world.read_bytes().splitlines(keepends=True)
        yield b"".join(line for line in lines if not line.lstrip().startswith(b"#"))
    yield OCTOMAP_SCENE


def prepare(files: Path) -> None:
    boxes = _core.BoxWorld([[1.0, 0.5, 0.5]], [[0.4, 0.4, 0.5]], [np.eye(3)])
    _core.OctreeWorld.from_boxes(boxes, 0.1).write_binary(str(files / "tiny.bt"))


def read(path: Path) -> object:
    load_scene(path, variant="playback")
    return load_scene(path)


def read_with_setup(path: Path) -> object:
    scene = read(path)
    for index in range(len(scene.robot_specs)):
        robot = build_robot(scene, seed=0, index=index)
        build_sensors(scene, robot, seed=0, dt=0.1, index=index)
    return scene


if __name__ == "__main__":
    setup = "--setup" in sys.argv
    if setup:
        sys.argv.remove("--setup")
    reader = read_with_setup if setup else read
    main(reader, seeds, suffix=".yaml", prepare=prepare, packages=("kiseki", "yaml"))
