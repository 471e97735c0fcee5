# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki playback``: play a taught route back (the factory AGV's main job, with
``kiseki teach``)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import typer
from rich.console import Console

from kiseki._support.guard import Derived, guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import Seed
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix
from kiseki.apps.teach import PlaybackConfig, playback
from kiseki.apps.teach.playback_picture import render_playback
from kiseki.apps.teach.taught_route import load_route
from kiseki.cli._defaults import default_of
from kiseki.grid import OccupancyGrid
from kiseki.io.ros_map import load_map
from kiseki.sim.scene import check_scene_file, load_scene
from kiseki.speed import SpeedLimiter, SpeedLimiterConfig
from kiseki.teach.local_maps import METHODS
from kiseki.teach.route_check import read_travelled
from kiseki.teach.scene_identity import check_scene, taught_scene_of

__all__ = ["app"]

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)
# the waypoint file of the taught folder, which no option names (kiseki._support.guard)
_TAUGHT_WAYPOINTS = Derived(
    "--taught's waypoint file", lambda a: a["taught"] / "waypoints.yaml" if a["taught"] else None
)


@app.command("playback")
@guarded(
    inputs=("scene_file", "taught", _TAUGHT_WAYPOINTS, "waypoints", "map_file"),
    outputs=("log", "plot"),
)
@interruptible()
def playback_command(
    scene_file: Path = typer.Argument(..., metavar="SCENE", help="Scene YAML (playback variant)."),
    route: str = typer.Option(..., help="Waypoint names, start, via, goal: P0,P1,P2."),
    taught: Path | None = typer.Option(None, help="Folder written by kiseki teach."),
    map_file: Path | None = typer.Option(
        None, "--map", help="Taught map YAML (instead of --taught; with --waypoints)."
    ),
    waypoints: Path | None = typer.Option(
        None, help="Waypoint YAML written by kiseki teach (instead of --taught)."
    ),
    method: str = typer.Option(
        default_of(PlaybackConfig, "method"), help="conventional, proposal1, proposal2 or both."
    ),
    seed: int = typer.Option(
        default_of(PlaybackConfig, "seed"), parser=Seed(), help="Seed of the run's noise."
    ),
    speed_limit: str = typer.Option(
        "none",
        help="Speed limiter on the scene's laser: occlusion (occluded regions), "
        "occlusion-width (and the movable width) or none.",
    ),
    log: Path | None = typer.Option(
        None,
        help="MCAP file to write the run to (poses, /cmd_vel; with a limiter /scan and "
        "/speed_limit as nav2_msgs/SpeedLimit fields).",
    ),
    plot: Path | None = typer.Option(
        None,
        help="Picture to draw (PNG): the taught map, the route, the estimate, the true path, "
        "the stop and a contact.",
    ),
    variant: str | None = typer.Option(
        None,
        help="Label of a deliberately changed copy of the taught scene (its SHA-1 differs from "
        "the one the teaching recorded): played back instead of refused, the label and both "
        "SHA-1s printed and in --log's metadata.",
    ),
) -> None:
    """Play a taught route back on the particle filter's estimate; stop within 0.1 m of the goal.
    Give the teaching folder (--taught) or its waypoint file (--waypoints, and --map for a map
    other than the one named there).

    Example: kiseki playback data/worlds/factory_corridor.yaml --taught taught --route P0,P1,P2"""

    if (taught is None) == (waypoints is None):
        raise ValueError("give either --taught FOLDER or --waypoints FILE (with --map MAP.yaml)")
    if taught is not None and map_file is not None:
        raise ValueError("--map goes with --waypoints, not with --taught")
    check_suffix("--plot", plot, FIGURE_SUFFIXES)
    if speed_limit not in SPEED_LIMITS:
        raise ValueError(f"--speed-limit must be {', '.join(SPEED_LIMITS)}, got {speed_limit!r}")
    config = PlaybackConfig(method=method, seed=seed)
    band, _ = METHODS[method]
    names = [n.strip() for n in route.split(",")]
    if not all(names):  # ',,' read as waypoints named '' ('no waypoint named , ,')
        raise ValueError(f"--route {route!r}: a waypoint name is empty: give names as P0,P1,P2")
    if taught is not None:
        if not taught.is_dir():  # its waypoint file was named as missing, not the folder
            what = "no such folder" if not taught.exists() else "not a folder"
            raise ValueError(f"--taught {taught}: {what} (kiseki teach writes one)")
        waypoints = taught / "waypoints.yaml"
    map_path, marks = load_route(waypoints, band, names, map_file)
    check_scene_file(scene_file)
    taught_scene = taught_scene_of(waypoints)
    identity = check_scene(taught_scene, scene_file, variant)
    if log is not None and log.exists():
        raise FileExistsError(f"--log {log} exists; give a new file")
    scene, environment = load_scene(scene_file, "playback"), load_map(map_path)
    check_on_the_map(waypoints, map_path, environment, marks)
    limiter = _speed_limiter(speed_limit, scene, environment, config.speed)
    travelled = read_travelled(waypoints)  # the teaching log's odometry (None without it)
    result = playback(
        scene, environment, marks, config, limiter, log, taught_scene, variant, travelled
    )
    console.print(_stop_summary(method, result, marks[-1]))
    if result.collision is not None:
        console.print("  " + result.collision.line(), soft_wrap=True)
    if variant is not None:
        console.print(
            f"  scene variant {variant!r}: {scene_file} (SHA-1 {identity['scene_sha1']}), taught "
            f"in {identity.get('taught_scene_file') or 'an unrecorded scene'} (SHA-1 "
            f"{identity.get('taught_scene_sha1', 'not recorded')})",
            soft_wrap=True,
        )
    if result.speed_limits is not None:
        limits = result.speed_limits
        console.print(
            f"  speed limit ({speed_limit}): {limits.min():.2f} to {limits.max():.2f} m/s, "
            f"below the route speed {config.speed:.2f} m/s at {np.mean(limits < config.speed):.0%}"
            " of the steps"
        )
    if log is not None:
        console.print(f"  run logged to {log}", soft_wrap=True)
    if plot is not None:
        render_playback(result, environment, marks, plot, label=f"{scene_file.name}, {method}")
        console.print(f"  picture in {plot}", soft_wrap=True)


