# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki serve``: the thesis' use phase (sec. 2.3) through a web page. A worker picks start,
via and goal waypoints on the taught map; the AGV drives there, stops within 0.1 m, dwells
while the part is taken, and returns to the worker's cell, watched live. An application layer
beside the CLI: it uses teach, sim and map_io; nothing imports it."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

from kiseki.apps.teach.playback import PlaybackConfig
from kiseki.serve.app import STATIC, create_app
from kiseki.serve.guard import loopback_hosts
from kiseki.serve.history import RouteHistory
from kiseki.serve.listen import listening_sockets
from kiseki.serve.robot import Robot, RobotState, SimulatedAgv
from kiseki.serve.routes import RouteRequest, RouteRunner
from kiseki.serve.taught import TaughtRun, taught_scene
from kiseki.sim.scene import check_scene_file, load_scene
from kiseki.teach.scene_identity import resolve_scene_file, scene_digest, taught_scene_of

__all__ = [
    "HISTORY_FILE",
    "LOOPBACK",
    "STATIC",
    "Robot",
    "RobotState",
    "RouteHistory",
    "RouteRequest",
    "RouteRunner",
    "Server",
    "SimulatedAgv",
    "TaughtRun",
    "build_server",
    "create_app",
    "listening_sockets",
    "scene_of",
]

LOOPBACK = ("127.0.0.1", "localhost", "::1")
HISTORY_FILE = "route_history.json"  # kiseki serve's --history, in the taught folder


class Server:
    """The pieces of a served taught run: the FastAPI app, its runner and the taught run."""

    def __init__(self, app, runner: RouteRunner, taught: TaughtRun, scene: Path) -> None:
        self.app, self.runner, self.taught, self.scene = app, runner, taught, scene


def scene_of(folder: str | os.PathLike, scene: str | os.PathLike | None) -> Path:
    """The scene to play the taught run in: `scene`, which must be the one the run records (the
    same SHA-1; for a run recorded without one, the same file or text), or the recorded one when
    `scene` is None, found from any working directory (relative to the taught folder, or for an
    older run to the working directory it was taught in: ``resolve_scene_file``)."""
    folder = Path(folder)
    identity = _taught_identity(folder)
    recorded = identity.file if identity is not None and identity.file else taught_scene(folder)
    found = resolve_scene_file(recorded, folder)
    if scene is None:
        if not recorded:
            raise ValueError(f"{folder}: the taught run records no scene; give --scene SCENE")
        if found is None:
            raise FileNotFoundError(
                f"{recorded}: the scene {folder} was taught in is not found (neither from "
                f"{folder} nor from the working directory); give --scene SCENE"
            )
        if identity is not None and scene_digest(found) != identity.sha1:
            raise ValueError(
                f"{found}: the scene {folder} was taught in has changed since (its SHA-1 "
                "differs from the one recorded); give --scene with the scene it was taught in"
            )
        return found
    scene = Path(scene)
    check_scene_file(scene)
    if not recorded:
        return scene
    if identity is not None:  # the scene's SHA-1, as teaching recorded it
        same = scene_digest(scene) == identity.sha1
    elif found is not None:
        same = scene.samefile(found) or scene.read_bytes() == found.read_bytes()
    else:  # an old run whose scene file is gone: only its name can be compared
        same = scene.name == Path(recorded).name
    if not same:
        raise ValueError(
            f"{scene}: the run in {folder} was taught in {found or recorded}, not this scene"
        )
    return scene


def _taught_identity(folder: Path):
    """The taught scene (file, SHA-1) as the run's waypoint file (or its log) records it, or
    None."""
    waypoints = folder / "waypoints.yaml"
    return taught_scene_of(waypoints) if waypoints.is_file() else None


def build_server(
    folder: str | os.PathLike,
    scene: str | os.PathLike | None = None,
    method: str = "both",
    token: str | None = None,
    dwell: float = 5.0,
    speed_up: float = 1.0,
    particles: int = 1000,
    seed: int = 0,
    static: Path = STATIC,
    host: str = "127.0.0.1",
    port: int = 8000,
    history: str | os.PathLike | None = None,
) -> Server:
    """Loads the taught run in `folder` and its scene and returns the app driving the
    simulated AGV there (playback's configuration with `method`, `particles` and `seed`), to
    be served at `host`:`port` (on loopback it answers only to that address's names); the
    finished routes are read from and written to the JSON file `history` (None: in memory)."""
    taught = TaughtRun(folder, method)
    scene_file = scene_of(folder, scene)
    finished = RouteHistory(history)  # a file that is not a route history stops here
    if not all("truth" in w for w in taught.waypoints):
        raise ValueError(f"{taught.path}: waypoints without their taught truth (not simulated)")
    config = replace(PlaybackConfig(), method=method, particles=particles, seed=seed)
    robot = SimulatedAgv(
        load_scene(scene_file, "playback"), taught.environment, config, travelled=taught.travelled
    )
    runner = RouteRunner(robot, taught, dwell, speed_up, finished)
    app = create_app(taught, runner, token, static, loopback_hosts(host, port))
    return Server(app, runner, taught, scene_file)
