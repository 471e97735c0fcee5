# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What a teaching run (`kiseki.apps.teach.teaching`) writes and measures: the environment map it
starts from, its taught maps against the scene's truth, and the map and waypoint files, written
so that a full disk leaves the previous ones consistent with one another."""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from kiseki._support.atomic import atomic_write_all
from kiseki.core import Pose2
from kiseki.grid import OccupancyGrid
from kiseki.io.ros_map import map_files
from kiseki.sim.scene import Scene
from kiseki.teach.local_maps import BANDS
from kiseki.teach.map_truth import taught_map_truth
from kiseki.teach.scene_identity import TaughtScene

__all__ = [
    "TeachResult",
    "environment_grid",
    "measure_taught_maps",
    "merge_local_maps",
    "write_teaching_files",
]


@dataclass(frozen=True)
class TeachResult:
    maps: dict[str, Path]  # band -> map YAML
    waypoints: Path | None  # None: no waypoint was marked, no waypoint file written
    log: Path
    steps: int
    marks: list[dict]
    merge: str = "thesis"  # the merge rule the maps were built with
    truth: dict | None = None  # band -> the map against the scene's truth (map_truth.json)
    scene: TaughtScene | None = None  # the scene file taught in and its SHA-1


def merge_local_maps(maps: dict, makers: dict, images: list, odom) -> None:
    """One step of teaching (sec. 3.4): each band's local map from the depth `images`, placed
    by the odometry pose `odom` (x, y, theta), merged into that band's environment map."""
    pose = Pose2(*odom)
    for band, maker in makers.items():
        maps[band].merge(maker.builder(images), pose)


def environment_grid(scene: Scene, resolution: float = 0.1, margin: float = 4.0) -> OccupancyGrid:
    """The empty environment map M of a scene: its bounds and ``margin`` metres around them."""
    lo, hi = scene.bounds
    width = int(math.ceil((hi[0] - lo[0] + 2 * margin) / resolution))
    height = int(math.ceil((hi[1] - lo[1] + 2 * margin) / resolution))
    return OccupancyGrid(width, height, resolution, Pose2(lo[0] - margin, lo[1] - margin, 0.0))


def measure_taught_maps(
    scene: Scene,
    maps: dict[str, OccupancyGrid],
    truths: np.ndarray,
    cameras: list,
    local_size: float = 8.0,
) -> dict:
    """Each taught map against the scene's ground truth at its own band's heights (and its
    resolution), over what the cameras could reach from the true poses of the run: see
    `kiseki.teach.map_truth.taught_map_truth` (every camera's poses together: a cell that several
    reach counts once). A camera's reach is half the local map's size less the mount's offset
    from the robot's centre (so every cell in reach lies inside L), within its max range, and
    no nearer than its minimum depth (a bench under it is invisible)."""
    truths = np.asarray(truths, dtype=np.float64).reshape(-1, 3)
    poses, hfov, reach, min_range = [], [], [], []
    for camera in cameras:
        device, mount = camera.device, camera.device.mount
        poses.append(np.array([mount.planar(p) for p in truths]).reshape(-1, 3))
        n = len(truths)
        hfov.append(np.full(n, math.radians(device.params.hfov_deg)))
        far = min(device.params.max_range, 0.5 * local_size - math.hypot(mount.x, mount.y))
        reach.append(np.full(n, far))
        min_range.append(np.full(n, device.params.min_range))
    poses, hfov, reach, min_range = (np.concatenate(v) for v in (poses, hfov, reach, min_range))
    out = {}
    for band, grid in maps.items():
        truth = scene.ground_truth(*BANDS[band], resolution=grid.resolution)
        measured = taught_map_truth(grid, truth, poses, hfov, reach, min_range)
        out[band] = {**measured.as_dict(), "truth_band_m": list(BANDS[band])}
    return out


def write_teaching_files(
    out: Path,
    maps: dict[str, OccupancyGrid],
    marks: list[dict],
    log: Path,
    steps: int,
    merge: str,
    truth: dict | None,
    scene: TaughtScene,
) -> TeachResult:
    """Every file is written before any replaces its previous version (a full disk leaves the
    previous maps and waypoint file as they were, consistent with one another)."""
    paths = {band: out / f"map_{band}.yaml" for band in maps}
    writes, digests = [], {}
    for band, grid in maps.items():
        (image, write_image), yaml_file = map_files(grid, paths[band])

        def hashed(tmp: str, band=band, write_image=write_image) -> None:
            write_image(tmp)
            digests[band] = hashlib.sha1(Path(tmp).read_bytes()).hexdigest()

        writes += [(image, hashed), yaml_file]
    if truth is not None:
        truth_text = json.dumps({"merge": merge, "maps": truth}, indent=2)
        writes.append(
            (out / "map_truth.json", lambda tmp: Path(tmp).write_text(truth_text, "utf-8"))
        )

    def taught_map(band: str, p: Path) -> dict:
        """What ties the waypoints to a map: its file, its image's digest, its geometry."""
        origin = maps[band].origin
        return {
            "file": p.name,
            "image_sha1": digests[band],
            "resolution": float(maps[band].resolution),
            "origin": [float(origin.x), float(origin.y), float(origin.theta)],
        }

    def waypoints(tmp: str) -> None:  # after the images: it records their digests
        doc = {
            "log": log.name,
            "merge": merge,
            "scene_file": scene.file,
            "scene_sha1": scene.sha1,
            "maps": {band: taught_map(band, p) for band, p in paths.items()},
            "waypoints": marks,
        }
        Path(tmp).write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")

    if not marks:  # a waypoint file holds at least one (playback and serve refuse an empty one)
        atomic_write_all(writes)
        (out / "waypoints.yaml").unlink(missing_ok=True)  # an earlier teaching's, of other maps
        return TeachResult(paths, None, log, steps, marks, merge, truth, scene)
    atomic_write_all([*writes, (out / "waypoints.yaml", waypoints)])
    return TeachResult(paths, out / "waypoints.yaml", log, steps, marks, merge, truth, scene)
