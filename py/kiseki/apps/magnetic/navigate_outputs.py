# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Files of magnetic teaching and navigation (``kiseki magnetic teach`` / ``navigate``):

* a taught folder: the taught path's linear map (a linear-map folder,
  :mod:`kiseki.magnetic.linear_map_folder`, so it declares its kind and its path), the maps of
  the left and right parallel paths in its sub-folders ``left/`` and ``right/`` (Rahok's eq. 3.1),
  and the teaching runs in ``runs/``;
* a navigation's ``navigation.csv`` (one row per control step: t, true x, y, theta, the
  navigator's travel distance, the signed cross-track error (left +), the true distance along
  the route, the travel-distance error, the navigator that drove) and ``navigation.png`` (the
  path, the cross-track error along it, and the priority history of Fig. 4.12, or Rahok's
  travel-distance corrections).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from kiseki._support.atomic import atomic_write, check_writable_folder
from kiseki.apps.magnetic.navigate_run import (
    GATES,
    METHODS,
    NavigationResult,
    TaughtMaps,
    navigate,
    teach,
)
from kiseki.apps.magnetic.teach_checks import check_magnetometer
from kiseki.magnetic.linear_map import path_identity
from kiseki.magnetic.linear_map_folder import MAP_FILE, load_linear_map, save_linear_map
from kiseki.plots import new_figure, save_figure
from kiseki.sim.scene import load_scene

__all__ = ["load_taught", "navigate_folder", "save_taught", "teach_folder", "write_navigation"]

SIDES = ("left", "right")


def save_taught(maps: TaughtMaps, folder: str | os.PathLike, runs: list[Path] = ()) -> Path:
    """Writes the maps to ``folder`` (see the module text) and moves the teaching ``runs``
    (MCAP files) into ``folder/runs``."""
    folder = Path(folder)
    save_linear_map(maps.center, folder)
    for side in SIDES:
        lmap = getattr(maps, side)
        if lmap is not None:
            save_linear_map(lmap, folder / side)
    if runs:
        (folder / "runs").mkdir(exist_ok=True)
        for run in runs:
            shutil.move(os.fspath(run), os.fspath(folder / "runs" / Path(run).name))
    return folder


def load_taught(folder: str | os.PathLike, waypoints) -> TaughtMaps:
    """The maps of a taught folder for the route ``waypoints`` (a map of another path raises
    OtherPathError; a GP map folder MapFormatError); absent parallel maps are None."""

    folder = Path(folder)
    path_id = path_identity(waypoints)
    center = load_linear_map(folder, path_id)
    sides = {
        s: load_linear_map(folder / s, path_id) if (folder / s / MAP_FILE).is_file() else None
        for s in SIDES
    }
    return TaughtMaps(center, sides["left"], sides["right"], np.asarray(waypoints, dtype=float))


def _csv_text(r: NavigationResult) -> str:
    lines = ["t,x,y,theta,travel,cross_track,along_track,travel_error,drove"]
    for i in range(len(r.times)):
        x, y, th = r.truth[i]
        values = (r.times[i], x, y, th, r.travel[i], r.cross_track[i], r.along_track[i])
        numbers = ",".join(f"{v:.6f}" for v in (*values, r.travel_error[i]))
        lines.append(f"{numbers},{r.drove[i] or ''}")
    return "\n".join(lines) + "\n"


