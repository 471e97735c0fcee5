# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The simulation loop: a fixed time step moves the robot by pure pursuit along the scene's
route, by a script of velocity commands, or by a caller's controller (see :func:`simulate`),
records ground truth, odometry, every sensor, the commanded and the actual body velocity
(``/cmd_vel``, ``/velocity``: ``kiseki.Twist``) and the scene's pedestrians, and writes the run to
MCAP as it goes. After every step each robot's footprint is checked against the obstacles, the
other robots and the pedestrians (kiseki.sim.collisions): a collision ends the run and is
logged on ``/collision``."""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from tqdm import tqdm

from kiseki._support.field_types import check_field_types
from kiseki._support.real_numbers import check_number
from kiseki.control import PurePursuit
from kiseki.core import check_seed
from kiseki.io.runlog import TWIST_SCHEMA, TWIST_SCHEMA_NAME, RunWriter, read_run
from kiseki.sim.collisions import COLLISION_SCHEMA, Collision, CollisionCheck
from kiseki.sim.command_schema import MAX_COMMAND_SECONDS, check_command_array, read_command_rows
from kiseki.sim.pedestrians import PEDESTRIANS_SCHEMA
from kiseki.sim.recorder import Recorder, planar_pose
from kiseki.sim.scene import Scene, check_route_in_bounds
from kiseki.sim.setup import RobotSetup, SensorSetup, build_robot, build_sensors
from kiseki.sim.turns import Turns

__all__ = ["RunSummary", "SimConfig", "read_commands", "simulate"]


MAX_SIM_SECONDS = MAX_COMMAND_SECONDS  # a run is at most a day of simulated time


@dataclass(frozen=True)
class SimConfig:
    dt: float = 0.1  # s, the thesis' 10 Hz control loop
    duration: float | None = None  # s; None: until the route's goal is reached
    max_duration: float = 900.0  # s, a safety stop for controllers
    seed: int = 0
    lookahead: float = 0.6  # m, pure pursuit
    goal_tolerance: float = 0.1  # m, the thesis' stop rule
    # a collision ends the run; False: the first one is logged and the run goes on (scenes of
    # point robots, such as cooperative positioning's turns)
    stop_on_collision: bool = True

    def __post_init__(self) -> None:
        check_field_types(self)
        check_number(self.dt, "dt", 0.0, low_open=True, unit="s")
        for name in ("duration", "max_duration"):  # at most a day of simulated time
            value = getattr(self, name)
            if value is not None:
                check_number(value, name, 0.0, MAX_SIM_SECONDS, low_open=True, unit="s")
        for name in ("lookahead", "goal_tolerance"):  # inf was taken, then refused by the
            # route follower once the robot was built
            check_number(getattr(self, name), name, 0.0, low_open=True, unit="m")
        check_seed(self.seed)


@dataclass(frozen=True)
class RunSummary:
    path: Path
    steps: int
    sim_seconds: float
    wall_seconds: float
    reached_goal: bool
    final_pose: tuple[float, float, float]
    final_odometry: tuple[float, float, float]
    messages: dict[str, int]
    collision: Collision | None = None  # the contact that ended the run


def read_commands(path: str | os.PathLike) -> np.ndarray:
    """A velocity-command script: CSV with header t,v,w (diff drive) or t,vx,vy,w (omni); each
    row holds from its time until the next row (see :mod:`kiseki.sim.command_schema`). Returns
    (n, 4) rows of t, vx, vy, w (vy 0 for a diff-drive script)."""
    data = read_command_rows(path)
    if data.shape[1] == 3:
        data = np.column_stack([data[:, :2], np.zeros(len(data)), data[:, 2]])
    return data


def _step(setup: RobotSetup, command, dt: float) -> None:
    vx, vy, w = command
    if setup.kind == "diff_drive":
        setup.odometry.update(setup.robot.step(vx, w, dt))
    else:
        setup.odometry.update(setup.robot.step(vx, vy, w, dt))


_pose = planar_pose


@dataclass
class _Agent:
    setup: RobotSetup
    sensors: list[SensorSetup]
    controller: PurePursuit | None


def _agents(scene: Scene, config: SimConfig, commands, controller) -> list[_Agent]:
    if controller is not None and (
        commands is not None or scene.turns is not None or len(scene.robot_specs) > 1
    ):
        raise ValueError(
            f"{scene.path}: a controller drives one robot alone: no command script, no turns, "
            "no second robot"
        )
    if controller is not None and not callable(getattr(controller, "command", None)):
        raise ValueError("controller must have a command(t, pose, scans) method")
    agents = []
    for index, spec in enumerate(scene.robot_specs):
        setup = build_robot(scene, config.seed, index)
        sensors = build_sensors(scene, setup, config.seed, config.dt, index)
        route, pursuit = spec["route"], None
        if commands is None and controller is None and "waypoints" in route:
            pursuit = PurePursuit(
                route["waypoints"],
                route["speed"],
                config.lookahead,
                config.goal_tolerance,
                setup.robot.params.max_accel,
            )
        agents.append(_Agent(setup, sensors, pursuit))
    if scene.turns is not None and commands is not None:
        raise ValueError(f"{scene.path}: the scene's robots take turns: no command script")
    if (
        commands is None
        and controller is None
        and scene.turns is None
        and not any(a.controller for a in agents)
    ):
        raise ValueError(f"{scene.path}: no route: give velocity commands instead")
    if commands is not None and len(agents) > 1:
        raise ValueError(f"{scene.path}: command scripts drive one robot; this scene has several")
    if commands is not None and agents[0].setup.kind == "diff_drive" and commands[:, 2].any():
        # a differential robot cannot move sideways: the vy column was dropped without a word
        row = int(np.argmax(commands[:, 2] != 0))
        raise ValueError(
            f"{scene.path}: the robot is a differential drive, but the command script's row "
            f"{row + 1} asks for vy = {commands[row, 2]:g} m/s (give t,v,w)"
        )
    for agent, spec in zip(agents, scene.robot_specs, strict=True):
        if agent.controller is not None:  # the robot would leave the world to reach it
            check_route_in_bounds(scene, spec["route"]["waypoints"])
    return agents


def simulate(
    scene: Scene,
    out: str | os.PathLike,
    config: SimConfig | None = None,
    commands: np.ndarray | None = None,
    overwrite: bool = False,
    progress: bool = True,
    controller=None,
) -> RunSummary:
    """Runs a scene and writes the run to an MCAP file; returns a summary. With one robot the
    topics are /ground_truth, /odom, /tf, /cmd_vel, /velocity and /<sensor>; with several,
    /<robot>/... . /cmd_vel and /velocity at time t hold the command given at t and the body
    velocity the robot then moves with until t + dt.

    ``controller`` (one robot, no commands, no turns): an object with ``command(t, pose,
    scans) -> (vx, vy, w)``, pose the robot's true (x, y, theta), scans {laser name: (sensor
    pose (3,), beam angles (n,), ranges (n,), max range)} (the latest scan of each laser); the
    scene's route is then not followed. A controller with an ``observe(t, odometry,
    readings)`` method is first given, each step, the odometry's (x, y, theta) and
    {magnetometer name: (time of its latest reading, (3,) reading G in the sensor frame)}: a
    navigator that must not see the true pose takes its inputs from there. A ``done``
    attribute that turns True ends the run, and RunSummary.reached_goal is its final value.

    A collision (a footprint touching an obstacle, another robot or a pedestrian) ends the run
    at the end of the step that made it: /collision, RunSummary.collision, reached_goal False.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a kiseki Scene (load_scene), got {type(scene).__name__}")
    if config is not None and not isinstance(config, SimConfig):
        raise TypeError(f"config must be a SimConfig or None, got {type(config).__name__}")
    if not isinstance(out, str | os.PathLike):
        raise TypeError(f"out must be a path (the MCAP file), got {type(out).__name__}")
    config = config or SimConfig()
    commands = check_command_array(commands)
    agents = _agents(scene, config, commands, controller)
    routed = [a for a in agents if a.controller is not None]
    turns = Turns(scene, agents, config) if scene.turns is not None else None
    limit = config.duration or (
        float(commands[-1, 0]) + config.dt if commands is not None else config.max_duration
    )
    steps = int(math.ceil(limit / config.dt - 1e-9))
    meta = {
        "scene": scene.name,
        "scene_file": str(scene.path),
        "scene_sha1": scene.sha1,
        "seed": str(config.seed),
        "dt": str(config.dt),
        "robots": ",".join(a.setup.name for a in agents),
    }
    walkers = scene.pedestrians
    collisions = CollisionCheck(scene, [a.setup for a in agents], walkers)
    start, t, k, collision = time.perf_counter(), 0.0, 0, None
    single = len(agents) == 1
    with RunWriter(out, meta, overwrite=overwrite) as writer:
        laser_grid = next((g for a in agents for g in _laser_grids(scene, a.sensors)), None)
        writer.write_grid("/map", 0.0, laser_grid or scene.ground_truth(0.35, 0.45))
        recorders = [
            Recorder(writer, scene, a.setup, a.sensors, "" if single else f"/{a.setup.name}")
            for a in agents
        ]
        total = steps if not (routed or turns or controller) else None  # a goal ends a route
        bar = tqdm(total=total, desc=scene.name, unit="step", disable=not progress, leave=False)
        with bar:
            for k in range(steps + 1):
                t = k * config.dt
                positions = {a.setup.name: _pose(a.setup.robot.pose) for a in agents}
                discs = _pedestrians(writer, walkers, t)
                for recorder in recorders:
                    recorder.record(t, positions, discs)
                if turns is not None:
                    turns.advance(writer, t)
                if (
                    k == steps
                    or (collision is not None and config.stop_on_collision)
                    or (routed and all(a.controller.done for a in routed))
                    or (turns is not None and turns.done)
                    or (controller is not None and getattr(controller, "done", False))
                ):
                    break
                for a, recorder in zip(agents, recorders, strict=True):
                    if controller is not None:
                        pose = _pose(a.setup.robot.pose)
                        observe = getattr(controller, "observe", None)
                        if observe is not None:
                            observe(t, _pose(a.setup.odometry.pose), dict(recorder.readings))
                        command = tuple(controller.command(t, pose, dict(recorder.latest)))
                    elif turns is not None:
                        command = turns.command(a)
                    else:
                        command = _command(a, commands, t)
                    _step(a.setup, command, config.dt)
                    _velocities(writer, recorder.prefix, t, command, a.setup)
                if collision is None:
                    collision = collisions.check(t + config.dt)
                    if collision is not None:
                        writer.write_json(
                            "/collision",
                            collision.t,
                            "kiseki.Collision",
                            collision.payload(),
                            COLLISION_SCHEMA,
                        )
                bar.update(1)
    counts = {topic: n for topic, (_, n) in _topic_counts(out).items()}
    first = agents[0].setup
    reached = (
        (bool(routed) and all(a.controller.done for a in routed))
        or (turns is not None and turns.done)
        or (controller is not None and bool(getattr(controller, "done", False)))
    )
    return RunSummary(
        Path(out),
        k,
        t,
        time.perf_counter() - start,
        reached and (collision is None or not config.stop_on_collision),
        _pose(first.robot.pose),
        _pose(first.odometry.pose),
        counts,
        collision,
    )


