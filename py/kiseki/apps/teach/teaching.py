# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Teaching (thesis sec. 3.4): the robot is pushed once along the route; every step its local
map is placed by odometry into the environment map M with the thesis' merge rules, and a
waypoint (id, name, odometry pose) is recorded where the operator marks one. The run is logged
to MCAP as it goes (odometry, depth images, waypoint marks), so that `recover` (in `recovery`,
importable from here) rebuilds the map and the waypoints from the log after a crash, losing at
most the last unwritten chunk (well under a second at 10 Hz).

The files a run writes (its maps, their truth, the waypoint file) are `teaching_files`'.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

import numpy as np
from tqdm import tqdm

from kiseki._support.atomic import check_writable_folder, reworded
from kiseki._support.real_numbers import check_number
from kiseki._support.replaced_files import refuse_replacing
from kiseki.apps.teach.recovery import recover
from kiseki.apps.teach.teaching_files import (
    TeachResult,
    environment_grid,
    measure_taught_maps,
    merge_local_maps,
    write_teaching_files,
)
from kiseki.control import PurePursuit
from kiseki.io.runlog import RunWriter
from kiseki.sim.collisions import (
    COLLISION_SCHEMA,
    Collision,
    FootprintChecker,
    body_grid,
    check_route_clear,
    refuse_pedestrians,
)
from kiseki.sim.scene import Scene, check_route_in_bounds
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.teach.environment_map import MERGE_RULES, EnvironmentMap
from kiseki.teach.local_maps import BANDS, LocalMapMaker
from kiseki.teach.scene_identity import (
    TaughtScene,
    recorded_scene_file,
    scene_digest,
)

__all__ = ["TEACHING_FILES", "TeachingRun", "recover", "teach"]

# what a teaching run writes in its folder, the log first (`write_teaching_files` the rest: each
# band's map YAML and image, their truth, the waypoint file, removed when no waypoint is marked)
TEACHING_FILES = (
    "teach.mcap",
    *(name for band in BANDS for name in (f"map_{band}.yaml", f"map_{band}.pgm")),
    "map_truth.json",
    "waypoints.yaml",
)

MARK_SCHEMA = {
    "type": "object",
    "title": "kiseki.WaypointMark",
    "properties": {
        "id": {"type": "integer"},
        "name": {"type": "string"},
        "x": {"type": "number"},
        "y": {"type": "number"},
        "theta": {"type": "number"},
        "truth": {"type": "array"},
    },
}


