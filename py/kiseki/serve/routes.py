# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The thesis' use phase (sec. 2.3) as a background worker: a route start -> via... -> goal
(stop within the goal tolerance), a dwell while the part is taken, then goal -> via reversed ->
home. One route at a time; every control period's state goes to the subscribers of a
:class:`Broadcaster` (the websocket pages) as one JSON text, the same for all of them.

Every message and state carries ``epoch`` (this runner's random id) and ``seq`` (the number of
messages published before it, and it): a page draws a state only when it is newer than the one
it shows, so a late reply or a message overtaken by another never puts an older pose back. A
route's first message (published before the robot has started it) carries no pose: the robot
may be placed elsewhere by the start, so the previous route's pose is not this route's."""

from __future__ import annotations

import asyncio
import itertools
import json
import math
import numbers
import secrets
import threading
import time
from dataclasses import dataclass, field

import numpy as np

from kiseki._support.real_numbers import check_number
from kiseki.apps.teach.playback import check_route
from kiseki.serve.history import RouteHistory
from kiseki.serve.robot import Robot, RobotState
from kiseki.serve.taught import TaughtRun

__all__ = ["Broadcaster", "RouteBusyError", "RouteRefusedError", "RouteRequest", "RouteRunner"]


class RouteRefusedError(ValueError):
    """The route names an unknown waypoint or has a leg through occupied space (HTTP 422)."""


class RouteBusyError(RuntimeError):
    """Another route is running (HTTP 409)."""


@dataclass(frozen=True)
class RouteRequest:
    start: str
    goal: str
    via: list[str] = field(default_factory=list)
    home: str | None = None  # the worker's cell; the start when not given


class Broadcaster:
    """Hands each published text to every subscriber's asyncio queue (thread-safe: publish
    from any thread). A subscriber that falls more than `backlog` messages behind loses its
    oldest ones."""

    def __init__(self, backlog: int = 600) -> None:
        self.backlog = backlog
        self._subscribers: dict[int, tuple[asyncio.AbstractEventLoop, asyncio.Queue]] = {}
        self._ids = itertools.count()
        self._lock = threading.Lock()

    def subscribe(self) -> tuple[int, asyncio.Queue]:
        """A new queue on the running event loop, and its key for :meth:`unsubscribe`."""
        queue: asyncio.Queue = asyncio.Queue(self.backlog)
        with self._lock:
            key = next(self._ids)
            self._subscribers[key] = (asyncio.get_running_loop(), queue)
        return key, queue

    def unsubscribe(self, key: int) -> None:
        with self._lock:
            self._subscribers.pop(key, None)

    @property
    def count(self) -> int:
        with self._lock:
            return len(self._subscribers)

    def publish(self, text: str) -> None:
        with self._lock:
            subscribers = list(self._subscribers.items())
        for key, (loop, queue) in subscribers:
            try:
                loop.call_soon_threadsafe(_put, queue, text)
            except RuntimeError:  # the subscriber's loop is closed
                self.unsubscribe(key)


def _put(queue: asyncio.Queue, text: str) -> None:
    if queue.full():
        queue.get_nowait()
    queue.put_nowait(text)


def _pose(values) -> list[float] | None:
    return None if values is None else [round(float(v), 4) for v in values]


HISTORY_SHOWN = 50  # the last finished routes in the state and its messages (the file: all)


class RouteRunner:
    """Runs routes of `taught`'s waypoints with `robot` in a background thread, paced at
    `speed_up` times real time (math.inf: as fast as the robot steps), with a dwell of
    `dwell` seconds (of robot time) at the goal. Finished routes go to `history` (kept in
    memory when None); route ids go on from its last."""

    def __init__(
        self,
        robot: Robot,
        taught: TaughtRun,
        dwell: float = 5.0,
        speed_up: float = 1.0,
        history: RouteHistory | None = None,
    ) -> None:
        check_number(dwell, "dwell", 0.0, unit="s")  # inf was an OverflowError at the goal
        real = isinstance(speed_up, numbers.Real) and not isinstance(speed_up, bool | np.bool_)
        if not (real and speed_up > 0):  # not check_number's: math.inf is a speed-up
            raise ValueError(f"speed_up must be > 0 (inf: as fast as it steps), got {speed_up!r}")
        self.robot, self.taught, self.dwell, self.speed_up = robot, taught, dwell, speed_up
        self.history = history if history is not None else RouteHistory()
        self.broadcaster = Broadcaster()
        self.epoch = secrets.token_hex(4)  # tells this runner's numbering from a restarted one's
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._ids = itertools.count(self.history.next_id)
        self._seq = 0
        self._state: dict = {
            "status": "idle",
            "route": None,
            "leg": None,
            "pose": None,
            "estimate": None,
            "speed": 0.0,
            "command": [0.0, 0.0],
            "t": 0.0,
            "stop_error_m": None,
            "dwell_left_s": None,
            "detail": None,
            "history": self.history.routes[-HISTORY_SHOWN:],
        }
        self._particles: list = []

    # --- requests (called from the HTTP handlers; never wait on the robot) ---

    def plan(self, request: RouteRequest) -> dict:
        """The route's waypoints out and back; RouteRefusedError naming what is wrong."""
        home = request.start if request.home is None else request.home
        names = [request.start, *request.via, request.goal]
        unknown = [n for n in dict.fromkeys([*names, home]) if self.taught.by_name(n) is None]
        if unknown:
            known = ", ".join(w["name"] for w in self.taught.waypoints)
            raise RouteRefusedError(f"no waypoint named {', '.join(unknown)} (known: {known})")
        if len(set(names)) != len(names):
            raise RouteRefusedError(f"a waypoint appears twice in {' -> '.join(names)}")
        back = [request.goal, *reversed(request.via), home]
        if home in request.via or home == request.goal:
            back = [request.goal, home] if home != request.goal else []
        out_marks = [self.taught.by_name(n) for n in names]
        back_marks = [self.taught.by_name(n) for n in back]
        try:
            for marks in (out_marks, back_marks):
                check_route(
                    self.taught.environment, marks, self.taught.travelled, self.robot.footprint
                )
        except ValueError as err:
            raise RouteRefusedError(str(err)) from None
        return {"out": out_marks, "back": back_marks}

    def submit(self, request: RouteRequest) -> dict:
        """Starts the route in the background and returns it; RouteBusyError while one runs."""
        with self._lock:
            if self._state["status"] == "running":
                raise RouteBusyError(
                    f"route {self._state['route']['id']} is running; wait for it to finish or "
                    "stop it (POST /api/stop)"
                )
            legs = self.plan(request)
            route = {
                "id": next(self._ids),
                "start": request.start,
                "via": list(request.via),
                "goal": request.goal,
                "home": legs["back"][-1]["name"] if legs["back"] else request.goal,
                "outbound": [w["name"] for w in legs["out"]],
                "return": [w["name"] for w in legs["back"]],
            }
            if self._thread is not None:  # past its last use of the lock: ends at once
                self._thread.join()
            self._stop.clear()
            self._state.update(
                status="running", route=route, leg=None, stop_error_m=None, detail=None, t=0.0,
                pose=None, estimate=None, speed=0.0, command=[0.0, 0.0], dwell_left_s=None,
            )  # fmt: skip
            self._particles = []  # nothing of the previous route's robot is this route's
            self._publish()  # the pages hear of the route before the robot has started it
            self._thread = threading.Thread(
                target=self._run, args=(route, legs), name=f"route-{route['id']}", daemon=True
            )
            self._thread.start()
            return route

    def stop(self) -> dict:
        """Asks the running route to halt (the robot brakes within one control period)."""
        with self._lock:
            running = self._state["status"] == "running"
            if running:
                self._stop.set()
                self._state["detail"] = "stopping"
            # t and speed: the route's clock and the robot's speed when the stop was taken
            state = self._state
            route = state["route"]["id"] if state["route"] else None
            return {"stopping": running, "status": state["status"], "route": route,
                    "t": state["t"], "speed": state["speed"], "epoch": self.epoch,
                    "seq": self._seq}  # fmt: skip

    def state(self) -> dict:
        """The state (a deep copy) with the sequence number of the last message sent, so a page
        can tell a reply that is older than the websocket's latest message and drop it."""
        with self._lock:
            return {**json.loads(json.dumps(self._state)), "epoch": self.epoch, "seq": self._seq}

    def message(self) -> str:
        """The latest state with the particles, as sent on the websocket."""
        with self._lock:
            return self._message()

    def close(self, timeout: float = 5.0) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout)

    # --- the worker thread ---

    def _run(self, route: dict, legs: dict) -> None:
        status, detail = "finished", None
        try:
            arrived = self._drive("outbound", legs["out"])
            if arrived:
                self._at_goal(legs["out"][-1])
            back = legs["back"]
            if not (arrived and self._dwell() and (not back or self._drive("return", back))):
                status = "stopped"
        except Exception as err:  # the robot failed: the page must hear of it
            status, detail = "stopped", f"the route failed: {err}"
        with self._lock:
            if status == "stopped" and detail is None:
                detail = "stopped" if self._stop.is_set() else "the goal was not reached in time"
            try:
                self.history.append(
                    {
                        **{k: route[k] for k in ("id", "start", "via", "goal", "home")},
                        "status": status,
                        "stop_error_m": self._state["stop_error_m"],
                        "duration_s": self._state["t"],
                    }
                )
            except (OSError, ValueError) as err:  # the pages hear that the file is behind
                detail = f"{detail or status}; the route history was not written: {err}"
            self._state.update(
                status=status,
                detail=detail,
                dwell_left_s=None,
                history=self.history.routes[-HISTORY_SHOWN:],
            )
            self._publish()

    def _drive(self, phase: str, marks: list[dict]) -> bool:
        """Drives one phase; False if it was stopped (or the robot gave up) before the end."""
        self.robot.start(marks)
        clock = _Clock(self.robot.dt / self.speed_up)
        stopped = False
        while True:
            if self._stop.is_set() and not stopped:
                self.robot.stop()
                stopped = True
            state = self.robot.step()
            self._update(phase, marks, state)
            if state.done:
                if state.fault is not None:  # a simulated collision
                    raise RuntimeError(state.fault)
                return state.reached and not stopped
            clock.wait()

    def _at_goal(self, goal: dict) -> None:
        """The stop error: the true distance from where the robot rests to where the goal was
        taught (simulation only: a real robot has no ground truth)."""
        state = self.robot.state()
        if state is None or state.pose is None or "truth" not in goal:
            return
        error = math.hypot(state.pose[0] - goal["truth"][0], state.pose[1] - goal["truth"][1])
        with self._lock:
            self._state["stop_error_m"] = round(error, 4)

    def _dwell(self) -> bool:
        """The part is taken: the robot waits `dwell` seconds at the goal (False if stopped)."""
        periods = math.ceil(self.dwell / self.robot.dt - 1e-9)
        clock = _Clock(self.robot.dt / self.speed_up)
        for k in range(periods):
            if self._stop.is_set():
                return False
            with self._lock:
                self._state["leg"] = {"phase": "dwell", "index": None, "from": None, "to": None}
                self._state["dwell_left_s"] = round((periods - k) * self.robot.dt, 3)
                self._state["speed"] = 0.0
                self._state["t"] = round(self._state["t"] + self.robot.dt, 3)
                self._publish()
            clock.wait()
        with self._lock:
            self._state["dwell_left_s"] = None
        return not self._stop.is_set()

    def _update(self, phase: str, marks: list[dict], state: RobotState) -> None:
        with self._lock:
            self._state.update(
                leg={
                    "phase": phase,
                    "index": state.leg,
                    "from": marks[state.leg]["name"],
                    "to": marks[state.leg + 1]["name"],
                },
                pose=_pose(state.pose),
                estimate=_pose(state.estimate),
                speed=round(float(state.speed), 4),
                command=[round(float(c), 4) for c in state.command],
            )
            self._state["t"] = round(self._state["t"] + self.robot.dt, 3)
            self._particles = [[round(float(v), 3) for v in p] for p in state.particles]
            self._publish()

    def _message(self) -> str:
        return json.dumps(
            {
                "type": "state",
                "epoch": self.epoch,
                "seq": self._seq,
                **self._state,
                "particles": self._particles,
            }
        )

    def _publish(self) -> None:
        """Sends the state to every page (called with the lock held)."""
        self._seq += 1
        self.broadcaster.publish(self._message())


class _Clock:
    """Paces a loop at one tick per `period` seconds of wall time; a loop that falls behind by
    more than half a second starts a new schedule instead of hurrying."""

    def __init__(self, period: float) -> None:
        self.period, self.next = period, time.monotonic() + period

    def wait(self) -> None:
        if not math.isfinite(self.next):
            return
        delay = self.next - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        elif delay < -0.5:
            self.next = time.monotonic()
        self.next += self.period