def _figure(r: NavigationResult, waypoints: np.ndarray):

    fig = new_figure(figsize=(10.0, 8.0), dpi=100)
    ax_path, ax_xt, ax_p = fig.subplots(3, 1)
    ax_path.plot(waypoints[:, 0], waypoints[:, 1], "k--", lw=1, label="taught route")
    ax_path.plot(r.truth[:, 0], r.truth[:, 1], "C0", lw=1.5, label=f"{r.method} (truth)")
    ax_path.set_xlabel("x [m]")
    ax_path.set_ylabel("y [m]")
    ax_path.legend(loc="upper left", fontsize=8)
    ax_path.set_title(f"magnetic navigation: {r.method}")
    ax_xt.plot(r.along_track, r.cross_track, "C1", lw=1)
    ax_xt.axhline(0.0, color="k", lw=0.5)
    ax_xt.set_xlabel("distance along the route [m]")
    ax_xt.set_ylabel("cross-track error [m] (left +)")
    if r.priorities is not None and len(r.navigators) > 1:
        for k, name in enumerate(r.navigators):
            ax_p.step(r.times, r.priorities[:, k], where="post", lw=1, label=name)
        top = np.array(
            [r.priorities[i, r.navigators.index(d)] if d else 0.0 for i, d in enumerate(r.drove)]
        )
        ax_p.plot(r.times, top, "k.", ms=1.5, label="drove")
        ax_p.set_ylabel("priority (0: invalid)")
        ax_p.legend(loc="upper right", fontsize=7, ncol=5)
    else:
        done = [(s, c) for s, _, c, _ in r.corrections if c is not None]
        if done:
            ax_p.stem([s for s, _ in done], [c for _, c in done])
        ax_p.set_ylabel("travel correction [m]")
    ax_p.set_xlabel("time [s]" if r.priorities is not None and len(r.navigators) > 1 else "s [m]")
    fig.tight_layout()
    return fig


def write_navigation(
    result: NavigationResult, folder: str | os.PathLike, waypoints
) -> tuple[Path, Path]:
    """Writes ``navigation.csv`` and ``navigation.png`` into ``folder`` atomically."""

    folder = Path(folder)
    csv = atomic_write(
        folder / "navigation.csv",
        lambda tmp: Path(tmp).write_text(_csv_text(result), encoding="utf-8"),
    )
    png = save_figure(
        _figure(result, np.asarray(waypoints, dtype=float)), folder / "navigation.png"
    )
    return csv, png


def _check_out(folder: Path, option: str) -> None:

    if folder.exists() and not folder.is_dir():
        raise ValueError(f"{option} {folder}: not a folder")
    check_writable_folder(folder)


def teach_folder(scene: Path, folder: Path, seed: int, offset: float) -> TaughtMaps:
    """``kiseki magnetic teach``: the three teaching runs (:func:`teach`) into a temporary
    folder beside ``folder``, then the maps and the runs into ``folder``. A non-empty folder
    that is not a linear map is refused before the runs."""
    folder = Path(folder)
    _check_out(folder, "-o")
    if folder.is_dir() and any(folder.iterdir()) and not (folder / MAP_FILE).is_file():
        raise ValueError(f"-o {folder}: a non-empty folder that is not a linear magnetic map")
    folder.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder.parent, prefix=".teach-") as tmp:
        maps = teach(scene, tmp, seed, offset, option="--offset")
        save_taught(maps, folder, sorted(Path(tmp).glob("teach_*.mcap")))
    return maps


def navigate_folder(
    scene: Path, map_folder: Path, method: str, folder: Path, seed: int, gates: str = "thesis"
) -> NavigationResult:
    """``kiseki magnetic navigate``: the playback run ``folder/run.mcap`` and
    :func:`write_navigation`'s files."""

    if method not in METHODS:
        raise ValueError(f"--navigator must be one of {'|'.join(METHODS)}, got {method!r}")
    if gates not in GATES:
        raise ValueError(f"--gates must be one of {'|'.join(GATES)}, got {gates!r}")
    folder = Path(folder)
    _check_out(folder, "-o")
    played = load_scene(scene, "playback")
    waypoints = played.route.get("waypoints")
    if waypoints is None:
        raise ValueError(f"{scene}: the scene has no route")
    check_magnetometer(played, scene)  # before the output folder is made
    maps = load_taught(map_folder, waypoints)
    if method == "rahok" and (maps.left is None or maps.right is None):  # before the run
        raise ValueError(
            f"--map {map_folder}: Rahok's method needs the maps of the left and right parallel "
            "paths (left/ and right/ in a folder of kiseki magnetic teach)"
        )
    folder.mkdir(parents=True, exist_ok=True)
    result = navigate(scene, maps, method, folder / "run.mcap", seed, gates=gates)
    write_navigation(result, folder, waypoints)
    return result
