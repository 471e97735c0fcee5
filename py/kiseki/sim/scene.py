# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Scenes: a YAML description of a world (objects made of boxes, or a real OctoMap), its
magnetic field, and a default robot, sensors and route, so that a scene file alone gives a
meaningful run.

Top-level keys: name, description, source, bounds {min: [x, y, z], max: [x, y, z]}, floor,
octomap (a .bt file instead of, or beside, objects), objects (list of primitives, see
kiseki.sim.primitives; an object may carry ``only_in: teach`` or ``only_in: playback``),
grid_resolution, robot {type, start [x, y, yaw_deg], params, odometry_errors}, sensors (list),
route {waypoints [[x, y], ...], speed}, magnetic (see kiseki.sim.magnetic), measurement_grid
{lower: [x, y, z], upper: [x, y, z], spacing} (where the field is surveyed or scored, see
kiseki.sim.magnetic_survey; ``Scene.measurement_grid``). Several robots:
``robots`` (a list of {name, type, start, params, odometry_errors, sensors, route}) instead of
robot, sensors and route; and with several robots, ``turns`` {goal, speed, moves [{robot, to}]}
instead of routes: the robots take turns (cooperative positioning), one driving while the
others stand. ``poses`` {corner, distance, phi_deg [start, stop, step], heading_deg}: a sweep of
test poses around a corner (``Scene.poses``, a list of (x, y, theta)). ``pedestrians``: walking
discs (see kiseki.sim.pedestrians; ``Scene.pedestrians``). ``point_robots: true``: the paper
treats its robots as points, so the robots' bodies do not collide with each other (they still
do with obstacles and pedestrians).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from kiseki import _core
from kiseki._yaml import safe_load_12
from kiseki.core import Pose2
from kiseki.grid import OccupancyGrid
from kiseki.mapping import check_map_size
from kiseki.sim.magnetic_survey import MeasurementGrid
from kiseki.sim.pedestrians import Pedestrian, parse_pedestrians
from kiseki.sim.primitives import BoxList, expand

__all__ = ["Scene", "load_scene"]

TOP_KEYS = {
    "name",
    "description",
    "source",
    "bounds",
    "floor",
    "octomap",
    "objects",
    "grid_resolution",
    "robot",
    "sensors",
    "route",
    "magnetic",
    "measurement_grid",
    "robots",
    "turns",
    "poses",
    "pedestrians",
    "point_robots",
}
ROBOT_ENTRY_KEYS = {"name", "type", "start", "params", "odometry_errors", "sensors", "route"}
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
    magnetic: dict | None = None
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
    _bands: dict = field(default_factory=dict, repr=False, compare=False)  # ground_truth's

    def ground_truth(
        self, z_min: float, z_max: float, resolution: float | None = None
    ) -> OccupancyGrid:
        """The 2-D ground-truth grid of a height band (metres above the floor), at the scene's
        grid resolution or at `resolution`."""
        lo, hi = self.bounds
        res = self.grid_resolution if resolution is None else float(resolution)
        if not (np.isfinite(res) and res > 0):
            raise ValueError(f"resolution must be a positive number of metres, got {resolution}")
        key = (id(self.world), float(z_min), float(z_max), res)
        if key not in self._bands:  # rasterising takes 0.1-0.3 s: once per band and scene
            width = max(1, int(np.ceil((hi[0] - lo[0]) / res)))
            height = max(1, int(np.ceil((hi[1] - lo[1]) / res)))
            grid = OccupancyGrid(width, height, res, Pose2(float(lo[0]), float(lo[1]), 0.0))
            self.world.rasterize_band(z_min, z_max, grid)
            self._bands[key] = grid
        return self._bands[key].copy()  # the caller's own cells


def _bounds(doc: dict, where: str, world) -> tuple[np.ndarray, np.ndarray]:
    if "bounds" not in doc:
        lo, hi = world.bounds
        return np.asarray(lo), np.asarray(hi)
    b = doc["bounds"]
    if not isinstance(b, dict):
        raise ValueError(f"{where}: 'bounds' needs min: [x, y, z] and max: [x, y, z], got {b!r}")
    try:
        lo, hi = np.asarray(b["min"], dtype=float), np.asarray(b["max"], dtype=float)
    except (KeyError, TypeError, ValueError):
        raise ValueError(f"{where}: 'bounds' needs min: [x, y, z] and max: [x, y, z]") from None
    if lo.shape != (3,) or hi.shape != (3,) or not (hi > lo).all():
        raise ValueError(f"{where}: 'bounds' max must exceed min in x, y and z")
    return lo, hi


def _objects(doc: dict, where: str, variant: str) -> BoxList:
    boxes = BoxList.empty()
    objects = doc.get("objects", [])
    if not isinstance(objects, list):
        raise ValueError(f"{where}: 'objects' must be a list")
    for i, spec in enumerate(objects):
        label = f"{where}: objects[{i}]"
        only = spec.get("only_in") if isinstance(spec, dict) else None
        if only is not None and only not in VARIANTS:
            raise ValueError(f"{label}: only_in must be teach or playback, got {only!r}")
        if only is None or only == variant:
            boxes.extend(expand(spec, label))
    return boxes


