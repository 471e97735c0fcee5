# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Playback (thesis sec. 3.5): the robot follows the taught waypoints on the particle filter's
estimate and stops when the estimate is within 0.1 m of the goal; it then decelerates at its
acceleration limit (the filter still running) and its stop pose is where it comes to rest. The
filter (kiseki's Monte Carlo engine, :mod:`kiseki.filters`) predicts from odometry and
weighs particles with the space observation model on the chosen method's local map. In
simulation the run ends where the robot touches an obstacle (:mod:`kiseki.sim.collisions`),
as a simulated run does; a scene with pedestrians is refused (playback does not simulate
them).

A speed limiter (any :class:`~kiseki.control.SpeedLimitSource`; playback never imports the
limiter's area) caps the follower's speed at every control step: the scene's first laser scans
the world at the true pose, and the limiter gets that scan with the laser pose the robot knows,
the one of its estimate in the taught map. With ``log`` the run is written to MCAP as it goes
(:mod:`kiseki.teach.playback_log`).
"""

from __future__ import annotations

import contextlib
import copy
import math
import os
from dataclasses import dataclass, field

import numpy as np

from kiseki import _core
from kiseki.apps.teach.playback_config import PLAYBACK_MODELS, PlaybackConfig
from kiseki.control import PurePursuit, SpeedLimit, SpeedLimitSource
from kiseki.core import derive_seed
from kiseki.filters import MclConfig, MonteCarloLocalizer
from kiseki.grid import OccupancyGrid
from kiseki.sim.collisions import (
    COLLISION_SCHEMA,
    Collision,
    CollisionCheck,
    refuse_pedestrians,
)
from kiseki.sim.scene import Scene
from kiseki.sim.setup import SensorSetup, build_robot, build_sensors
from kiseki.teach.local_maps import METHODS, LocalMapMaker, local_map_scan
from kiseki.teach.playback_log import PlaybackLog
from kiseki.teach.route_check import check_route
from kiseki.teach.scene_identity import TaughtScene, check_scene

__all__ = [
    "PLAYBACK_MODELS",
    "PlaybackConfig",
    "PlaybackResult",
    "PlaybackRun",
    "check_route",
    "playback",
]


@dataclass
class PlaybackResult:
    reached: bool
    steps: int
    stop_true: tuple[float, float, float]
    stop_estimate: tuple[float, float, float]
    stop_odometry: tuple[float, float, float]
    passes: dict = field(default_factory=dict)  # waypoint -> true / estimate / odometry poses
    truth: np.ndarray | None = None
    estimates: np.ndarray | None = None
    times: np.ndarray | None = None  # s, of each step (truth[k] and estimates[k] at times[k])
    speed_limits: np.ndarray | None = None  # m/s the limiter allowed at each step, if any
    scene_identity: dict = field(default_factory=dict)  # scene_sha1, taught_scene_sha1, variant
    collision: Collision | None = None  # the contact that ended the run, if one did

    @property
    def duration(self) -> float:
        """Seconds from the start to the last step (the stop at rest)."""
        return float(self.times[-1]) if self.times is not None and len(self.times) else 0.0


def _pose(p) -> tuple[float, float, float]:
    return (float(p.x), float(p.y), float(p.theta))


def playback(
    scene: Scene,
    environment: OccupancyGrid,
    waypoints: list[dict],
    config: PlaybackConfig | None = None,
    speed_limiter: SpeedLimitSource | None = None,
    log: str | os.PathLike | None = None,
    taught_scene: TaughtScene | None = None,
    variant: str | None = None,
    travelled: np.ndarray | None = None,
) -> PlaybackResult:
    """Runs the route through `waypoints` (taught marks, map frame) in the scene; the follower's
    speed is capped by `speed_limiter` when given (the scene needs a laser), and the run is
    written to the MCAP file `log` (which must not exist) when given. A loop over
    :class:`PlaybackRun`'s steps, for at most ``config.max_duration``.

    `taught_scene` (a :class:`TeachResult`'s ``scene``) is the scene the route was taught in: a
    scene file whose bytes differ is refused (ValueError) unless `variant` labels the change;
    the scene's and the taught scene's SHA-1s and the label go into the log's metadata and the
    result's ``scene_identity``. `travelled` (the teaching run's odometry poses,
    :func:`kiseki.teach.route_check.travelled_poses`) lets the route cross occupied cells of
    the map that the robot's body covered while it was taught."""
    config = config or PlaybackConfig()
    identity = check_scene(taught_scene, scene.path, variant)
    run = PlaybackRun(scene, environment, waypoints, config, speed_limiter, travelled=travelled)
    meta = {
        **identity,
        "scene_file": str(scene.path),
        "route": ",".join(str(w["name"]) for w in waypoints),
        "method": config.method,
        "seed": str(config.seed),
        "dt": str(config.dt),
        "speed_limiter": type(speed_limiter).__name__ if speed_limiter is not None else "none",
    }
    with PlaybackLog(log, meta) if log is not None else contextlib.nullcontext() as writer:
        run.writer = writer
        for _ in range(int(config.max_duration / config.dt)):
            if not run.step():
                break
    result = run.result()
    result.scene_identity = identity
    return result


class PlaybackRun:
    """One playback in steps of one control period, for a driver that cannot wait for the whole
    route (a server streaming the run, a stop button). Created with :func:`playback`'s
    arguments: the simulated robot is placed where the start was taught (its ``truth``) and the
    filter starts around the start's taught pose. :meth:`step` runs one period; :meth:`stop`
    brings the robot to rest at its acceleration limit; :meth:`follow` starts the next route
    from where the robot rests with the same robot, sensors and filter (a route that starts
    where the previous one ended). ``writer`` (a :class:`PlaybackLog`) logs the steps when set.
    """

    def __init__(
        self,
        scene: Scene,
        environment: OccupancyGrid,
        waypoints: list[dict],
        config: PlaybackConfig | None = None,
        speed_limiter: SpeedLimitSource | None = None,
        writer: PlaybackLog | None = None,
        travelled: np.ndarray | None = None,
    ) -> None:
        self.config = config = config or PlaybackConfig()
        self.travelled = travelled
        _need_start_and_goal(waypoints)
        band, occlusion = METHODS[config.method]
        if "truth" in waypoints[0]:  # in simulation the robot starts where the start was taught
            x, y, th = waypoints[0]["truth"]
            scene = copy.copy(scene)
            scene.robot_specs = [dict(scene.robot_specs[0])]
            scene.robot_specs[0]["robot"] = {
                **scene.robot_specs[0]["robot"],
                "start": [x, y, math.degrees(th)],
            }
        self.scene, self.environment, self.writer = scene, environment, writer
        self.setup = build_robot(scene, derive_seed(config.seed, 1))
        check_route(environment, waypoints, travelled, self.setup.footprint)
        refuse_pedestrians(scene, "playback")
        # the robot against the scene's truth: a contact ends the run
        self._collisions = CollisionCheck(scene, [self.setup])
        self.collision: Collision | None = None
        sensors = build_sensors(scene, self.setup, config.seed, config.dt)
        self.cameras = [s.device for s in sensors if s.kind == "depth_camera"]
        self.limiter = None
        if speed_limiter is not None:
            self.limiter = _ScanLimiter(scene, sensors, speed_limiter, config.dt)
        self.maker = LocalMapMaker(self.cameras, band)
        if config.model == "ray-space-observation":
            self.model = _core.RaySpaceObservationModel(environment)
            self._angles = np.linspace(-np.pi, np.pi, config.scan_beams, endpoint=False)
        else:
            self.model = _core.SpaceObservationModel(environment, occlusion_aware=occlusion)
        self.localizer = MonteCarloLocalizer(
            MclConfig(particles=config.particles, alphas=tuple(config.alphas)),
            derive_seed(config.seed, 2),
        )
        start = waypoints[0]
        self.localizer.initialize((start["x"], start["y"], start["theta"]), config.initial_sd)
        self._begin(waypoints)

    def _begin(self, waypoints: list[dict]) -> None:
        self.waypoints = list(waypoints)
        self.controller = PurePursuit(
            [[w["x"], w["y"]] for w in waypoints],
            self.config.speed,
            0.6,
            self.config.goal_tolerance,
            self.setup.robot.params.max_accel,
        )
        self.passes: dict = {}
        self._truths: list[tuple[float, float, float]] = []
        self._estimates: list[tuple[float, float, float]] = []
        self.command: tuple[float, float] = (0.0, 0.0)  # (v m/s, w rad/s) of the last step
        self.stopping = False  # stop() was called
        self.done = False  # the robot rests at the end of the route, or after stop()

    def follow(self, waypoints: list[dict]) -> None:
        """Starts the next route with the same robot and filter, from where the robot rests
        (the filter is not reset: the start waypoint should be where the robot is)."""
        if not self.done:
            raise ValueError("the robot is still on its route: stop it or let it finish first")
        if self.collision is not None:
            raise ValueError(f"the last route ended in a collision ({self.collision.line()})")
        _need_start_and_goal(waypoints)
        check_route(self.environment, waypoints, self.travelled, self.setup.footprint)
        self._begin(waypoints)

    @property
    def steps(self) -> int:
        """Steps recorded on this route."""
        return len(self._truths)

    @property
    def truth(self) -> tuple[float, float, float]:
        """The true pose of the last recorded step (simulation)."""
        return self._truths[-1] if self._truths else _pose(self.setup.robot.pose)

    @property
    def estimate(self) -> tuple[float, float, float]:
        """The filter's estimate of the last recorded step."""
        return tuple(float(v) for v in self.localizer.estimate)

    @property
    def velocity(self) -> tuple[float, float]:
        """The robot's (v m/s, w rad/s) now (after its acceleration limit)."""
        v, w = self.setup.robot.velocity
        return float(v), float(w)

    @property
    def reached(self) -> bool:
        """The estimate came within the goal tolerance of the goal (the follower's stop rule)
        and the robot touched nothing on the way."""
        return bool(self.controller.done) and self.collision is None

    def particles(self, count: int | None = None) -> np.ndarray:
        """The filter's particles (n, 3), or `count` of them, evenly spaced in its array."""
        poses = np.asarray(self.localizer.engine.poses, dtype=float)
        if count is None or count >= len(poses):
            return poses
        return poses[np.linspace(0, len(poses) - 1, max(count, 1)).astype(int)]

    def stop(self) -> None:
        """Commands zero speed from the next step on: the robot brakes at its acceleration
        limit (the filter still running) and the run is done once it rests."""
        self.stopping = True

    def step(self) -> bool:
        """One control period: the filter's update at the current pose (recorded), then the
        follower's command for dt, unless the route is over (reached or stopped) and the robot
        at rest. Returns False when the robot rests at the end (that step recorded, no command),
        and from then on. A move that brings the robot into contact (its footprint on the
        scene's obstacles, :class:`~kiseki.sim.collisions.CollisionCheck`) ends the run as a
        simulated run ends: the next step records the pose of the contact and returns False;
        ``collision`` holds the contact (its time counted, as ``steps``, from the start of the
        current route)."""
        if self.done:
            return False
        config, setup, writer = self.config, self.setup, self.writer
        t = len(self._truths) * config.dt
        truth = _pose(setup.robot.pose)
        self._observed = truth
        self.localizer.step(_pose(setup.odometry.pose), self._observe)
        estimate = self.estimate
        self._truths.append(truth)
        self._estimates.append(estimate)
        odometry = _pose(setup.odometry.pose)
        _record_passes(self.passes, self.waypoints, self.controller, truth, estimate, odometry)
        cap = None  # m/s, the limiter's cap of the follower's speed
        if self.limiter is not None:
            cap = self.limiter.update(t, truth, estimate, writer)
        if writer is not None:
            writer.step(t, truth, estimate, odometry)
        resting = (self.controller.done or self.stopping) and not any(setup.robot.velocity)
        if resting or self.collision is not None:
            self.done, self.command = True, (0.0, 0.0)
            return False  # the stop pose is where the robot comes to rest, not where it was told
        if self.stopping:
            v, w = 0.0, 0.0
        else:
            v, _, w = self.controller.command(estimate, max_speed=cap)
        self.command = (float(v), float(w))
        if writer is not None:
            writer.command(t, v, w)
        setup.odometry.update(setup.robot.step(v, w, config.dt))
        self.collision = self._collisions.check(t + config.dt)
        if self.collision is not None and writer is not None:
            c = self.collision
            writer.record("/collision", c.t, "kiseki.Collision", c.payload(), COLLISION_SCHEMA)
        return True

    def _observe(self):
        images = [c.render(self.scene.world, self._observed) for c in self.cameras]
        local = self.maker.make(images)
        if self.config.model == "ray-space-observation":
            reach, scale = 0.5 * self.maker.size, self.config.scan_range_scale
            ranges = local_map_scan(local, self._angles, reach, scale)
            self.model.set_scan(self._angles, ranges, reach * max(1.0, scale))
        else:
            self.model.set_local_map(local)
        return self.model

    def result(self) -> PlaybackResult:
        """The route so far as a :class:`PlaybackResult`."""
        return PlaybackResult(
            self.reached,
            len(self._truths),
            self._truths[-1],
            self._estimates[-1],
            _pose(self.setup.odometry.pose),
            self.passes,
            np.array(self._truths),
            np.array(self._estimates),
            np.arange(len(self._truths)) * self.config.dt,
            None if self.limiter is None else np.array(self.limiter.limits),
            collision=self.collision,
        )


def _need_start_and_goal(waypoints: list[dict]) -> None:
    if len(waypoints) < 2:
        raise ValueError("a route needs a start and a goal waypoint")


class _ScanLimiter:
    """Feeds a speed limiter: the scene's first laser scans the world at the true pose (the
    sensor sees the world); the limiter gets the laser pose of the estimate (the robot knows
    only its estimate, in the taught map's frame) and, as the direction of motion of this
    differential drive, the estimate's heading."""

    def __init__(
        self, scene: Scene, sensors: list[SensorSetup], source: SpeedLimitSource, dt: float
    ) -> None:
        if not isinstance(source, SpeedLimitSource):
            raise TypeError(f"a speed limiter needs an update() method, got {type(source)}")
        laser = next((s for s in sensors if s.kind == "laser"), None)
        if laser is None:
            raise ValueError(f"scene {scene.name} ({scene.path}) has no laser for a speed limiter")
        self.laser, self.source, self.dt = laser, source, dt
        self.angles, self.max_range = laser.device.params.angles, laser.device.params.max_range
        self.grid = scene.ground_truth(laser.mount.z - 0.02, laser.mount.z + 0.02)
        self.limits: list[float] = []  # m/s, one per update

    def update(self, t: float, truth, estimate, writer: PlaybackLog | None) -> float:
        """The step's speed cap (m/s); logs the scan and the limit when `writer` is given."""
        true_sensor, ranges = self.laser.device.scan(self.grid, truth)
        sensor = self.laser.mount.planar(estimate)
        limit = self.source.update(
            sensor, self.angles, ranges, self.max_range, self.dt, heading=float(estimate[2])
        )
        if not isinstance(limit, SpeedLimit):
            raise TypeError(f"the speed limiter returned {type(limit)}, not a SpeedLimit")
        self.limits.append(limit.metres_per_second)
        if writer is not None:
            writer.scan(t, true_sensor, self.angles, ranges, self.max_range)
            writer.speed_limit(t, limit)
        return limit.metres_per_second


def _record_passes(passes, waypoints, controller, truth, estimate, odom) -> None:
    """Poses when the estimate passes each via-point and at the goal (the latest wins)."""
    for i, w in enumerate(waypoints[1:], start=1):
        if w["name"] in passes and i < len(waypoints) - 1:
            continue
        if controller.progress >= controller.cum[i] - 0.05 or (
            i == len(waypoints) - 1 and controller.done
        ):
            passes[w["name"]] = {"true": truth, "estimate": estimate, "odometry": odom}
