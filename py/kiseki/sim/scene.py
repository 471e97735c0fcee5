# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Scenes: a YAML description of a world (objects made of boxes, or a real OctoMap), its
magnetic field, and a default robot, sensors and route, so that a scene file alone gives a
meaningful run.

Top-level keys: name, description, source, bounds {min: [x, y, z], max: [x, y, z]}, floor,
octomap (a .bt file instead of, or beside, objects), objects (list of primitives, see
kiseki.sim.primitives; an object, and a magnetic source, may carry ``only_in: teach`` or
``only_in: playback``),
grid_resolution, robot {type, start [x, y, yaw_deg], params, odometry_errors}, sensors (list),
route {waypoints [[x, y], ...], names, speed} (kiseki.sim.scene_schema.Route), magnetic (see
kiseki.sim.magnetic), measurement_grid
{lower: [x, y, z], upper: [x, y, z], spacing} (where the field is surveyed or scored, see
kiseki.sim.magnetic_survey; ``Scene.measurement_grid``). Several robots:
``robots`` (a list of {name, type, start, params, odometry_errors, sensors, route}) instead of
robot, sensors and route; and with several robots, ``turns`` {goal, speed, moves [{robot, to}]}
instead of routes: the robots take turns (cooperative positioning), one driving while the
others stand. ``poses`` {corner, distance, phi_deg [start, stop, step], heading_deg}: a sweep of
test poses around a corner (``Scene.poses``, a list of (x, y, theta)). ``pedestrians``: walking
discs (see kiseki.sim.pedestrians; ``Scene.pedestrians``). ``point_robots: true``: the paper
treats its robots as points, so the robots' bodies do not collide with each other (they still
do with obstacles and pedestrians). ``calibrated``: the parameters fitted to a paper's number,
each with that number (kiseki.sim.calibration; ``Scene.calibrated``).

The file is checked by the models of kiseki.sim.scene_schema (limits on the boxes, cells,
points, robots, pedestrians, moves and poses a scene makes are stated there); errors name the
file, the field and the value.
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from kiseki import _core
from kiseki._support.inputs import MIB, YAML_LIMIT, check_input, read_input
from kiseki._support.real_numbers import check_number
from kiseki._support.schema import SchemaError, parse
from kiseki._support.yaml import safe_load_12, yaml_problem
from kiseki.core import Pose2
from kiseki.grid import OccupancyGrid
from kiseki.sim.calibration import check_marks
from kiseki.sim.magnetic_schema import MagneticSection
from kiseki.sim.magnetic_survey import MeasurementGrid
from kiseki.sim.pedestrians import Pedestrian
from kiseki.sim.primitives import BoxList, boxes_of
from kiseki.sim.scene_schema import Poses, SceneDoc, Turns, extent_problem

__all__ = [
    "MAX_OCTOMAP_BYTES",
    "Scene",
    "check_route_in_bounds",
    "check_scene_file",
    "load_scene",
    "read_octree",
]

MAX_OCTOMAP_BYTES = 32 * MIB
"""An OctoMap ``.bt`` file holds at most this: reading one takes about 120 times its size in
memory (``geb079.bt``, a building floor at 8 cm: 0.2 MB, 25 MB), so 32 MiB is about 4 GB."""
OCTOMAP_RESOLUTIONS = (1e-4, 10.0)  # m per voxel: OctoMap's buildings use 0.01-0.2 m
OCTOMAP_EXTENT = 1e4  # m: the largest building or site an OctoMap world may span