def _floor(doc: dict, where: str, boxes: BoxList) -> None:
    if not doc.get("floor", False):
        return
    if "bounds" not in doc:
        raise ValueError(f"{where}: 'floor: true' needs 'bounds'")
    lo, hi = _bounds(doc, where, None)
    boxes.add(
        [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, -0.05], [hi[0] - lo[0], hi[1] - lo[1], 0.1]
    )


def load_scene(path: str | os.PathLike, variant: str = "teach") -> Scene:
    """Reads a scene file. ``variant`` selects objects marked ``only_in`` (a bicycle park that
    changes between teaching and playback)."""
    path = Path(path)
    if variant not in VARIANTS:
        raise ValueError(f"variant must be teach or playback, got {variant!r}")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: scene file not found")
    try:
        doc = safe_load_12(path.read_text(encoding="utf-8"))  # 5e-2 is a number, as in YAML 1.2
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a scene file (not UTF-8 text)") from None
    except yaml.YAMLError as err:
        raise ValueError(f"{path}: invalid YAML ({err})") from err
    if not isinstance(doc, dict):
        raise ValueError(f"{path}: a scene file must be a YAML mapping")
    unknown = sorted(set(doc) - TOP_KEYS)
    if unknown:
        raise ValueError(f"{path}: unknown key(s) {', '.join(unknown)}")
    where = str(path)
    boxes = _objects(doc, where, variant)
    _floor(doc, where, boxes)
    if "octomap" in doc:
        bt = (path.parent / doc["octomap"]).resolve()
        if not bt.is_file():
            raise FileNotFoundError(f"{path}: octomap file {bt} not found")
        try:
            world = _core.OctreeWorld.read_binary(str(bt))
        except RuntimeError as err:
            raise ValueError(f"{path}: {err}") from err
    else:
        if not boxes.centers:
            raise ValueError(f"{path}: a scene needs objects or an octomap")
        world = _core.BoxWorld(*boxes.arrays())
    res = doc.get("grid_resolution", 0.05)
    if isinstance(res, bool) or not isinstance(res, int | float) or not res > 0:
        raise ValueError(f"{path}: 'grid_resolution' must be a positive number")
    lo, hi = _bounds(doc, where, world)
    try:  # the ground truth's cells: the map limits of kiseki.mapping
        check_map_size(hi[0] - lo[0], hi[1] - lo[1], float(res))
    except ValueError as err:
        raise ValueError(f"{path}: grid_{err}") from None
    specs = _robot_specs(doc, where)
    scene = Scene(
        name=str(doc.get("name", path.stem)),
        path=path,
        world=world,
        bounds=(lo, hi),
        grid_resolution=float(res),
        robot=specs[0]["robot"],
        sensors=specs[0]["sensors"],
        route=specs[0]["route"],
        magnetic=doc.get("magnetic"),
        measurement_grid=_measurement_grid(doc, where, (lo, hi)),
        description=str(doc.get("description", "")),
        source=str(doc.get("source", "")),
        boxes=boxes,
        robot_specs=specs,
        turns=_turns(doc, where, specs),
        poses=_poses(doc, where),
        pedestrians=parse_pedestrians(doc.get("pedestrians"), where),
        point_robots=_flag(doc, "point_robots", where),
    )
    return scene


def _measurement_grid(doc: dict, where: str, bounds) -> MeasurementGrid | None:
    """``measurement_grid``: a regular grid inside the scene's bounds (see MeasurementGrid)."""
    if "measurement_grid" not in doc:
        return None
    grid = MeasurementGrid.from_dict(doc["measurement_grid"], f"{where}: measurement_grid")
    lo, hi = bounds
    if np.any(np.array(grid.lower) < lo) or np.any(np.array(grid.upper) > hi):
        raise ValueError(
            f"{where}: measurement_grid {list(grid.lower)}..{list(grid.upper)} leaves the "
            f"scene's bounds {lo.tolist()}..{hi.tolist()}"
        )
    return grid


def _flag(doc: dict, key: str, where: str) -> bool:
    value = doc.get(key, False)
    if not isinstance(value, bool):
        raise ValueError(f"{where}: '{key}' must be true or false, got {value!r}")
    return value


