# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The robot the server drives, behind an interface: :class:`Robot` starts a route of taught
waypoints, steps (or polls) one control period and stops; :class:`SimulatedAgv` implements it
with playback (:class:`kiseki.apps.teach.playback.PlaybackRun`) in the scene the route was taught
in. A real robot's adapter would implement the same four members, with ``pose`` None (no
ground truth) and ``step`` waiting for the robot's next state."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from kiseki.apps.teach.playback import PlaybackConfig, PlaybackRun
from kiseki.grid import OccupancyGrid
from kiseki.sim.scene import Scene
from kiseki.sim.setup import build_robot

__all__ = ["Robot", "RobotState", "SimulatedAgv"]


@dataclass(frozen=True)
class RobotState:
    """One control period's state of the robot on its route."""

    estimate: tuple[float, float, float]  # the filter's pose in the taught map (m, m, rad)
    speed: float  # m/s, the robot's forward speed now
    command: tuple[float, float]  # (v m/s, w rad/s) commanded in this period
    particles: np.ndarray  # (n, 3) a subsample of the filter's particles
    leg: int  # the route's leg the robot is on: waypoints[leg] -> waypoints[leg + 1]
    t: float  # s since the route started
    done: bool  # the robot rests at the end of the route, or after a stop
    reached: bool  # the estimate came within the goal tolerance of the goal, touching nothing
    pose: tuple[float, float, float] | None = None  # the true pose (simulation only)
    fault: str | None = None  # why the robot ended the route itself (a simulated collision)


@runtime_checkable
class Robot(Protocol):
    """What the server needs of a robot."""

    dt: float  # s, the control period
    footprint: tuple[float, float]  # m, (length, width): the route check's robot body

    def start(self, waypoints: list[dict]) -> None:
        """Begins following the route through `waypoints` (taught marks, map frame)."""

    def step(self) -> RobotState:
        """Advances (or waits) one control period and returns the state."""

    def stop(self) -> None:
        """Brings the robot to rest at its acceleration limit (the route ends)."""

    def state(self) -> RobotState | None:
        """The last state, None before the first route."""


class SimulatedAgv:
    """The simulated AGV playing routes back in `scene` (its playback variant) on the taught
    map `environment`. A route that starts at the waypoint where the previous route ended (the
    robot at rest there) continues with the same robot and filter; any other start places the
    robot where that start was taught, with a new filter around it (as if pushed there). A
    route longer than ``config.max_duration`` is stopped."""

    def __init__(
        self,
        scene: Scene,
        environment: OccupancyGrid,
        config: PlaybackConfig | None = None,
        particles_shown: int = 200,
        travelled: np.ndarray | None = None,
    ) -> None:
        self.scene, self.environment, self.travelled = scene, environment, travelled
        self.footprint = build_robot(scene, 0).footprint  # for the route check
        self.config = config or PlaybackConfig()
        self.dt = self.config.dt
        self.particles_shown = particles_shown
        self.run: PlaybackRun | None = None
        self.resting_at: int | None = None  # id of the waypoint the robot rests at
        self._state: RobotState | None = None

    def start(self, waypoints: list[dict]) -> None:
        if self.run is not None and not self.run.done:
            raise RuntimeError("the robot is still on a route")
        if self.run is not None and self.resting_at == waypoints[0].get("id"):
            self.run.follow(waypoints)
        else:
            self.run = PlaybackRun(
                self.scene, self.environment, waypoints, self.config, travelled=self.travelled
            )
        self.resting_at = None
        self._state = self._snapshot()

    def step(self) -> RobotState:
        run = self._route()
        if run.steps * self.dt >= self.config.max_duration:
            run.stop()
        if not run.step() and run.reached and not run.stopping:
            self.resting_at = run.waypoints[-1].get("id")
        self._state = self._snapshot()
        return self._state

    def stop(self) -> None:
        self._route().stop()

    def state(self) -> RobotState | None:
        return self._state

    def _route(self) -> PlaybackRun:
        if self.run is None:
            raise RuntimeError("no route was started")
        return self.run

    def _snapshot(self) -> RobotState:
        run = self._route()
        controller = run.controller
        leg = int(np.searchsorted(controller.cum, controller.progress, side="right")) - 1
        return RobotState(
            estimate=run.estimate,
            speed=abs(run.velocity[0]),
            command=run.command,
            particles=run.particles(self.particles_shown),
            leg=min(max(leg, 0), len(run.waypoints) - 2),
            t=max(run.steps - 1, 0) * self.dt,
            done=run.done,
            reached=run.reached,
            pose=run.truth,
            fault=None if run.collision is None else run.collision.line(),
        )