def read_octree(bt: Path) -> Any:
    """An OctoMap ``.bt`` file as a world, its size and header checked first; a voxel size or
    an extent beyond kiseki's limits (a header edited to 1e9 m voxels asked for terabytes
    later) is refused naming the file (ValueError)."""
    check_input(bt, "OctoMap files", MAX_OCTOMAP_BYTES)
    if not Path(bt).is_file():
        raise FileNotFoundError(f"{bt}: OctoMap file not found")
    try:
        world = _core.OctreeWorld.read_binary(str(bt))
    except RuntimeError as err:
        raise ValueError(str(err)) from None
    lo_res, hi_res = OCTOMAP_RESOLUTIONS
    if not lo_res <= world.resolution <= hi_res:
        raise ValueError(
            f"{bt}: voxels of {world.resolution:g} m: kiseki reads {lo_res:g}-{hi_res:g} m"
        )
    lo, hi = (np.asarray(b, dtype=float) for b in world.bounds)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()) or (hi - lo).max() > OCTOMAP_EXTENT:
        raise ValueError(f"{bt}: the occupied voxels span more than {OCTOMAP_EXTENT:g} m")
    return world


VARIANTS = ("teach", "playback")


@dataclass
class Scene:
    """A loaded scene: the 3-D world and everything a run needs from the file."""

    name: str
    path: Path
    world: Any  # kiseki._core.BoxWorld or OctreeWorld
    bounds: tuple[np.ndarray, np.ndarray]
    grid_resolution: float
    robot: dict = field(default_factory=dict)
    sensors: list = field(default_factory=list)
    route: dict = field(default_factory=dict)
    magnetic: dict | None = None  # the file's section; its sources may carry only_in
    variant: str = "teach"  # which objects and magnetic sources marked only_in are in
    measurement_grid: MeasurementGrid | None = None  # where the magnetic field is surveyed
    description: str = ""
    source: str = ""
    boxes: BoxList | None = None
    robot_specs: list = field(default_factory=list)  # [{name, robot, sensors, route}]
    # cooperative positioning: {goal: (x, y), speed, moves: [(robot name, (x, y)), ...]}
    turns: dict | None = None
    poses: list[tuple[float, float, float]] | None = None  # a sweep of test poses (x, y, theta)
    pedestrians: list[Pedestrian] = field(default_factory=list)
    # the paper treats its robots as points: contacts between them are logged, not stopped at
    point_robots: bool = False
    # the parameters fitted to a paper's number: [{parameter, fitted_to, unit, source}]
    calibrated: list[dict] = field(default_factory=list)
    sha1: str = ""  # of the scene file's bytes, as read (recorded with every run)
    _bands: dict = field(default_factory=dict, repr=False, compare=False)  # ground_truth's

    def ground_truth(
        self, z_min: float, z_max: float, resolution: float | None = None
    ) -> OccupancyGrid:
        """The 2-D ground-truth grid of a height band (metres above the floor), at the scene's
        grid resolution or at `resolution`."""
        lo, hi = self.bounds
        res = self.grid_resolution if resolution is None else resolution
        res = check_number(res, "resolution", 0.0, low_open=True, unit="m")
        key = (id(self.world), float(z_min), float(z_max), res)
        if key not in self._bands:  # rasterising takes 0.1-0.3 s: once per band and scene
            width = max(1, int(np.ceil((hi[0] - lo[0]) / res)))
            height = max(1, int(np.ceil((hi[1] - lo[1]) / res)))
            grid = OccupancyGrid(width, height, res, Pose2(float(lo[0]), float(lo[1]), 0.0))
            self.world.rasterize_band(z_min, z_max, grid)
            self._bands[key] = grid
        return self._bands[key].copy()  # the caller's own cells


def _boxes(doc: SceneDoc, variant: str) -> BoxList:
    """The boxes of the objects of this variant, and the floor's (a 0.1 m slab under the
    bounds) when the scene has one."""
    boxes = BoxList.empty()
    for obj in doc.objects:
        if obj.only_in is None or obj.only_in == variant:
            boxes.extend(boxes_of(obj))
    if doc.floor:
        lo, hi = doc.bounds.min, doc.bounds.max
        boxes.add(
            [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, -0.05], [hi[0] - lo[0], hi[1] - lo[1], 0.1]
        )
    return boxes


