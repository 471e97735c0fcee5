# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The main job until teaching and playback land: the thesis' corridor run (P0 -> P1 -> P2) in
the simulated factory (data/worlds/factory_corridor.yaml). The AGV follows the route with a
Hokuyo laser and two sideways depth cameras, its wheel odometry drifting as real odometry does;
the run is logged to MCAP; maps are built from the laser along the true path and along the
odometry path, showing how odometry alone bends a taught map; the odometry error at P1 and P2
is set beside the thesis' Tables 4.1-4.4. Uses only files in the repository.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import yaml
from rich.console import Console
from rich.table import Table

from kiseki._atomic import atomic_write
from kiseki.grid import grid_summary
from kiseki.map_io import save_map
from kiseki.mapping import build_map, endpoint_agreement
from kiseki.plots import render_map
from kiseki.sim.mcap_log import read_run
from kiseki.sim.render import render_scene
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene

__all__ = ["DemoConfig", "run_demo"]

# The thesis' odometry error (odometry - truth) at P1 and P2, means of 11 runs (Tables 4.1-4.4).
THESIS_ODOMETRY_ERROR = {"P1": (None, -0.07), "P2": (0.01, -0.20)}


@dataclass(frozen=True)
class DemoConfig:
    scene: str = "data/worlds/factory_corridor.yaml"
    seed: int = 0


def _write_text(path: Path, text: str) -> None:
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def _odometry_sensor_poses(odometry: np.ndarray, mount_x: float) -> np.ndarray:
    """The laser's pose if the robot were where its odometry says (laser mount_x ahead)."""
    c, s = np.cos(odometry[:, 2]), np.sin(odometry[:, 2])
    return np.column_stack(
        [odometry[:, 0] + mount_x * c, odometry[:, 1] + mount_x * s, odometry[:, 2]]
    )


def _errors_at(truth: np.ndarray, odometry: np.ndarray, waypoints: dict) -> dict:
    """Odometry - truth (x, y) when the robot passes each waypoint's x (the stop for the last)."""
    out = {}
    for name, (x, _) in waypoints.items():
        passed = np.nonzero(truth[:, 0] >= x - 0.05)[0]
        i = int(passed[0]) if len(passed) else len(truth) - 1
        out[name] = (odometry[i, :2] - truth[i, :2]).tolist()
    return out


def run_demo(map_file: Path, out: Path, seed: int, console: Console) -> dict:
    config = DemoConfig(scene=str(map_file), seed=seed)
    out.mkdir(parents=True, exist_ok=True)
    scene = load_scene(map_file)
    render_scene(scene, out / "scene.png")
    run = simulate(scene, out / "run.mcap", SimConfig(seed=seed), overwrite=True, progress=True)
    log = read_run(run.path)
    scans = log.laser_scans()
    mount_x = float(np.hypot(*(scans.poses[0, :2] - _track(log)[0, :2])))
    truth = _track(log)
    odom_sensor = _odometry_sensor_poses(scans.odometry, mount_x)
    maps = {
        "true_path": build_map(scans.poses, scans.ranges, scans.angles, scans.max_range),
        "odometry_path": build_map(odom_sensor, scans.ranges, scans.angles, scans.max_range),
    }
    for name, grid in maps.items():
        save_map(grid, out / f"map_{name}.yaml")
    render_map(
        maps["true_path"],
        out / "map_true_path.png",
        trajectory=scans.poses,
        title="map from the laser along the true path",
    )
    render_map(
        maps["odometry_path"],
        out / "map_odometry_path.png",
        trajectory=odom_sensor,
        title="map from the laser along the odometry path (what odometry alone teaches)",
    )
    route = dict(zip(scene.route.get("names", []), scene.route["waypoints"], strict=False))
    x, y, _ = run.final_pose
    goal = scene.route["waypoints"][-1]
    summary = {
        "scene": str(map_file),
        "simulated_seconds": run.sim_seconds,
        "real_time_factor": run.sim_seconds / run.wall_seconds,
        "messages": run.messages,
        "stop_error_m": math.hypot(x - goal[0], y - goal[1]),
        "reached_goal": run.reached_goal,
        "odometry_error_m": _errors_at(
            truth, scans.odometry, {k: v for k, v in route.items() if k != "P0"}
        ),
        "endpoints_true_path_map": endpoint_agreement(
            maps["true_path"], scans.poses, scans.ranges, scans.angles, scans.max_range
        ),
        "endpoints_odometry_path_map": endpoint_agreement(
            maps["odometry_path"], odom_sensor, scans.ranges, scans.angles, scans.max_range
        ),
        "map_true_path": grid_summary(maps["true_path"]),
    }
    _write_text(out / "config.yaml", yaml.safe_dump(asdict(config), sort_keys=False))
    _write_text(out / "summary.json", json.dumps(summary, indent=2))
    _print_summary(summary, out, console)
    return summary


def _track(log) -> np.ndarray:
    msgs = log.messages("/ground_truth")
    return np.array([[m["pose"]["position"]["x"], m["pose"]["position"]["y"]] for _, m in msgs])


def _print_summary(summary: dict, out: Path, console: Console) -> None:
    table = Table(title="kiseki demo: the thesis' corridor run P0 -> P1 -> P2, simulated")
    table.add_column("quantity")
    table.add_column("thesis", justify="right")
    table.add_column("kiseki", justify="right")
    table.add_row(
        "simulated time (s), speed vs real time",
        "",
        f"{summary['simulated_seconds']:.1f} s, {summary['real_time_factor']:.1f}x",
    )
    table.add_row(
        "stop distance from P2 (m), controller on ground truth",
        "<= 0.1",
        f"{summary['stop_error_m']:.3f}",
    )
    for name, (dx, dy) in summary["odometry_error_m"].items():
        tx, ty = THESIS_ODOMETRY_ERROR.get(name, (None, None))
        thesis = f"({'-' if tx is None else f'{tx:+.2f}'}, {ty:+.2f})" if ty is not None else ""
        table.add_row(
            f"odometry error at {name} (x, y) m, one run", thesis, f"({dx:+.3f}, {dy:+.3f})"
        )
    table.add_row(
        "scan endpoints on the map, true path",
        "",
        f"{100 * summary['endpoints_true_path_map']:.1f} %",
    )
    table.add_row(
        "scan endpoints on the map, odometry path",
        "",
        f"{100 * summary['endpoints_odometry_path_map']:.1f} %",
    )
    console.print(table)
    console.print(f"run (MCAP), maps (ROS YAML + PGM), figures and summary in {out}/")