class TeachingRun:
    """The state of one teaching run and its one step, shared by scripted and keyboard
    teaching: the robot, its depth cameras, the environment maps being merged, the waypoint
    marks and the MCAP log. Opening the run logs step 0 at the start pose; each :meth:`step`
    moves the robot by a velocity command for ``dt`` (unless the move would touch an obstacle:
    then it stays, see :meth:`step`), then logs the true pose, odometry and depth images and
    merges the local maps placed by odometry; :meth:`mark` records a waypoint at the current
    odometry pose. Use it as a context manager (the log is closed on exit, also on an exception,
    so that :func:`recover` can rebuild the run). `merge` is the environment maps' merge rule
    (`kiseki.teach.environment_map`). Before anything is written: unless `overwrite`, a folder
    holding any file the run writes (:data:`TEACHING_FILES`) is refused (FileExistsError); a
    scene with pedestrians is refused (teaching does not simulate them); with `route` ((n, 2)
    points and their `names`), a route point where the robot cannot stand is refused
    (:func:`~kiseki.sim.collisions.check_route_clear`)."""

    def __init__(
        self,
        scene: Scene,
        out: str | os.PathLike,
        seed: int = 0,
        dt: float = 0.1,
        overwrite: bool = False,
        metadata: dict[str, str] | None = None,
        merge: str = "thesis",
        route: tuple[list, list[str]] | None = None,
    ) -> None:
        check_number(dt, "dt", 0.0, low_open=True, unit="s")
        if merge not in MERGE_RULES:
            raise ValueError(f"merge rule must be one of {', '.join(MERGE_RULES)}, got {merge!r}")
        self.merge = merge
        self.scene, self.dt = scene, float(dt)
        self.out = Path(out)
        check_writable_folder(self.out, "teaching")
        if not overwrite:  # a user's map_plane.yaml beside no teach.mcap was replaced
            remedy = "give a new or empty folder, or overwrite=True"
            refuse_replacing(self.out, TEACHING_FILES, "out", remedy)
        self.setup = build_robot(scene, seed)
        if self.setup.kind != "diff_drive":
            raise ValueError(f"{scene.path}: teaching pushes a diff_drive robot")
        self.cameras = [
            s for s in build_sensors(scene, self.setup, seed, dt) if s.kind == "depth_camera"
        ]
        if not self.cameras:
            raise ValueError(f"{scene.path}: teaching needs the robot's depth cameras")
        refuse_pedestrians(scene, "teaching")
        body = body_grid(scene, self.setup.height)
        if route is not None:
            check_route_clear(scene, *route, self.setup.width, body)
        self._body = FootprintChecker(body, self.setup.length, self.setup.width)
        self.makers = {b: LocalMapMaker([c.device for c in self.cameras], b) for b in BANDS}
        self.maps = {b: EnvironmentMap(environment_grid(scene), merge) for b in BANDS}
        self.marks: list[dict] = []
        self.truths: list[tuple[float, float, float]] = []  # true pose of every logged step
        self.steps = 0  # steps logged
        self.out.mkdir(parents=True, exist_ok=True)
        self.log = self.out / "teach.mcap"
        # the scene by its path from the taught folder (this log's folder): found from anywhere
        self.scene_id = TaughtScene(
            recorded_scene_file(scene.path, self.out), scene_digest(scene.path), str(self.out)
        )
        meta = {
            "scene_file": self.scene_id.file,
            "scene_sha1": self.scene_id.sha1,
            "seed": str(seed),
            "dt": str(dt),
            "merge": merge,
        }
        self._writer = RunWriter(self.log, {**(metadata or {}), **meta}, overwrite=overwrite)
        try:
            self._record()
        except BaseException:
            self._close_after_error()
            raise

    @property
    def t(self) -> float:
        """Time of the last logged step (s)."""
        return (self.steps - 1) * self.dt

    @property
    def truth(self) -> tuple[float, float, float]:
        return _pose(self.setup.robot.pose)

    @property
    def odom(self) -> tuple[float, float, float]:
        return _pose(self.setup.odometry.pose)

    @property
    def limits(self) -> tuple[float, float]:
        """The robot's (max_speed m/s, max_yaw_rate rad/s)."""
        p = self.setup.robot.params
        return float(p.max_speed), float(p.max_yaw_rate)

    def step(self, v: float, w: float) -> Collision | None:
        """Moves the robot by (v m/s, w rad/s) for dt (within its limits) and logs the step.
        A move that would bring the robot's footprint onto an obstacle (the scene's truth at
        its height, :mod:`kiseki.sim.collisions`) is not made: the robot stays where it was,
        at rest, its wheels still (the odometry unchanged), the step is logged there, and the
        contact is returned (else None)."""
        robot = self.setup.robot
        before = robot.pose
        motion = robot.step(v, w, self.dt)
        contact = self._body.contact(_pose(robot.pose))
        if contact is None:
            self.setup.odometry.update(motion)
        else:
            robot.halt(before)
        self._record()
        if contact is None:
            return None
        c = Collision(self.t, self.setup.name, "obstacle", contact)
        self._writer.write_json(
            "/collision", c.t, "kiseki.Collision", c.payload(), COLLISION_SCHEMA
        )
        return c

    def _record(self) -> None:
        t, truth, odom = self.steps * self.dt, self.truth, self.odom
        images = [c.device.render(self.scene.world, truth) for c in self.cameras]
        try:
            self._writer.write_pose("/ground_truth", t, truth)
            self._writer.write_odometry("/odom", t, odom)
            for c, image in zip(self.cameras, images, strict=True):
                self._writer.write_depth_image(f"/{c.name}", t, image, c.name)
        except OSError as err:  # a full disk: what was logged before stays readable
            raise self._log_error(err) from err
        merge_local_maps(self.maps, self.makers, images, odom)
        self.truths.append(truth)
        self.steps += 1

    def mark(self, name: str) -> dict:
        """Records waypoint `name` at the current odometry pose (and logs the mark)."""
        odom = self.odom
        mark = {
            "id": len(self.marks),
            "name": str(name),
            "x": odom[0],
            "y": odom[1],
            "theta": odom[2],
            "truth": [float(v) for v in self.truth],
        }
        self.marks.append(mark)
        self._writer.write_json("/waypoints", self.t, "kiseki.WaypointMark", mark, MARK_SCHEMA)
        return mark

    def _log_error(self, err: OSError) -> OSError:
        """The error of writing the log, naming it and saying what is kept."""
        reason = err.strerror or str(err)
        return reworded(
            err,
            f"{self.log}: {reason[:1].lower()}{reason[1:]}; the steps logged before are kept "
            "(kiseki teach --resume rebuilds the maps from them once there is space)",
        )

    def _close_after_error(self) -> None:
        """Closes the log after an error without hiding it (on a full disk, closing fails
        too)."""
        with contextlib.suppress(OSError):
            self._writer.close()

    def close(self) -> None:
        try:
            self._writer.close()
        except OSError as err:
            raise self._log_error(err) from err

    def finish(self) -> TeachResult:
        """Closes the log and writes the maps, the waypoint file (when a waypoint was marked)
        and the maps measured against the scene's truth (map_truth.json)."""
        self.close()
        maps = {b: m.map() for b, m in self.maps.items()}
        truth = measure_taught_maps(self.scene, maps, np.array(self.truths), self.cameras)
        return write_teaching_files(
            self.out, maps, self.marks, self.log, self.steps, self.merge, truth, self.scene_id
        )

    def __enter__(self) -> TeachingRun:
        return self

    def __exit__(self, exc_type, *exc) -> None:
        if exc_type is None:
            self.close()
        else:
            self._close_after_error()