SPEED_LIMITS = ("none", "occlusion", "occlusion-width")


def _stop_summary(method: str, result, goal: dict) -> str:
    """Where a playback stopped: estimated, against the goal, and true, against where the goal
    was taught when the waypoint file records it ('truth' is optional: a hand-made file or a
    real robot has none)."""
    tx, ty, _ = result.stop_true
    ex, ey, _ = result.stop_estimate
    if "truth" in goal:
        taught_at = f"{math.hypot(tx - goal['truth'][0], ty - goal['truth'][1]):.3f} m from"
    else:
        taught_at = "no true pose recorded for"
    return (
        f"{method}: stopped after {result.steps} steps; estimated stop ({ex:.3f}, {ey:.3f}) in the "
        f"map, {math.hypot(ex - goal['x'], ey - goal['y']):.3f} m from {goal['name']}; true stop "
        f"({tx:.3f}, {ty:.3f}), {taught_at} where {goal['name']} was taught; goal reached: "
        f"{result.reached} ({result.duration:.1f} s)"
    )


def _speed_limiter(name: str, scene, grid, v_max: float):
    """The --speed-limit limiter on the taught map (kiseki.speed: the library's playback never
    imports it; the command adds it)."""
    if name == "none":
        return None
    sensors = scene.robot_specs[0]["sensors"]
    if not any(isinstance(s, dict) and s.get("type") == "laser" for s in sensors):
        raise ValueError(f"--speed-limit {name}: scene {scene.path} has no laser")
    config = SpeedLimiterConfig(
        v_max=v_max, use_occlusion=True, use_width=name == "occlusion-width"
    )
    return SpeedLimiter(grid, config)


def check_on_the_map(path: Path, map_path: Path, grid: OccupancyGrid, marks: list[dict]) -> None:
    """Each waypoint of a route lies on the taught map's cells, ``grid`` read from ``map_path``
    (a waypoint edited to 700 m sent the simulated robot out through the walls, and the run
    ended without an error)."""
    for mark in marks:
        cell = grid.world_to_cell(np.array([[mark["x"], mark["y"]]]))[0]
        if not (0 <= cell[0] < grid.width and 0 <= cell[1] < grid.height):
            raise ValueError(
                f"{path}: waypoint {mark['name']} at ({mark['x']:g}, {mark['y']:g}) m lies off "
                f"the taught map {map_path}"
            )
