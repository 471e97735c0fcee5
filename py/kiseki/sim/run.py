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

from kiseki.control import PurePursuit
from kiseki.core import check_seed
from kiseki.sim.collisions import COLLISION_SCHEMA, Collision, CollisionCheck
from kiseki.sim.mcap_log import TWIST_SCHEMA, TWIST_SCHEMA_NAME, RunWriter, read_run
from kiseki.sim.pedestrians import PEDESTRIANS_SCHEMA, DiscStamp
from kiseki.sim.scene import Scene
from kiseki.sim.setup import RobotSetup, SensorSetup, build_robot, build_sensors
from kiseki.sim.turns import Turns

__all__ = ["RunSummary", "SimConfig", "read_commands", "simulate"]

MAG_SCHEMA = {
    "type": "object",
    "title": "kiseki.MagneticField",
    "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}},
}
TILT_SCHEMA = {
    "type": "object",
    "title": "kiseki.TiltScan",
    "properties": {
        "tilt_deg": {"type": "array"},
        "scan_deg": {"type": "array"},
        "ranges": {"type": "array", "description": "row-major (tilt, scan); 0 = no return"},
        "gyro_rpy": {"type": "array"},
        "sensor_pose": {"type": "array"},
    },
}


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
        if not (self.dt > 0 and math.isfinite(self.dt)):
            raise ValueError(f"dt must be positive, got {self.dt}")
        if self.duration is not None and not (self.duration > 0 and math.isfinite(self.duration)):
            raise ValueError(f"duration must be positive, got {self.duration}")
        if not (self.lookahead > 0 and self.goal_tolerance > 0):
            raise ValueError("lookahead and goal_tolerance must be positive")
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
    row holds from its time until the next row."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: command file not found")
    header = path.read_text(encoding="utf-8").splitlines()[0].strip().split(",")
    if header not in (["t", "v", "w"], ["t", "vx", "vy", "w"]):
        raise ValueError(f"{path}: header must be t,v,w or t,vx,vy,w, got {','.join(header)}")
    try:
        data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    except ValueError as err:
        raise ValueError(f"{path}: not a numeric CSV ({err})") from err
    if data.shape[1] != len(header) or not np.isfinite(data).all():
        raise ValueError(f"{path}: every row needs {len(header)} finite numbers (no NaN)")
    if (np.diff(data[:, 0]) < 0).any() or data[0, 0] < 0:
        raise ValueError(f"{path}: times must start at >= 0 and not decrease")
    if len(header) == 3:
        data = np.column_stack([data[:, :2], np.zeros(len(data)), data[:, 2]])
    return data


def _step(setup: RobotSetup, command, dt: float) -> None:
    vx, vy, w = command
    if setup.kind == "diff_drive":
        setup.odometry.update(setup.robot.step(vx, w, dt))
    else:
        setup.odometry.update(setup.robot.step(vx, vy, w, dt))


def _pose(p) -> tuple[float, float, float]:
    return (float(p.x), float(p.y), float(p.theta)) if hasattr(p, "x") else tuple(map(float, p))


BEARING_SCHEMA = {
    "type": "object",
    "title": "kiseki.Bearings",
    "properties": {
        "targets": {"type": "array", "items": {"type": "string"}},
        "bearings": {
            "type": "array",
            "description": "rad, counter-clockwise in the sensor frame; null: not seen",
        },
        "elevations": {"type": "array", "description": "rad above the horizontal; null: not seen"},
    },
}


