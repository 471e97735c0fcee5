# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A taught run as the server sees it: the waypoint file (read, and rewritten only to rename a
waypoint: atomically, the previous version kept beside it as ``waypoints.yaml.bak``), the taught
map of the method's band (read only; served as PNG or JSON), and the scene the run was taught
in (recorded in the teaching log's metadata)."""

from __future__ import annotations

import os
import re
import tempfile
import threading
from pathlib import Path

import numpy as np
import yaml

from kiseki import _core
from kiseki._support.atomic import atomic_write
from kiseki.apps.teach.taught_route import load_route
from kiseki.grid import OccupancyGrid
from kiseki.io.ros_map import load_map, write_image
from kiseki.io.runlog import read_run
from kiseki.teach.local_maps import METHODS
from kiseki.teach.route_check import read_travelled
from kiseki.teach.waypoint_schema import MAX_NAME_LENGTH, read_waypoint_file

__all__ = ["NAME_RULE", "TaughtRun", "WaypointError", "taught_scene"]

# A waypoint name: letters (any script), digits, '_', '.', '-', single inner spaces; as long as
# the waypoint file, a route and the route history take (MAX_NAME_LENGTH)
NAME_RULE = (
    f"letters, digits, '_', '.', '-' and single inner spaces, at most {MAX_NAME_LENGTH} characters"
)
_NAME = re.compile(r"\w[\w.\-]*(?: [\w.\-]+)*")


class WaypointError(ValueError):
    """A refused waypoint edit; ``status`` is the HTTP status that says why."""

    def __init__(self, message: str, status: int) -> None:
        super().__init__(message)
        self.status = status


def taught_scene(folder: str | os.PathLike) -> str | None:
    """The scene file the run in `folder` was taught in, as its teaching log records it (None
    when the log is missing or records none)."""
    doc = read_waypoint_file(Path(folder) / "waypoints.yaml")
    log = Path(folder) / (doc.log or "teach.mcap")
    if not log.is_file():
        return None
    return read_run(log).metadata.get("scene_file")


class TaughtRun:
    """The waypoints and the `method`'s taught map of the teaching folder `folder`."""

    def __init__(self, folder: str | os.PathLike, method: str = "both") -> None:
        folder = Path(folder)
        if not folder.is_dir():
            raise FileNotFoundError(f"{folder}: no such folder (run kiseki demo or kiseki teach)")
        if method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
        self.folder, self.method = folder, method
        self.band = METHODS[method][0]
        self.path = folder / "waypoints.yaml"
        if not self.path.is_file():
            raise FileNotFoundError(
                f"{self.path}: no waypoint file (kiseki teach writes one when a waypoint is marked)"
            )
        doc = self._read()  # names are unique (the model checks it)
        names = [w["name"] for w in doc["waypoints"]]
        if len(names) < 2:
            raise ValueError(f"{self.path}: {len(names)} waypoint(s); a route needs two")
        self.map_path, _ = load_route(self.path, self.band, names)  # checks the map's SHA-1
        self.environment: OccupancyGrid = load_map(self.map_path)
        self.waypoints: list[dict] = [dict(w) for w in doc["waypoints"]]
        self.travelled = read_travelled(self.path)  # the teaching run's odometry poses, or None
        self._lock = threading.Lock()
        self._png: bytes | None = None

    def _read(self) -> dict:
        """The waypoint file checked by its model (:mod:`kiseki.teach.waypoint_schema`: a
        problem names the file, the field and the value), as plain YAML data."""
        return read_waypoint_file(self.path).model_dump(mode="json", exclude_none=True)

    def by_name(self, name: str) -> dict | None:
        with self._lock:
            return next((dict(w) for w in self.waypoints if w["name"] == name), None)

    def public(self) -> dict:
        """The waypoints (id, name, taught pose) and the map's metadata, for GET /api/waypoints."""
        with self._lock:
            marks = [
                {
                    "id": w.get("id", i),
                    "name": w["name"],
                    "x": w["x"],
                    "y": w["y"],
                    "theta": w["theta"],
                }
                for i, w in enumerate(self.waypoints)
            ]
        return {"waypoints": marks, "map": self.map_info()}

    def map_info(self) -> dict:
        grid = self.environment
        origin = grid.origin
        return {
            "method": self.method,
            "band": self.band,
            "width": int(grid.width),
            "height": int(grid.height),
            "resolution": float(grid.resolution),
            "origin": [float(origin.x), float(origin.y), float(origin.theta)],
            "image": "/api/map",
        }

    def map_json(self) -> dict:
        """The map's cells, row-major from the bottom row (y = origin y) up: -1 unknown,
        0 free, 100 occupied."""
        return {**self.map_info(), "cells": np.asarray(self.environment.cells).ravel().tolist()}

    def map_png(self) -> bytes:
        """The map as a ROS map image (top row = the largest y; black occupied, white free,
        grey unknown), encoded as PNG in a temporary file outside the taught folder."""
        if self._png is None:
            image = _core.image_from_occupancy(self.environment, mode="trinary")
            with tempfile.TemporaryDirectory(prefix="kiseki-map-") as tmp:
                target = Path(tmp) / "map.png"
                write_image(target, image)
                self._png = target.read_bytes()
        return self._png

    def rename(self, old: str, new: str) -> dict:
        """Renames waypoint `old` to `new` in the waypoint file (the previous file kept as
        waypoints.yaml.bak, both written atomically); WaypointError 404 / 409 / 422."""
        if not isinstance(new, str) or len(new) > MAX_NAME_LENGTH or not _NAME.fullmatch(new):
            raise WaypointError(f"bad waypoint name {new!r}: use {NAME_RULE}", 422)
        with self._lock:
            doc = self._read()  # the file as it is now, not as it was at start
            marks = doc["waypoints"]
            mark = next((w for w in marks if w.get("name") == old), None)
            if mark is None:
                raise WaypointError(f"no waypoint named {old!r}", 404)
            if new != old and any(w.get("name") == new for w in marks):
                raise WaypointError(f"a waypoint named {new!r} exists already", 409)
            previous = self.path.read_bytes()
            mark["name"] = new
            text = yaml.safe_dump(doc, sort_keys=False)
            backup = self.path.with_name(self.path.name + ".bak")
            atomic_write(backup, lambda tmp: Path(tmp).write_bytes(previous))
            atomic_write(self.path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
            for w in self.waypoints:
                if w["name"] == old:  # names are unique
                    w["name"] = new
            return {"id": mark.get("id"), "name": new, "x": mark["x"], "y": mark["y"]}
