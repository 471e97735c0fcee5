# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Top-down pictures of scenes and runs: the world in height bands, the robot, its route, scans
and trajectories (PNG), and an animation of a run (GIF)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kiseki._support.atomic import atomic_write
from kiseki.plots import new_figure
from kiseki.sim.scene import Scene

__all__ = ["render_run", "render_scene"]

# Height bands drawn from the top down, so lower obstacles show where they exist.
BANDS = [
    ((1.0, None), "high (1.0 m to under the ceiling)"),
    ((0.6, 1.0), "table tops (0.6-1.0 m)"),
    ((0.05, 0.6), "low (0.05-0.6 m): legs, walls"),
]
COLOURS = ["white", "#b0b0b0", "#e69f00", "black"]


def _layers(scene: Scene) -> tuple[np.ndarray, object]:
    layers = None
    grid = None
    top = float(scene.bounds[1][2]) - 0.15  # leave out a ceiling at the scene's top
    for k, ((lo, hi), _) in enumerate(BANDS):
        grid = scene.ground_truth(lo, hi if hi is not None else max(top, lo + 0.1))
        occ = grid.cells == 100
        if layers is None:
            layers = np.zeros(occ.shape, dtype=np.int8)
        layers[occ] = k + 1
    return layers, grid


def _axes(grid, title: str):
    aspect = grid.height / grid.width
    width = 12.0 if aspect < 1 else 12.0 / aspect
    fig = new_figure(figsize=(width, max(3.0, width * aspect)), dpi=110)
    ax = fig.subplots()
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    return fig, ax


def _scene_axes(scene: Scene, title: str):
    """A figure with the scene's obstacles drawn by height band."""
    layers, grid = _layers(scene)
    fig, ax = _axes(grid, title)
    ax.imshow(
        layers,
        origin="lower",
        extent=_extent(grid),
        cmap=_colours(),
        vmin=0,
        vmax=3,
        interpolation="nearest",
    )
    return fig, ax


def _colours():
    from matplotlib.colors import ListedColormap  # imported when a picture is drawn

    return ListedColormap(COLOURS)


def _extent(grid) -> list[float]:
    o, r = grid.origin, grid.resolution
    return [o.x, o.x + grid.width * r, o.y, o.y + grid.height * r]


def _save(fig, path) -> Path:
    return atomic_write(Path(path), lambda tmp: fig.savefig(tmp, bbox_inches="tight"))


def render_scene(scene: Scene, path: str | os.PathLike) -> Path:
    """The scene from above: obstacles by height band, robot start, route and waypoints."""
    fig, ax = _scene_axes(scene, f"{scene.name}: {scene.description}")
    for k, (_, label) in enumerate(BANDS):
        ax.plot([], [], "s", color=COLOURS[k + 1], label=label)
    for k, spec in enumerate(scene.robot_specs):
        label = spec["name"] if len(scene.robot_specs) > 1 else ""
        _draw_robot(ax, spec, label, f"C{k}")
    if scene.turns is not None:
        _draw_turns(ax, scene)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    return _save(fig, path)


def _draw_turns(ax, scene: Scene) -> None:
    """The turns: each robot's moves as arrows from where it stands, numbered in order."""
    names = [spec["name"] for spec in scene.robot_specs]
    at = {spec["name"]: tuple(map(float, spec["robot"]["start"][:2])) for spec in scene.robot_specs}
    for k, (name, to) in enumerate(scene.turns["moves"], start=1):
        colour = f"C{names.index(name)}"
        ax.annotate("", to, at[name], arrowprops={"arrowstyle": "->", "color": colour, "lw": 1})
        ax.annotate(str(k), to, textcoords="offset points", xytext=(5, 3), fontsize=7)
        at[name] = to
    for k, name in enumerate(names):
        ax.plot([], [], "-", color=f"C{k}", label=f"turns of {name}")
    ax.plot(*scene.turns["goal"], "r*", markersize=12, label="goal")