class _Recorder:
    """Writes one time step of a robot's ground truth, odometry and every due sensor."""

    def __init__(
        self,
        writer: RunWriter,
        scene: Scene,
        robot: RobotSetup,
        sensors: list[SensorSetup],
        prefix: str,
    ) -> None:
        self.writer, self.scene, self.robot, self.sensors = writer, scene, robot, sensors
        self.prefix = prefix
        self.next_due = {s.name: 0.0 for s in sensors}
        self.latest: dict[str, tuple] = {}  # laser name -> (sensor pose, angles, ranges, max)
        self.grids = {}
        for s in sensors:
            if s.kind == "laser":
                z = s.mount.z
                self.grids[s.name] = scene.ground_truth(z - 0.02, z + 0.02)

    def record(self, t: float, positions: dict[str, tuple[float, float, float]], discs) -> None:
        """Writes step t; `discs`: the pedestrians (x, y, radius) the lasers see."""
        w, p = self.writer, self.prefix
        pose, odom = _pose(self.robot.robot.pose), _pose(self.robot.odometry.pose)
        w.write_pose(f"{p}/ground_truth", t, pose)
        w.write_transform(
            t, "world", f"{p.strip('/')}/base_link" if p else "base_link", pose, topic=f"{p}/tf"
        )
        w.write_odometry(f"{p}/odom", t, odom)
        for s in self.sensors:
            if t + 1e-9 < self.next_due[s.name]:
                continue
            self.next_due[s.name] = t + s.period
            self._sensor(s, t, pose, positions, discs)

    def _sensor(self, s: SensorSetup, t: float, pose, positions, discs) -> None:
        w, topic = self.writer, f"{self.prefix}/{s.name}"
        if s.kind == "laser":
            if discs:
                with DiscStamp(self.grids[s.name], discs) as grid:
                    sensor_pose, ranges = s.device.scan(grid, pose)
            else:
                sensor_pose, ranges = s.device.scan(self.grids[s.name], pose)
            self.latest[s.name] = (
                sensor_pose,
                s.device.params.angles,
                ranges,
                s.device.params.max_range,
            )
            w.write_laser_scan(
                topic,
                t,
                sensor_pose,
                s.device.params.angles,
                ranges,
                max_range=s.device.params.max_range,
            )
        elif s.kind == "depth_camera":
            w.write_depth_image(topic, t, s.device.render(self.scene.world, pose), s.name)
        elif s.kind == "magnetometer":
            m = s.device.read(pose, t)
            w.write_json(
                topic,
                t,
                "kiseki.MagneticField",
                {"x": float(m[0]), "y": float(m[1]), "z": float(m[2])},
                MAG_SCHEMA,
            )
        elif s.kind == "bearing":
            # the markers sit at the sensor's height on every robot (the scenes are planar)
            planar = s.mount.planar(pose)
            sensor = (planar[0], planar[1], s.mount.z, planar[2])
            targets = np.array([[*positions[n][:2], s.mount.z] for n in s.targets])
            others = np.array([v[:2] for v in positions.values()])
            seen = s.device.observe(sensor, targets, self.scene.world, others)
            w.write_json(
                topic,
                t,
                "kiseki.Bearings",
                {
                    "targets": list(s.targets),
                    "bearings": [
                        float(b) if ok else None
                        for b, ok in zip(seen.bearings, seen.visible, strict=True)
                    ],
                    "elevations": [
                        float(e) if ok else None
                        for e, ok in zip(seen.elevations, seen.visible, strict=True)
                    ],
                },
                BEARING_SCHEMA,
            )
        elif s.kind == "tilting_laser":
            sensor = s.mount.world(pose)
            ranges, gyro = s.device.scan(self.scene.world, sensor)
            tilt, scan = s.device.params.grid()
            w.write_json(
                topic,
                t,
                "kiseki.TiltScan",
                {
                    "tilt_deg": np.degrees(tilt).tolist(),
                    "scan_deg": np.degrees(scan).tolist(),
                    "ranges": np.nan_to_num(ranges, nan=0.0).ravel().tolist(),
                    "gyro_rpy": gyro.tolist(),
                    "sensor_pose": sensor.ravel().tolist(),
                },
                TILT_SCHEMA,
            )


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
                float(route.get("speed", 0.5)),
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
    scene's route is then not followed. A ``done`` attribute that turns True ends the run, and
    RunSummary.reached_goal is its final value.

    A collision (a footprint touching an obstacle, another robot or a pedestrian) ends the run
    at the end of the step that made it: /collision, RunSummary.collision, reached_goal False.
    """
    config = config or SimConfig()
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
            _Recorder(writer, scene, a.setup, a.sensors, "" if single else f"/{a.setup.name}")
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
