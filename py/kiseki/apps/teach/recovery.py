# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A teaching run rebuilt from its MCAP log (`kiseki teach --resume`): after a crash or a kill,
the maps and the waypoints of the steps the log holds, with the merge rule the run was taught
with. The log is refused in a scene other than the one it was taught in."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kiseki._support.atomic import check_writable_folder
from kiseki.apps.teach.teaching_files import (
    TeachResult,
    environment_grid,
    measure_taught_maps,
    merge_local_maps,
    write_teaching_files,
)
from kiseki.io.runlog import read_run
from kiseki.sim.scene import Scene
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.teach.environment_map import MERGE_RULES, EnvironmentMap
from kiseki.teach.local_maps import BANDS, LocalMapMaker
from kiseki.teach.scene_identity import (
    TaughtScene,
    recorded_scene_file,
    resolve_scene_file,
    scene_digest,
)

__all__ = ["recover"]


def _check_same_scene(metadata: dict, scene: Scene, log) -> None:
    """Refuses to rebuild a log in a scene other than the one it was taught in: by the scene
    file's SHA-1 when the log records it, else by the recorded file when it still exists."""
    taught = metadata.get("scene_file", "")
    recorded = metadata.get("scene_sha1")
    found = resolve_scene_file(taught, Path(log).parent)
    if recorded is None and found is not None:
        recorded = scene_digest(found)  # logs from before the digest was recorded
    if recorded is not None and recorded != scene_digest(scene.path):
        raise ValueError(
            f"{log} was taught in {found or taught or 'another scene'}, not in {scene.path} "
            "(the scene files differ): give the scene it was taught in"
        )


def recover(
    scene: Scene, log: str | os.PathLike, out: str | os.PathLike, merge: str | None = None
) -> TeachResult:
    """Rebuilds the maps and waypoints of a teaching run from its MCAP log (after a crash),
    with the merge rule the run was taught with (or `merge`)."""
    check_writable_folder(out, "teaching")
    run = read_run(log)
    _check_same_scene(run.metadata, scene, log)
    topics = run.topics()
    merge = merge or run.metadata.get("merge", "thesis")
    if merge not in MERGE_RULES:
        raise ValueError(f"{log}: unknown merge rule {merge!r} (known: {', '.join(MERGE_RULES)})")
    setup = build_robot(scene, 0)
    cameras = [s for s in build_sensors(scene, setup, 0, 0.1) if s.kind == "depth_camera"]
    missing = [c.name for c in cameras if f"/{c.name}" not in topics]
    if missing or "/odom" not in topics:
        raise ValueError(f"{log}: not a teaching log of {scene.path} (missing topics)")
    odom = {round(t, 6): (m["x"], m["y"], m["theta"]) for t, m in run.messages("/odom")}
    truth = {}
    if "/ground_truth" in topics:
        times, poses = run.poses("/ground_truth")
        truth = {round(float(t), 6): tuple(p) for t, p in zip(times, poses, strict=True)}
    images = [dict((round(t, 6), d) for t, d in run.depth_images(f"/{c.name}")) for c in cameras]
    makers = {b: LocalMapMaker([c.device for c in cameras], b) for b in BANDS}
    maps = {b: EnvironmentMap(environment_grid(scene), merge) for b in BANDS}
    steps, truths = 0, []
    for t in sorted(odom):
        if all(t in im for im in images):
            merge_local_maps(
                maps, makers, [np.asarray(im[t], dtype=np.float32) for im in images], odom[t]
            )
            steps += 1
            if t in truth:
                truths.append(truth[t])
    marks = [m for _, m in run.messages("/waypoints")] if "/waypoints" in topics else []
    Path(out).mkdir(parents=True, exist_ok=True)
    grids = {b: m.map() for b, m in maps.items()}
    measured = measure_taught_maps(scene, grids, np.array(truths), cameras) if truths else None
    scene_id = TaughtScene(recorded_scene_file(scene.path, out), scene_digest(scene.path), str(out))
    files = (grids, marks, Path(log), steps, merge, measured, scene_id)
    return write_teaching_files(Path(out), *files)