def _draw_robot(ax, spec: dict, label: str, colour: str) -> None:
    if spec["route"]:  # checked by the scene's model: two or more [x, y], names one per point
        route = np.asarray(spec["route"]["waypoints"])
        ax.plot(
            route[:, 0],
            route[:, 1],
            "--o",
            color=colour,
            markersize=4,
            label=f"route {label}".strip(),
        )
        for name, (x, y) in zip(spec["route"].get("names", []), route, strict=False):
            ax.annotate(name, (x, y), textcoords="offset points", xytext=(4, 6), fontsize=8)
    start = spec["robot"].get("start")
    if start is not None:
        x, y, yaw = float(start[0]), float(start[1]), np.radians(float(start[2]))
        ax.arrow(
            x,
            y,
            0.6 * np.cos(yaw),
            0.6 * np.sin(yaw),
            width=0.08,
            color="tab:green",
            label=f"start {label}".strip(),
        )
        if label:
            ax.annotate(label, (x, y), textcoords="offset points", xytext=(-10, -12), fontsize=8)


def _track(run, topic: str) -> np.ndarray:
    msgs = run.messages(topic)
    if not msgs:
        return np.zeros((0, 2))
    if "pose" in msgs[0][1]:
        return np.array([[m["pose"]["position"]["x"], m["pose"]["position"]["y"]] for _, m in msgs])
    return np.array([[m["x"], m["y"]] for _, m in msgs])


def _scan_points(message: dict) -> np.ndarray:
    r = np.asarray(message["ranges"], dtype=float)
    step = (message["end_angle"] - message["start_angle"]) / max(1, len(r) - 1)
    a = message["start_angle"] + np.arange(len(r)) * step
    q = message["pose"]
    yaw = 2 * np.arctan2(q["orientation"]["z"], q["orientation"]["w"])
    ok = np.isfinite(r) & (r < np.nanmax(r))
    return np.column_stack(
        [
            q["position"]["x"] + r[ok] * np.cos(yaw + a[ok]),
            q["position"]["y"] + r[ok] * np.sin(yaw + a[ok]),
        ]
    )


def render_run(
    scene: Scene, run, path: str | os.PathLike, scan_topic: str = "/scan", frames: int = 40
) -> Path:
    """An animation of a recorded run (kiseki.io.runlog.SimRun): every robot's ground truth
    and odometry, and the laser scan, over the scene. GIF via Pillow."""
    topics = run.topics()
    prefixes = sorted(t[: -len("/ground_truth")] for t in topics if t.endswith("/ground_truth"))
    if not prefixes:
        raise ValueError(f"{run.path}: no ground-truth topic to animate")
    truths = [_track(run, f"{p}/ground_truth") for p in prefixes]
    odoms = [
        _track(run, f"{p}/odom") if f"{p}/odom" in topics else np.zeros((0, 2)) for p in prefixes
    ]
    scans = run.messages(scan_topic) if scan_topic in topics else []
    fig, ax = _scene_axes(scene, f"{scene.name}: simulated run")
    lines = []
    for k, p in enumerate(prefixes):
        name = p.strip("/") or "robot"
        lines.append(ax.plot([], [], "-", color=f"C{k}", label=f"{name} ground truth")[0])
        lines.append(ax.plot([], [], ":", color=f"C{k}", label=f"{name} odometry")[0])
    (points,) = ax.plot([], [], ".", color="tab:green", markersize=2, label="scan")
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=7)
    n = max(len(t) for t in truths)
    picks = np.unique(np.linspace(0, n - 1, min(frames, n)).astype(int))

    def draw(i):
        for k in range(len(prefixes)):
            for line, track in ((lines[2 * k], truths[k]), (lines[2 * k + 1], odoms[k])):
                j = min(len(track), int((i + 1) * len(track) / n))
                line.set_data(track[:j, 0], track[:j, 1])
        if scans:
            xy = _scan_points(scans[min(len(scans) - 1, int(i * len(scans) / n))][1])
            points.set_data(xy[:, 0], xy[:, 1])
        return (*lines, points)

    from matplotlib.animation import FuncAnimation, PillowWriter  # when an animation is drawn

    anim = FuncAnimation(fig, draw, frames=picks, blit=True)
    return atomic_write(Path(path), lambda tmp: anim.save(tmp, writer=PillowWriter(fps=10)))
