# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Playback (thesis sec. 3.5): the robot follows the taught waypoints on the particle filter's
estimate and stops when the estimate is within 0.1 m of the goal; it then decelerates at its
acceleration limit (the filter still running) and its stop pose is where it comes to rest. The
filter (kiseki's Monte Carlo engine, :mod:`kiseki.localization`) predicts from odometry and
weighs particles with the space observation model on the chosen method's local map.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np

from kiseki import _core
from kiseki.control import PurePursuit
from kiseki.core import derive_seed
from kiseki.grid import OccupancyGrid
from kiseki.localization import MclConfig, MonteCarloLocalizer
from kiseki.sim.scene import Scene
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.teach.local_maps import METHODS, LocalMapMaker

__all__ = ["PlaybackConfig", "PlaybackResult", "check_route", "playback"]


def check_route(environment: OccupancyGrid, waypoints: list[dict]) -> None:
    """Raises ValueError when a straight leg between consecutive waypoints crosses occupied
    cells of the taught map (the robot follows the legs, so such a route is unreachable)."""
    for a, b in zip(waypoints, waypoints[1:], strict=False):
        length = math.hypot(b["x"] - a["x"], b["y"] - a["y"])
        if length == 0:
            continue
        heading = math.atan2(b["y"] - a["y"], b["x"] - a["x"])
        rng, hit, cell = environment.cast_ray(a["x"], a["y"], heading, max_range=length)
        if hit and rng < length - environment.resolution:
            x, y = environment.cell_to_world(np.array([cell], dtype=float))[0]
            raise ValueError(
                f"the route leg {a['name']} -> {b['name']} crosses occupied space "
                f"at ({x:.2f}, {y:.2f}) m of the taught map"
            )


@dataclass(frozen=True)
class PlaybackConfig:
    method: str = "proposal2"
    particles: int = 1000
    seed: int = 0
    dt: float = 0.1  # s, 10 Hz as in the thesis
    speed: float = 0.5  # m/s
    goal_tolerance: float = 0.1  # m, the thesis' stop rule
    initial_sd: tuple[float, float, float] = (0.05, 0.05, math.radians(1.0))
    # Odometry motion model noise (Probabilistic Robotics Table 5.6), the same for every method,
    # set so that its 1-sigma spread covers the simulated AGV's odometry error (sim.robot's
    # OdometryErrorParams) at 10 Hz and 0.5 m/s (0.05 m, up to about 0.05 rad per step):
    #   alpha1 (rot -> rot): track width +0.5 % over a 90 deg turn of about 30 steps needs
    #     0.005^2 * 30 = 7.5e-4, turning slip 5e-5 rad/rad adds 5e-5 / 0.05 = 1e-3 -> 0.002;
    #   alpha2 (trans -> rot, rad^2/m^2): the 0.1 % wheel-radius difference over the 0.5 m track
    #     turns 0.002 rad/m, over a 10 m leg of 200 steps (0.002 * 10)^2 / 200 / 0.05^2 = 8e-4;
    #     wheel slip 4e-6 m/m per wheel adds 2 * 4e-6 / 0.5^2 / 0.05 = 6.4e-4 -> 0.002;
    #   alpha3 (trans -> trans): mean wheel radius -0.1 % over 200 steps 0.001^2 * 200 = 2e-4,
    #     slip 2e-6 / 0.05 = 4e-5 -> 5e-4;
    #   alpha4 (rot -> trans, m^2/rad^2): no modelled source; a floor of 5e-4.
    # (Each sum rounded up to 1, 2 or 5 times a power of ten.)
    alphas: tuple[float, float, float, float] = (0.002, 0.002, 0.0005, 0.0005)
    max_duration: float = 300.0

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise ValueError(f"method must be one of {', '.join(METHODS)}, got {self.method!r}")
        if self.particles < 1 or not self.dt > 0 or not self.goal_tolerance > 0:
            raise ValueError("particles >= 1, dt > 0 and goal_tolerance > 0 are needed")


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


def _pose(p) -> tuple[float, float, float]:
    return (float(p.x), float(p.y), float(p.theta))


def playback(
    scene: Scene,
    environment: OccupancyGrid,
    waypoints: list[dict],
    config: PlaybackConfig | None = None,
) -> PlaybackResult:
    """Runs the route through `waypoints` (taught marks, map frame) in the scene."""
    config = config or PlaybackConfig()
    if len(waypoints) < 2:
        raise ValueError("a route needs a start and a goal waypoint")
    check_route(environment, waypoints)
    band, occlusion = METHODS[config.method]
    if "truth" in waypoints[0]:  # in simulation the robot starts where the start was taught
        x, y, th = waypoints[0]["truth"]
        scene = copy.copy(scene)
        scene.robot_specs = [dict(scene.robot_specs[0])]
        scene.robot_specs[0]["robot"] = {
            **scene.robot_specs[0]["robot"],
            "start": [x, y, math.degrees(th)],
        }
    setup = build_robot(scene, derive_seed(config.seed, 1))
    cameras = [
        s.device
        for s in build_sensors(scene, setup, config.seed, config.dt)
        if s.kind == "depth_camera"
    ]
    maker = LocalMapMaker(cameras, band)
    model = _core.SpaceObservationModel(environment, occlusion_aware=occlusion)
    localizer = MonteCarloLocalizer(
        MclConfig(particles=config.particles, alphas=tuple(config.alphas)),
        derive_seed(config.seed, 2),
    )
    start = waypoints[0]
    localizer.initialize((start["x"], start["y"], start["theta"]), config.initial_sd)
    points = [[w["x"], w["y"]] for w in waypoints]
    controller = PurePursuit(
        points, config.speed, 0.6, config.goal_tolerance, setup.robot.params.max_accel
    )
    passes: dict = {}
    truth_log, est_log = [], []

    def observe():
        images = [c.render(scene.world, truth) for c in cameras]
        model.set_local_map(maker.make(images))
        return model

    for _ in range(int(config.max_duration / config.dt)):
        truth = _pose(setup.robot.pose)
        localizer.step(_pose(setup.odometry.pose), observe)
        estimate = tuple(float(v) for v in localizer.estimate)
        truth_log.append(truth)
        est_log.append(estimate)
        _record_passes(passes, waypoints, controller, truth, estimate, _pose(setup.odometry.pose))
        if controller.done and not any(setup.robot.velocity):
            break  # the stop pose is where the robot comes to rest, not where it was told to stop
        v, _, w = controller.command(estimate)
        setup.odometry.update(setup.robot.step(v, w, config.dt))
    return PlaybackResult(
        controller.done,
        len(truth_log),
        truth_log[-1],
        est_log[-1],
        _pose(setup.odometry.pose),
        passes,
        np.array(truth_log),
        np.array(est_log),
    )


def _record_passes(passes, waypoints, controller, truth, estimate, odom) -> None:
    """Poses when the estimate passes each via-point and at the goal (the latest wins)."""
    for i, w in enumerate(waypoints[1:], start=1):
        if w["name"] in passes and i < len(waypoints) - 1:
            continue
        if controller.progress >= controller.cum[i] - 0.05 or (
            i == len(waypoints) - 1 and controller.done
        ):
            passes[w["name"]] = {"true": truth, "estimate": estimate, "odometry": odom}
