# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki sim``: simulation: scenes, runs logged to MCAP."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import typer
from rich.console import Console

from kiseki import _core
from kiseki._support.atomic import atomic_write
from kiseki._support.guard import guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import (
    CELL_LIMITS,
    SIM_SECONDS_LIMIT,
    Metres,
    Seconds,
    Seed,
    refuse_given,
)
from kiseki._support.outputs import FIGURE_SUFFIXES, check_outputs, check_suffix
from kiseki.cli._defaults import default_of
from kiseki.io.runlog import read_run
from kiseki.sim.render import render_run, render_scene
from kiseki.sim.run import SimConfig, read_commands, simulate
from kiseki.sim.scene import load_scene
from kiseki.teach.scene_identity import resolve_scene_file

__all__ = ["app"]

app = typer.Typer(no_args_is_help=True, help="Simulation: scenes, runs logged to MCAP.")
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


@app.command("run")
@guarded(inputs=("scene_file", "commands"), outputs=("output",))
def sim_run(
    scene_file: Path = typer.Argument(..., metavar="SCENE", help="Scene YAML (data/worlds/...)."),
    output: Path = typer.Option(..., "-o", "--output", help="MCAP file to write."),
    controller: str = typer.Option("route", help="'route' (pure pursuit) or 'commands'."),
    commands: Path | None = typer.Option(None, help="CSV t,v,w or t,vx,vy,w for 'commands'."),
    duration: float | None = typer.Option(
        None,
        parser=Seconds("--duration", 0, SIM_SECONDS_LIMIT, lo_open=True),
        help="Seconds to simulate (default: to goal).",
    ),
    seed: int = typer.Option(
        default_of(SimConfig, "seed"), parser=Seed(), help="Seed of every noise source of the run."
    ),
    variant: str = typer.Option("teach", help="Scene variant: teach or playback."),
    overwrite: bool = typer.Option(False, help="Replace an existing output file."),
) -> None:
    """Simulate a scene and log the run (ground truth, odometry, sensors) to MCAP.

    Example: kiseki sim run data/worlds/factory_corridor.yaml -o run.mcap --seed 0"""
    if controller not in ("route", "commands"):
        raise ValueError(f"--controller must be route or commands, got {controller!r}")
    if (controller == "commands") != (commands is not None):
        raise ValueError("--commands FILE goes with --controller commands, and only with it")
    check_suffix("--output", output, (".mcap",))  # the run is MCAP whatever the name says
    if output.exists() and not overwrite:
        raise FileExistsError(f"--output {output} exists: give --overwrite to replace it")
    script = read_commands(commands) if commands is not None else None
    scene = load_scene(scene_file, variant)
    try:
        summary = simulate(
            scene, output, SimConfig(duration=duration, seed=seed), script, overwrite
        )
    except (KeyboardInterrupt, SystemExit) as stop:  # Ctrl-C, or SIGTERM through _terminate
        typer.echo(
            f"kiseki: interrupted; {output} holds the run up to the interruption, closed "
            "properly (every reader takes it)",
            err=True,
        )
        raise typer.Exit(stop.code if isinstance(stop, SystemExit) else 130) from None
    x, y, th = summary.final_pose
    console.print(
        f"{output}: {summary.sim_seconds:.1f} s simulated in {summary.wall_seconds:.1f} s "
        f"({summary.sim_seconds / max(summary.wall_seconds, 1e-9):.1f}x real time), "
        f"final pose ({x:.3f}, {y:.3f}, {th:.3f}), goal reached: {summary.reached_goal}; "
        + ", ".join(f"{k} {v}" for k, v in summary.messages.items())
    )
    if summary.collision is not None:
        console.print(summary.collision.line())


@app.command("render")
@guarded(inputs=("run_file", "scene_file"), outputs=("output",))
@interruptible()
def sim_render(
    run_file: Path = typer.Argument(..., metavar="RUN", help="MCAP file of a run."),
    output: Path = typer.Option(..., "-o", "--output", help="GIF to write."),
    scene_file: Path | None = typer.Option(None, "--scene", help="Scene (default: from run)."),
) -> None:
    """Animate a recorded run over its scene (GIF).

    Example: kiseki sim render run.mcap -o run.gif"""
    check_suffix("--output", output, (".gif",))
    if not run_file.is_file():
        raise FileNotFoundError(f"{run_file}: no such run file (an MCAP file of kiseki sim run)")
    if scene_file is not None and not scene_file.is_file():
        raise FileNotFoundError(f"--scene {scene_file}: no such scene file")
    run = read_run(run_file)
    recorded = run.metadata.get("scene_file", "")
    # a teaching log records its scene from its own folder, a simulated run from the cwd
    path = scene_file or resolve_scene_file(recorded, run_file.parent) or Path(recorded)
    if not str(path) or not path.is_file():
        raise FileNotFoundError(f"{run_file}: its scene file {path} is not found: give --scene")
    check_outputs({"--output": output}, {"the run's scene": path})  # named inside the run
    scene = load_scene(path)
    digest = run.metadata.get("scene_sha1")  # runs recorded before it carry none
    if digest and digest != scene.sha1:
        raise ValueError(
            f"{run_file} was recorded in {recorded or 'another scene'}, not in {path} (the "
            "scene files differ): give the scene it was recorded in"
        )
    render_run(scene, run, output)
    console.print(f"{output}: animation written")


MAX_OCTREE_VOXELS = 5e7  # a few GB of OcTree nodes; the factory fills 2.6e5 at 0.05 m


@app.command("show")
@guarded(inputs=("scene_file",), outputs=("output", "octree"))
@interruptible()
def sim_show(
    ctx: typer.Context,
    scene_file: Path = typer.Argument(..., metavar="SCENE", help="Scene YAML."),
    output: Path = typer.Option(..., "-o", "--output", help="PNG to write."),
    octree: Path | None = typer.Option(None, help="Also export the world as an OctoMap .bt."),
    resolution: float = typer.Option(
        0.05,
        parser=Metres("--resolution", *CELL_LIMITS),
        help="Voxel size of the .bt export (m); with --octree.",
    ),
) -> None:
    """Draw a scene from above (and export its OctoMap).

    Example: kiseki sim show data/worlds/factory_corridor.yaml -o corridor.png"""
    if octree is None:
        refuse_given(ctx, ["resolution"], "without --octree (the voxels of the .bt export)")
    check_suffix("--output", output, FIGURE_SUFFIXES)
    check_suffix("--octree", octree, (".bt",))  # write_binary writes OctoMap's binary .bt
    scene = load_scene(scene_file)
    if octree is not None:  # checked before anything is written
        if not isinstance(scene.world, _core.BoxWorld):
            raise ValueError(f"{scene_file}: the world is already an OctoMap")
        _, half, _ = scene.boxes.arrays()
        voxels = float(np.prod(np.ceil(2 * half / resolution) + 1, axis=1).sum())
        if voxels > MAX_OCTREE_VOXELS:
            raise ValueError(
                f"--resolution {resolution} m would fill about {voxels:.3g} voxels (at most "
                f"{MAX_OCTREE_VOXELS:.0e}): give a coarser resolution"
            )
    render_scene(scene, output)
    if octree is not None:
        tree = _core.OctreeWorld.from_boxes(scene.world, resolution)
        atomic_write(octree, tree.write_binary)
    console.print(f"{output}: scene drawn" + (f"; {octree} written" if octree else ""))
