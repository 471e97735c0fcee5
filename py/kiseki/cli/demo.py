# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The main job: the factory demo of the teaching-and-playback thesis, in the simulated factory
(data/worlds/factory_turn.yaml, the route with a turn of Exp. 2). The AGV is pushed once along
the route (teaching: environment maps from its two sideways depth cameras placed by odometry,
waypoints P0, T1, T2, G, the run logged to MCAP), then plays the route back with each method
(conventional, proposal 1, proposal 2, both) and stops when its estimate is within 0.1 m of G.
The Table 4.5-style comparison is printed beside the thesis' numbers (one run per method here;
`kiseki experiment run exp2-turn` repeats it). Uses only files in the repository.
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import typer
import yaml
from rich.console import Console

from kiseki._support.atomic import atomic_write
from kiseki._support.guard import guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import PARTICLE_LIMIT, Count, Seed
from kiseki._support.replaced_files import refuse_replacing
from kiseki._support.table import show
from kiseki.apps.teach import PlaybackConfig, playback, teach
from kiseki.apps.teach.playback_picture import render_playback
from kiseki.apps.teach.teaching import TEACHING_FILES
from kiseki.cli._defaults import default_of
from kiseki.cli.teach import merge_rule
from kiseki.core import derive_seed
from kiseki.io.ros_map import load_map
from kiseki.io.runlog import TruncatedRunWarning, read_run
from kiseki.plots import render_map
from kiseki.sim.collisions import Collision
from kiseki.sim.render import render_scene
from kiseki.sim.scene import load_scene
from kiseki.teach.local_maps import METHODS

__all__ = ["DEMO_FILES", "DemoConfig", "app", "run_demo"]

# Thesis Table 4.5 (5 runs each): stop error mean (m), estimate error mean (m), stops within 0.1 m
THESIS = {
    "conventional": (0.13, 0.13, "0/5"),
    "proposal1": (0.09, 0.08, "4/5"),
    "proposal2": (0.07, 0.05, "5/5"),
    "both": (None, None, "not tried"),
}


@dataclass(frozen=True)
class DemoConfig:
    """What the demo runs with (written to OUT/config.yaml); the command's defaults."""

    scene: str = "data/worlds/factory_turn.yaml"
    seed: int = 0
    particles: int = default_of(PlaybackConfig, "particles")  # the filter's own default
    merge: str = "thesis"  # the environment maps' merge rule (kiseki.teach.environment_map)


# what the demo writes in its --out folder, in order (the teaching run's files in teach/)
DEMO_FILES = (
    *(f"teach/{name}" for name in TEACHING_FILES),
    "scene.png",
    "taught_map_band.png",
    *(f"playback_{method}.png" for method in METHODS),
    "config.yaml",
    "summary.json",
)

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


@app.command("demo")
@guarded(inputs=("scene",), output_folders=("out",))
@interruptible()
def demo(
    out: Path = typer.Option(Path("results/demo"), help="Folder for the run, maps and figures."),
    scene: Path = typer.Option(
        Path(DemoConfig.scene), "--scene", help="Scene with a taught route."
    ),
    seed: int = typer.Option(
        DemoConfig.seed, parser=Seed(), help="Seed of every noise source of the run."
    ),
    particles: int = typer.Option(
        DemoConfig.particles,
        parser=Count("--particles", 1, PARTICLE_LIMIT),
        help="Particles of the localization filter.",
    ),
    merge: str = typer.Option(
        DemoConfig.merge,
        help="Merge rule of the taught maps: thesis or evidence (see kiseki teach).",
    ),
) -> None:
    """The main job: teach the factory route with a turn, measure the taught maps against the
    scene's truth, play the route back with each method, and print the thesis' Table 4.5-style
    comparison.

    Example: kiseki demo --out results/demo --seed 0"""
    run_demo(scene, out, seed, console, particles, merge_rule(merge))


# the demo's teaching log says in its metadata that the demo wrote it
WRITTEN_BY = {"written_by": "kiseki demo"}


def _check_out(out: Path) -> None:
    """Before any work: an earlier demo's folder is replaced, known by its teaching log
    (teach/teach.mcap, the demo's first file, so that a demo interrupted before its summary is
    one too) whose metadata says the demo wrote it (a user's own `kiseki teach -o OUT/teach`
    is not the demo's); another folder holding a file the demo writes (a user's own
    config.yaml) is refused."""
    log = out / "teach" / "teach.mcap"
    if log.is_file() and not log.is_symlink():
        try:
            with warnings.catch_warnings():  # a demo killed while teaching cut its log short
                warnings.simplefilter("ignore", TruncatedRunWarning)
                if read_run(log).metadata.get("written_by") == WRITTEN_BY["written_by"]:
                    return
        except (OSError, ValueError):  # not a log the demo could read back: not its own
            pass
    remedy = "give a new or empty folder as --out (an earlier demo's folder is replaced)"
    refuse_replacing(out, DEMO_FILES, "--out", remedy)