def _check_objects_meet_bounds(doc: SceneDoc, path: Path, lo: np.ndarray, hi: np.ndarray) -> None:
    """A SchemaError naming the first object (of either variant) wholly outside the scene's
    bounds: no sensor, map or grid of the run would hold it. An object that reaches past the
    bounds (a wall longer than the room) is kept. Each box is taken as the axis-aligned box
    around it (|R| times its half sizes), so a turned object is never refused wrongly."""
    for i, obj in enumerate(doc.objects):
        centers, halves, rotations = boxes_of(obj).arrays()
        reach = np.einsum("nij,nj->ni", np.abs(rotations), halves)
        meets = np.all((centers - reach <= hi) & (centers + reach >= lo), axis=1)
        if centers.size and not meets.any():
            box_lo, box_hi = (centers - reach).min(axis=0), (centers + reach).max(axis=0)
            raise SchemaError(
                f"{path}: objects[{i}] spans x {box_lo[0]:g}..{box_hi[0]:g}, "
                f"y {box_lo[1]:g}..{box_hi[1]:g}, z {box_lo[2]:g}..{box_hi[2]:g}: wholly outside "
                f"the scene's bounds x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g}, "
                f"z {lo[2]:g}..{hi[2]:g}"
            )


def load_scene(path: str | os.PathLike, variant: str = "teach") -> Scene:
    """Reads a scene file. ``variant`` selects objects marked ``only_in`` (a bicycle park that
    changes between teaching and playback), and magnetic sources so marked (``Scene.variant``:
    build the field with ``MagneticWorld.from_dict(scene.magnetic, variant=scene.variant)``).
    A :class:`~kiseki._support.schema.SchemaError` (a ValueError) names the file, the field and the
    value of what does not match."""
    path = Path(path)
    if variant not in VARIANTS:
        raise ValueError(f"variant must be teach or playback, got {variant!r}")
    check_input(path)
    check_scene_file(path)
    try:
        # 5e-2 is a number, as in YAML 1.2
        data = read_input(path, "scene files", YAML_LIMIT)
        raw = safe_load_12(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a scene file (not UTF-8 text)") from None
    except yaml.YAMLError as err:
        raise ValueError(f"{path}: invalid YAML ({yaml_problem(err)})") from err
    if not isinstance(raw, dict):
        raise ValueError(f"{path}: a scene file must be a YAML mapping")
    doc = parse(SceneDoc, raw, path)
    if raw.get("magnetic") is not None:  # checked now; the field is built when a sensor needs it
        parse(MagneticSection, raw["magnetic"], path, at=("magnetic",))
    boxes = _boxes(doc, variant)
    if doc.octomap is not None:
        bt = (path.parent / doc.octomap).resolve()
        try:
            world = read_octree(bt)
        except ValueError as err:
            raise ValueError(f"{path}: octomap {err}") from None
        except FileNotFoundError:
            raise FileNotFoundError(f"{path}: octomap file {bt} not found") from None
    else:
        if not boxes.centers:
            raise SchemaError(f"{path}: objects: a scene needs objects or an octomap")
        world = _core.BoxWorld(*boxes.arrays())
    if doc.bounds is None:  # the world's: checked here (the file's are checked by SceneDoc)
        lo, hi = (np.asarray(b, dtype=float) for b in world.bounds)
        problem = extent_problem(lo, hi, doc.grid_resolution, doc.measurement_grid)
        if problem is not None:
            raise SchemaError(f"{path}: {problem[0]}: {problem[2]}, got {problem[1]!r}")
    else:
        lo, hi = np.array(doc.bounds.min), np.array(doc.bounds.max)
        _check_objects_meet_bounds(doc, path, lo, hi)
    specs = _robot_specs(doc)
    return Scene(
        name=doc.name if doc.name is not None else path.stem,
        path=path,
        world=world,
        bounds=(lo, hi),
        grid_resolution=doc.grid_resolution,
        robot=specs[0]["robot"],
        sensors=specs[0]["sensors"],
        route=specs[0]["route"],
        magnetic=raw.get("magnetic"),
        variant=variant,
        measurement_grid=_measurement_grid(doc, path),
        description=doc.description,
        source=doc.source,
        boxes=boxes,
        robot_specs=specs,
        turns=_turns(doc.turns),
        poses=_poses(doc.poses),
        pedestrians=[Pedestrian(**p.model_dump()) for p in doc.pedestrians or []],
        sha1=hashlib.sha1(data).hexdigest(),
        point_robots=doc.point_robots,
        calibrated=check_marks(raw, doc.calibrated, str(path)),
    )


def _measurement_grid(doc: SceneDoc, path: Path) -> MeasurementGrid | None:
    """``measurement_grid``: a regular grid inside the scene's bounds (see MeasurementGrid)."""
    g = doc.measurement_grid
    if g is None:
        return None
    return MeasurementGrid(g.lower, g.upper, g.spacing, f"{path}: measurement_grid")


def _turns(turns: Turns | None) -> dict | None:
    """``turns: {goal: [x, y], speed: m/s, moves: [{robot: NAME, to: [x, y]}, ...]}``: the
    robots take turns (cooperative positioning): one drives straight to its place while the
    others stand; the last move ends on the goal."""
    if turns is None:
        return None
    return {
        "goal": turns.goal,
        "speed": turns.speed,
        "moves": [(m.robot, m.to) for m in turns.moves],
    }


def _poses(poses: Poses | None) -> list[tuple[float, float, float]] | None:
    """``poses: {corner: [x, y], distance: m, phi_deg: [start, stop, step], heading_deg}``: the
    robot's centre at corner + distance * (-cos phi, -sin phi) for phi = start, start + step, ...
    up to stop (inclusive), heading heading_deg in every pose (paper 004's Fig. 4 sweep)."""
    if poses is None:
        return None
    (cx, cy), distance = poses.corner, poses.distance
    start, _, step = poses.phi_deg
    out = []
    for i in range(poses.count):
        phi = math.radians(start + i * step)
        x, y = cx - distance * math.cos(phi), cy - distance * math.sin(phi)
        out.append((x, y, math.radians(poses.heading_deg)))
    return out


def _robot_specs(doc: SceneDoc) -> list[dict]:
    """One entry per robot: {name, robot (type/start/params/errors), sensors, route}."""
    if doc.robots is None:
        return [
            {
                "name": "robot",
                "robot": dict(doc.robot or {}),
                "sensors": list(doc.sensors or []),
                "route": doc.route.as_dict() if doc.route else {},
            }
        ]
    specs = []
    for entry in doc.robots:
        given = entry.model_dump(exclude_unset=True)
        robot = {k: given[k] for k in ("type", "start", "params", "odometry_errors") if k in given}
        specs.append(
            {
                "name": entry.name,
                "robot": robot,
                "sensors": list(entry.sensors or []),
                "route": entry.route.as_dict() if entry.route else {},
            }
        )
    return specs


def check_scene_file(path: str | os.PathLike) -> None:
    """IsADirectoryError for a folder (it read 'not found' of a folder that is there), else
    FileNotFoundError when `path` is no file."""
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(f"{path}: a folder, not a scene file")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: scene file not found")


def check_route_in_bounds(scene: Scene, waypoints, names=None) -> None:
    """A ValueError naming the scene and the first route waypoint outside its bounds (x, y):
    the robot would leave the mapped world to reach it."""
    lo, hi = (np.asarray(b, dtype=float)[:2] for b in scene.bounds)
    names = names or [f"W{i}" for i in range(len(waypoints))]
    for name, point in zip(names, waypoints, strict=True):
        if not (np.all(np.asarray(point) >= lo) and np.all(np.asarray(point) <= hi)):
            raise ValueError(
                f"{scene.path}: route waypoint {name} {list(point)} lies outside the scene's "
                f"bounds x {lo[0]:g}..{hi[0]:g}, y {lo[1]:g}..{hi[1]:g}"
            )