def _turns(doc: dict, where: str, specs: list[dict]) -> dict | None:
    """``turns: {goal: [x, y], speed: m/s, moves: [{robot: NAME, to: [x, y]}, ...]}``: the
    robots take turns (cooperative positioning): one drives straight to its place while the
    others stand; the last move ends on the goal."""
    if "turns" not in doc:
        return None
    t = doc["turns"]
    if not isinstance(t, dict) or set(t) - {"goal", "speed", "moves"}:
        raise ValueError(f"{where}: 'turns' must be a mapping of goal, speed and moves")
    names = [spec["name"] for spec in specs]
    if any(spec["route"] for spec in specs):
        raise ValueError(f"{where}: a scene with 'turns' gives its robots no routes")

    def point(value, what: str) -> tuple[float, float]:
        if (
            not isinstance(value, list | tuple)
            or len(value) != 2
            or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
            or not all(math.isfinite(v) for v in value)
        ):
            raise ValueError(f"{where}: turns: {what} must be [x, y] numbers, got {value!r}")
        return float(value[0]), float(value[1])

    goal = point(t.get("goal"), "goal")
    speed = t.get("speed", 0.3)
    if isinstance(speed, bool) or not isinstance(speed, int | float) or not 0 < speed <= 5:
        raise ValueError(f"{where}: turns: speed must be in (0, 5] m/s, got {speed!r}")
    moves = t.get("moves")
    if not isinstance(moves, list) or not moves or len(moves) > 10_000:
        raise ValueError(f"{where}: turns: moves must be a list of 1..10,000 moves")
    out = []
    for i, m in enumerate(moves):
        if not isinstance(m, dict) or set(m) != {"robot", "to"}:
            raise ValueError(f"{where}: turns: moves[{i}] must be {{robot: NAME, to: [x, y]}}")
        if m["robot"] not in names:
            raise ValueError(
                f"{where}: turns: moves[{i}]: unknown robot {m['robot']!r} ({', '.join(names)})"
            )
        out.append((str(m["robot"]), point(m["to"], f"moves[{i}].to")))
    if math.dist(out[-1][1], goal) > 1e-9:
        raise ValueError(f"{where}: turns: the last move must end on the goal {list(goal)}")
    return {"goal": goal, "speed": float(speed), "moves": out}


def _poses(doc: dict, where: str) -> list[tuple[float, float, float]] | None:
    """``poses: {corner: [x, y], distance: m, phi_deg: [start, stop, step], heading_deg}``: the
    robot's centre at corner + distance * (-cos phi, -sin phi) for phi = start, start + step, ...
    up to stop (inclusive), heading heading_deg in every pose (paper 004's Fig. 4 sweep)."""
    if "poses" not in doc:
        return None
    p = doc["poses"]
    keys = {"corner", "distance", "phi_deg", "heading_deg"}
    if not isinstance(p, dict) or set(p) != keys:
        raise ValueError(f"{where}: poses must be a mapping of exactly {', '.join(sorted(keys))}")

    def numbers(key: str, n: int) -> list[float]:
        value = p[key] if n > 1 else [p[key]]
        if (
            not isinstance(value, list | tuple)
            or len(value) != n
            or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
            or not all(math.isfinite(v) for v in value)
        ):
            raise ValueError(f"{where}: poses.{key} must be {n} finite number(s), got {p[key]!r}")
        return [float(v) for v in value]

    (cx, cy), (distance,) = numbers("corner", 2), numbers("distance", 1)
    start, stop, step = numbers("phi_deg", 3)
    (heading,) = numbers("heading_deg", 1)
    if distance <= 0:
        raise ValueError(f"{where}: poses.distance must be positive, got {distance}")
    if step <= 0 or stop < start or (stop - start) / step > 10_000:
        raise ValueError(
            f"{where}: poses.phi_deg must be [start, stop, step] with step > 0 and stop >= start"
            f" (at most 10,000 poses), got {p['phi_deg']!r}"
        )
    count = int(math.floor((stop - start) / step + 1e-9)) + 1
    out = []
    for i in range(count):
        phi = math.radians(start + i * step)
        x, y = cx - distance * math.cos(phi), cy - distance * math.sin(phi)
        out.append((x, y, math.radians(heading)))
    return out


def _robot_specs(doc: dict, where: str) -> list[dict]:
    """One entry per robot: {name, robot (type/start/params/errors), sensors, route}."""
    if "robots" not in doc:
        return [
            {
                "name": "robot",
                "robot": dict(doc.get("robot") or {}),
                "sensors": list(doc.get("sensors") or []),
                "route": dict(doc.get("route") or {}),
            }
        ]
    if any(k in doc for k in ("robot", "sensors", "route")):
        raise ValueError(f"{where}: give 'robots' or 'robot'/'sensors'/'route', not both")
    robots = doc["robots"]
    if not isinstance(robots, list) or not robots:
        raise ValueError(f"{where}: 'robots' must be a non-empty list")
    specs = []
    for i, entry in enumerate(robots):
        if not isinstance(entry, dict) or "name" not in entry:
            raise ValueError(f"{where}: robots[{i}] must be a mapping with a name")
        unknown = sorted(set(entry) - ROBOT_ENTRY_KEYS)
        if unknown:
            raise ValueError(f"{where}: robots[{i}]: unknown key(s) {', '.join(unknown)}")
        robot = {k: entry[k] for k in ("type", "start", "params", "odometry_errors") if k in entry}
        specs.append(
            {
                "name": str(entry["name"]),
                "robot": robot,
                "sensors": list(entry.get("sensors") or []),
                "route": dict(entry.get("route") or {}),
            }
        )
    names = [s["name"] for s in specs]
    if len(set(names)) != len(names):
        raise ValueError(f"{where}: robot names must be unique, got {names}")
    return specs