def _write_text(path: Path, text: str) -> None:
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def run_demo(
    scene_file: Path,
    out: Path,
    seed: int,
    console: Console,
    particles: int = DemoConfig.particles,
    merge: str = DemoConfig.merge,
) -> dict:
    config = DemoConfig(scene=str(scene_file), seed=seed, particles=particles, merge=merge)
    PlaybackConfig(particles=particles)  # a bad --particles is refused before the teaching
    scene = load_scene(scene_file)
    if not scene.route.get("waypoints"):  # teach's own check, before anything is written
        raise ValueError(f"{scene_file}: the demo teaches along the scene's route: it has none")
    _check_out(out)
    out.mkdir(parents=True, exist_ok=True)
    console.print("teaching: pushing the AGV along the route ...")
    # the teaching log first: it marks the folder as the demo's own (_check_out), so that a
    # demo cut short after it can be run into again
    taught = teach(
        scene, out / "teach", derive_seed(seed, 1), overwrite=True, merge=merge, metadata=WRITTEN_BY
    )
    render_scene(scene, out / "scene.png")
    goal = taught.marks[-1]
    maps = {band: load_map(path) for band, path in taught.maps.items()}
    marks_xy = np.array([[m["x"], m["y"]] for m in taught.marks])
    render_map(
        maps["band"],
        out / "taught_map_band.png",
        trajectory=marks_xy,
        title="taught map (depth height band) and waypoints, odometry frame",
    )
    play_scene = load_scene(scene_file, "playback")
    results = {}
    for method in METHODS:
        console.print(f"playback: {method} ...")
        band, _ = METHODS[method]
        r = playback(
            play_scene,
            maps[band],
            taught.marks,
            PlaybackConfig(method=method, particles=particles, seed=derive_seed(seed, 2)),
            taught_scene=taught.scene,
        )
        picture = out / f"playback_{method}.png"
        render_playback(r, maps[band], taught.marks, picture, label=f"{scene.name}, {method}")
        tx, ty = r.stop_true[0] - goal["truth"][0], r.stop_true[1] - goal["truth"][1]
        ex, ey = r.stop_estimate[0] - goal["x"], r.stop_estimate[1] - goal["y"]
        results[method] = {
            "stop_error_m": math.hypot(tx, ty),
            "estimate_error_m": math.hypot(ex - tx, ey - ty),
            "stop_offset_m": [tx, ty],
            "reached": r.reached,
            "steps": r.steps,
            "collision": None if r.collision is None else r.collision.payload(),
        }
    summary = {
        "scene": str(scene_file),
        "teaching_steps": taught.steps,
        "waypoints": [m["name"] for m in taught.marks],
        "merge": taught.merge,
        "taught_map_truth": {
            band: {k: t[k] for k in ("erased_share", "false_occupied_share")}
            for band, t in taught.truth.items()
        },
        "playback": results,
    }
    _write_text(out / "config.yaml", yaml.safe_dump(asdict(config), sort_keys=False))
    _write_text(out / "summary.json", json.dumps(summary, indent=2))
    _print_truth(taught.truth, taught.merge, console)
    _print(results, scene.name, out, console)
    return summary


def _print_truth(truth: dict, merge: str, console: Console) -> None:
    columns = ("map", "obstacle cells in reach", "erased", "visible free cells", "occupied")
    rows = [
        (
            band,
            t["obstacle_cells"],
            f"{100 * t['erased_share']:.1f} %",
            t["visible_free_cells"],
            f"{100 * t['false_occupied_share']:.1f} %",
        )
        for band, t in truth.items()
    ]
    title = f"Taught maps against the scene's truth ({merge} merge)"
    show(title, columns, rows, as_json=False, data=None, console=console)


def _print(results: dict, scene_name: str, out: Path, console: Console) -> None:
    columns = (
        "method",
        "stop error m (thesis)",
        "kiseki",
        "estimate error m (thesis)",
        "kiseki",
        "within 0.1 m (thesis)",
        "kiseki",
    )
    rows = []
    for method, r in results.items():
        stop, est, within = THESIS[method]
        rows.append(
            (
                method,
                "-" if stop is None else f"{stop:.2f}",
                f"{r['stop_error_m']:.3f}",
                "-" if est is None else f"{est:.2f}",
                f"{r['estimate_error_m']:.3f}",
                within,
                "yes" if r["stop_error_m"] <= 0.1 and r["collision"] is None else "no",
            )
        )
    title = f"{scene_name}: one run per method, beside the thesis' Exp. 2 (Table 4.5)"
    show(title, columns, rows, as_json=False, data=None, console=console)
    for method, r in results.items():
        if r["collision"] is not None:
            console.print(f"{method}: " + Collision(**r["collision"]).line())
    console.print(f"teaching log, taught maps, waypoints, figures and summary in {out}/")