def teach(
    scene: Scene,
    out: str | os.PathLike,
    seed: int = 0,
    dt: float = 0.1,
    overwrite: bool = False,
    progress: bool = False,
    merge: str = "thesis",
    metadata: dict[str, str] | None = None,
) -> TeachResult:
    """Pushes the robot along the scene's route (pure pursuit stands in for the operator),
    marks each named route point as a waypoint, and builds one environment map per local-map
    band ("plane" and "band") with the merge rule `merge`. `metadata`: more entries for the
    log's metadata (text keys and values; the run's own entries win)."""
    route = scene.route
    if not route.get("waypoints"):
        raise ValueError(f"{scene.path}: scripted teaching needs a route (or use the keyboard)")
    names = route.get("names") or [f"W{i}" for i in range(len(route["waypoints"]))]
    check_route_in_bounds(scene, route["waypoints"], names)
    meta = {**(metadata or {}), "names": ",".join(names)}
    points = (route["waypoints"], names)
    with TeachingRun(scene, out, seed, dt, overwrite, meta, merge, points) as run:
        controller = PurePursuit(
            route["waypoints"],
            route["speed"],
            0.6,
            0.1,
            run.setup.robot.params.max_accel,
        )
        with tqdm(desc="teaching", unit="step", disable=not progress, mininterval=0.1) as bar:
            while True:
                # the operator stops pushing at the goal and marks it once the cart is at rest
                resting = controller.done and not any(run.setup.robot.velocity)
                _mark(run, names, controller, resting)
                bar.update(1)  # this step is written
                if resting or run.steps >= int(900 / dt):
                    break
                v, _, w = controller.command(run.truth)
                contact = run.step(v, w)
                if contact is not None:
                    raise ValueError(_blocked(scene, names, run, contact))
        return run.finish()


def _pose(p) -> tuple[float, float, float]:
    return (float(p.x), float(p.y), float(p.theta))


def _blocked(scene: Scene, names, run: TeachingRun, contact: Collision) -> str:
    """Why scripted teaching stopped: the robot, following the route, touched an obstacle."""
    after = f"after waypoint {run.marks[-1]['name']}" if run.marks else f"before {names[0]}"
    x, y = contact.contact
    return (
        f"{scene.path}: pushed along the route, the robot touches an obstacle at ({x:.2f}, "
        f"{y:.2f}) m at t = {contact.t:.1f} s, {after}: move the route's waypoints so that its "
        "path stays clear of it (the robot cuts corners, steering to a point 0.6 m ahead); "
        f"{run.log} holds the run up to there (to teach into {run.out} again: --overwrite, "
        "or overwrite=True)"
    )


def _mark(run: TeachingRun, names, controller: PurePursuit, resting: bool) -> None:
    """The operator marks the next route point when the robot reaches it along the route (the
    goal once the robot has come to rest there)."""
    i = len(run.marks)
    if i >= len(names):
        return
    last = i == len(names) - 1
    if (last and not resting) or (not last and controller.progress < controller.cum[i] - 0.05):
        return
    run.mark(names[i])
