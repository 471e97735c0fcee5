# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A scene's turns (cooperative positioning): one robot drives to its place while the others
stand. Used by kiseki.sim.run."""

from __future__ import annotations

from kiseki.control import PurePursuit
from kiseki.sim.scene import Scene

__all__ = ["TURN_SCHEMA", "Turns"]


TURN_SCHEMA = {
    "type": "object",
    "title": "kiseki.Turn",
    "properties": {
        "move": {"type": "integer", "description": "1-based index of the scene's turns"},
        "robot": {"type": "string"},
        "to": {"type": "array", "description": "planned place (x, y), m"},
        "event": {"type": "string", "description": "start or arrived"},
    },
}


class Turns:
    """The scene's turns: one robot drives to its place while the others stand; /turns logs
    when each move starts and when its robot has arrived (the standing robots' bearings of that
    moment are the move's measurement)."""

    def __init__(self, scene: Scene, agents, config) -> None:
        self.moves = scene.turns["moves"]
        self.speed = scene.turns["speed"]
        self.by_name = {a.setup.name: a for a in agents}
        self.config, self.index, self.controller = config, -1, None

    @property
    def done(self) -> bool:
        return self.index >= len(self.moves)

    def _at_rest(self) -> bool:
        name = self.moves[self.index][0]
        return all(abs(v) < 1e-6 for v in self.by_name[name].setup.robot.velocity)

    def advance(self, writer, t: float) -> None:
        """Starts the next move when the current robot has arrived and come to rest (a robot
        that still rolls is not standing)."""
        while not self.done and (
            self.controller is None or (self.controller.done and self._at_rest())
        ):
            if self.controller is not None:
                self._log(writer, t, "arrived")
            self.index += 1
            self.controller = None
            if self.done:
                return
            name, to = self.moves[self.index]
            setup = self.by_name[name].setup
            x, y = setup.robot.pose.x, setup.robot.pose.y
            self.controller = PurePursuit(
                [[x, y], list(to)],
                self.speed,
                self.config.lookahead,
                self.config.goal_tolerance,
                setup.robot.params.max_accel,
            )
            self._log(writer, t, "start")

    def command(self, agent) -> tuple[float, float, float]:
        if self.done or agent.setup.name != self.moves[self.index][0]:
            return 0.0, 0.0, 0.0  # standing
        p = agent.setup.robot.pose
        return self.controller.command((p.x, p.y, p.theta))

    def _log(self, writer, t: float, event: str) -> None:
        name, to = self.moves[self.index]
        payload = {"move": self.index + 1, "robot": name, "to": list(to), "event": event}
        writer.write_json("/turns", t, "kiseki.Turn", payload, TURN_SCHEMA)