def _pedestrians(writer: RunWriter, walkers, t: float) -> list[tuple[float, float, float]]:
    """Logs the pedestrians at t; returns their discs (x, y, radius) for the lasers."""
    if not walkers:
        return []
    at = [p.position(t) for p in walkers]
    payload = {"names": [p.name for p in walkers], "positions": [list(xy) for xy in at]}
    writer.write_json("/pedestrians", t, "kiseki.Pedestrians", payload, PEDESTRIANS_SCHEMA)
    return [(x, y, p.radius) for (x, y), p in zip(at, walkers, strict=True)]


def _velocities(writer: RunWriter, prefix: str, t: float, command, setup: RobotSetup) -> None:
    """/cmd_vel and /velocity (kiseki.Twist, body frame) of the step starting at t."""
    velocity = setup.robot.velocity
    if setup.kind == "diff_drive":  # (v, w)
        velocity = (velocity[0], 0.0, velocity[1])
    for topic, (vx, vy, w) in (("cmd_vel", command), ("velocity", velocity)):
        payload = {"vx": float(vx), "vy": float(vy), "w": float(w)}
        writer.write_json(f"{prefix}/{topic}", t, TWIST_SCHEMA_NAME, payload, TWIST_SCHEMA)


def _command(agent: _Agent, commands, t: float) -> tuple[float, float, float]:
    if agent.controller is not None:
        return agent.controller.command(_pose(agent.setup.robot.pose))
    if commands is None:
        return 0.0, 0.0, 0.0  # a robot without a route stands still
    row = commands[max(0, int(np.searchsorted(commands[:, 0], t, "right")) - 1)]
    return row[1], row[2], row[3]


def _laser_grids(scene: Scene, sensors: list[SensorSetup]):
    for s in sensors:
        if s.kind == "laser":
            yield scene.ground_truth(s.mount.z - 0.02, s.mount.z + 0.02)


def _topic_counts(path) -> dict:
    return read_run(path).topics()
