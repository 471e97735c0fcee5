# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The ``kiseki`` command line: one command with subcommands.

Errors in what the user gave (a missing or corrupt file, a bad value) print one line
``kiseki: error: ...`` on stderr and exit with status 1; usage errors (an unknown option, a
missing argument) exit with status 2; an internal error (a bug) prints its traceback and exits
with status 3.
"""

from __future__ import annotations

import sys
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from kiseki._support.guard import Derived, Rewrites, guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import (
    BEAM_LIMIT,
    CELL_LIMITS,
    PARTICLE_LIMIT,
    REACH_LIMIT,
    RUN_LIMIT,
    SIM_SECONDS_LIMIT,
    THREAD_LIMIT,
    WORKER_LIMIT,
    Count,
    Degrees,
    Fraction,
    Metres,
    Seconds,
    Seed,
    refuse_given,
)
from kiseki._support.outputs import FIGURE_SUFFIXES, check_outputs, check_suffix
from kiseki.cli_magnetic import magnetic_app
from kiseki.cli_speed import speed_app
from kiseki.cli_terrain import terrain_app
from kiseki.errors import KisekiError
from kiseki.filters import GlobalConfig, LocalizeConfig

app = typer.Typer(
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    help="kiseki: mobile-robot localization and navigation toolkit.",
)
map_app = typer.Typer(no_args_is_help=True, help="Occupancy-grid maps: build, render, inspect.")
app.add_typer(map_app, name="map")
experiment_app = typer.Typer(
    no_args_is_help=True, help="Experiments: one command per paper table or figure."
)
app.add_typer(experiment_app, name="experiment")
sim_app = typer.Typer(no_args_is_help=True, help="Simulation: scenes, runs logged to MCAP.")
app.add_typer(sim_app, name="sim")
coop_app = typer.Typer(
    no_args_is_help=True, help="Cooperative positioning: robots triangulate each other."
)
app.add_typer(coop_app, name="coop")
app.add_typer(speed_app, name="speed")
app.add_typer(magnetic_app, name="magnetic")
app.add_typer(terrain_app, name="terrain")
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


def _version_callback(value: bool) -> None:
    if value:
        from kiseki.core import library_versions

        versions = library_versions()
        others = ", ".join(f"{k} {v}" for k, v in sorted(versions.items()) if k != "kiseki")
        typer.echo(f"kiseki {versions['kiseki']} ({others})")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version_callback, is_eager=True, help="Show the version."
    ),
) -> None:
    """kiseki: mobile-robot localization and navigation toolkit."""


def _merge_rule(value: str) -> str:
    """A checked --merge value (the taught maps' merge rule)."""
    from kiseki.teach.environment_map import MERGE_RULES

    if value not in MERGE_RULES:
        raise ValueError(f"--merge must be {' or '.join(MERGE_RULES)}, got {value!r}")
    return value


# files the commands read or write that no option names (kiseki._support.guard)
_MAP_IMAGE = Derived("--output's image", lambda a: a["output"].with_suffix(".pgm"))
_TAUGHT_WAYPOINTS = Derived(
    "--taught's waypoint file", lambda a: a["taught"] / "waypoints.yaml" if a["taught"] else None
)
_CONFIG_BESIDE = Derived(
    "its config", lambda a: a["output"].with_name(a["output"].stem + ".config.yaml")
)
# kiseki serve rewrites files of its taught run in place (the waypoint file, on a rename, by
# itself); --history may be the route history there, its default
_SERVED = Rewrites("taught", ("route_history.json",))
_GLOBAL_REPORT = Derived(
    "its report", lambda a: a["output"].with_suffix(".json") if a["global_start"] is True else None
)


@map_app.command("from-log")
@guarded(inputs=("log",), outputs=("output", _MAP_IMAGE, "render"))
@interruptible()
def map_from_log(
    ctx: typer.Context,
    log: Path = typer.Argument(
        ...,
        help="CARMEN log (.log, .log.gz), kiseki run (.mcap), ROS 1 bag (.bag) or ROS 2 bag "
        "(folder, .db3 or .mcap).",
    ),
    output: Path = typer.Option(..., "-o", "--output", help="Map YAML to write (image beside)."),
    resolution: float = typer.Option(
        0.05, parser=Metres("--resolution", *CELL_LIMITS), help="Cell size in metres."
    ),
    usable_range: float = typer.Option(
        30.0,
        parser=Metres("--usable-range", 0, REACH_LIMIT, lo_open=True),
        help="Free space is marked at most this far (m); --rules log-odds only.",
    ),
    render: Path | None = typer.Option(None, help="Also draw the map and trajectory to this PNG."),
    rules: str = typer.Option(
        "log-odds",
        help="log-odds (occupancy probabilities), teaching (the thesis' merge rules: the map "
        "the space observation model expects; use --resolution 0.1) or evidence (a teaching map "
        "whose cells turn free only when their free observations outweigh their hits).",
    ),
    scan_topic: str = typer.Option("/scan", help="ROS bags: the sensor_msgs/LaserScan topic."),
    odom_topic: str = typer.Option(
        "/odom", help="ROS bags: the nav_msgs/Odometry topic (if absent: odom -> base on /tf)."
    ),
    reference_topic: str | None = typer.Option(
        None, help="ROS bags: a nav_msgs/Odometry topic of reference poses, e.g. /ground_truth."
    ),
) -> None:
    """Build an occupancy grid from a log's poses and scans and save it as a ROS map.

    Example: kiseki map from-log run.mcap -o map.yaml --render map.png"""
    from kiseki.datasets import open_scans
    from kiseki.io.ros_map import load_map, save_map
    from kiseki.mapping import MapBuildConfig, endpoint_agreement, map_of_log
    from kiseki.plots import render_map
    from kiseki.teach.environment_map import build_teaching_map

    if rules not in ("log-odds", "teaching", "evidence"):
        raise ValueError(f"--rules must be log-odds, teaching or evidence, got {rules!r}")
    if rules != "log-odds":  # teaching maps merge 8 m local maps: they have no usable range
        refuse_given(ctx, ["usable_range"], f"to --rules {rules} (only to log-odds)")
    check_suffix("--output", output, (".yaml", ".yml"))
    check_suffix("--render", render, FIGURE_SUFFIXES)
    config = MapBuildConfig(resolution=resolution, usable_range=usable_range)
    start = time.perf_counter()
    scans = open_scans(log, scan_topic, odom_topic, reference_topic)
    if not scans.has_reference_poses:
        hint = ""
        if reference_topic is None:
            from kiseki.datasets.rosbag import is_ros_bag

            if is_ros_bag(log):
                hint = " (a bag's reference poses come from --reference-topic, e.g. /ground_truth)"
        raise ValueError(f"{log}: the log has no reference poses to build a map from{hint}")
    if rules in ("teaching", "evidence"):
        grid = build_teaching_map(
            scans.poses,
            scans.ranges,
            scans.angles,
            scans.max_range,
            resolution,
            rule="thesis" if rules == "teaching" else "evidence",
            progress=True,
        )
    else:
        grid = map_of_log(scans, config, True)
    seconds = time.perf_counter() - start
    saved = load_map(save_map(grid, output))
    share = endpoint_agreement(saved, scans.poses, scans.ranges, scans.angles, scans.max_range)
    if render is not None:
        render_map(saved, render, trajectory=scans.poses, title=f"{log.name}")
    console.print(
        f"{output}: {grid.width} x {grid.height} cells at {grid.resolution} m from "
        f"{len(scans)} scans ({scans.invalid_ranges} invalid range readings skipped) in "
        f"{seconds:.2f} s; {100 * share:.1f} % of scan endpoints on or next to occupied cells"
    )


def _read_trajectory(path: Path) -> np.ndarray:
    """x, y[, theta] rows from a CSV with a header naming x and y, or poses of a CARMEN log."""
    if path.name.endswith((".log", ".log.gz")):
        from kiseki.datasets import read_carmen_log

        return read_carmen_log(path).scans.poses
    from kiseki.io.trajectory_csv import read_trajectory_csv

    return read_trajectory_csv(path)


@map_app.command("render")
@guarded(inputs=("map_file", "trajectory"), outputs=("output",))
@interruptible()
def map_render(
    map_file: Path = typer.Argument(..., metavar="MAP", help="ROS map YAML or CMU .dat map."),
    output: Path = typer.Option(..., "-o", "--output", help="PNG to write."),
    trajectory: Path | None = typer.Option(
        None, help="Trajectory to overlay: CSV with x,y columns, or a CARMEN log."
    ),
) -> None:
    """Draw a map (and a trajectory over it) to a PNG.

    Example: kiseki map render data/maps/factory_corridor.yaml -o corridor.png"""
    from kiseki.io.ros_map import load_map
    from kiseki.plots import render_map

    check_suffix("--output", output, FIGURE_SUFFIXES)
    grid = load_map(map_file)
    path = _read_trajectory(trajectory) if trajectory is not None else None
    render_map(grid, output, trajectory=path, title=map_file.name)
    console.print(f"{output}: {grid.width} x {grid.height} map drawn")


@map_app.command("convert")
@guarded(inputs=("map_file",), outputs=("output", _MAP_IMAGE))
@interruptible()
def map_convert(
    map_file: Path = typer.Argument(..., metavar="MAP", help="ROS map YAML or CMU .dat(.gz) map."),
    output: Path = typer.Option(..., "-o", "--output", help="ROS map YAML to write (PGM beside)."),
) -> None:
    """Save a map (e.g. the CMU Wean .dat.gz) as a ROS map YAML + PGM (trinary).

    Example: kiseki map convert data/maps/factory_corridor.yaml -o corridor.yaml"""
    from kiseki.grid import grid_summary
    from kiseki.io.ros_map import load_map, save_map

    check_suffix("--output", output, (".yaml", ".yml"))
    grid = load_map(map_file)
    save_map(grid, output)
    summary = grid_summary(grid)
    console.print(
        f"{output}: {grid.width} x {grid.height} cells at {grid.resolution} m; "
        f"{summary['free']} free, {summary['occupied']} occupied, {summary['unknown']} unknown"
    )


@map_app.command("info")
@guarded(inputs=("map_file",))
def map_info(
    map_file: Path = typer.Argument(..., metavar="MAP", help="ROS map YAML or CMU .dat map."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Print a map's size, resolution, origin and cell counts: a table on a terminal,
    tab-separated field/value lines when piped, or JSON with --json.

    Example: kiseki map info data/maps/factory_corridor.yaml --json"""
    from kiseki._support.table import show_fields
    from kiseki.grid import grid_summary
    from kiseki.io.ros_map import load_map

    summary = grid_summary(load_map(map_file))
    show_fields(str(map_file), summary, as_json=as_json, console=console)


@app.command("demo")
@guarded(inputs=("scene",), output_folders=("out",))
@interruptible()
def demo(
    out: Path = typer.Option(Path("results/demo"), help="Folder for the run, maps and figures."),
    scene: Path = typer.Option(
        Path("data/worlds/factory_turn.yaml"), "--scene", help="Scene with a taught route."
    ),
    seed: int = typer.Option(0, parser=Seed(), help="Seed of every noise source of the run."),
    particles: int = typer.Option(
        1000,
        parser=Count("--particles", 1, PARTICLE_LIMIT),
        help="Particles of the localization filter.",
    ),
    merge: str = typer.Option(
        "thesis", help="Merge rule of the taught maps: thesis or evidence (see kiseki teach)."
    ),
) -> None:
    """The main job: teach the factory route with a turn, measure the taught maps against the
    scene's truth, play the route back with each method, and print the thesis' Table 4.5-style
    comparison.

    Example: kiseki demo --out results/demo --seed 0"""
    from kiseki.demo import run_demo

    run_demo(scene, out, seed, console, particles, _merge_rule(merge))


@experiment_app.command("list")
@guarded()  # no file
def experiment_list(
    as_json: bool = typer.Option(False, "--json", help="Print a JSON list of objects."),
) -> None:
    """List the registered experiments: a table on a terminal, tab-separated lines (a header,
    then one experiment a line) when piped, or JSON with --json.

    Example: kiseki experiment list | cut -f1"""
    import json

    from kiseki_experiments.harness.registry import all_experiments  # here: start-up time

    columns = ("name", "paper", "table/figure", "description", "default trials")
    rows = [
        (name, e.paper, e.artefact, e.description, str(e.default_runs))
        for name, e in sorted(all_experiments().items())
    ]
    if as_json:
        keys = ("name", "paper", "artefact", "description", "default_runs")
        items = [dict(zip(keys, row[:4] + (int(row[4]),), strict=True)) for row in rows]
        typer.echo(json.dumps(items, indent=2))
    elif not sys.stdout.isatty():
        for row in (columns, *rows):
            typer.echo("\t".join(" ".join(str(v).split()) for v in row))
    else:
        table = Table(title="kiseki experiments")
        for column in columns:
            table.add_column(column)
        for row in rows:
            table.add_row(*row)
        console.print(table)


@experiment_app.command("run")
@guarded(output_folders=("out",))
@interruptible("the finished trials are kept: --resume --out RUN_FOLDER runs only the missing ones")
def experiment_run(
    name: str = typer.Argument(..., help="Experiment name (see: kiseki experiment list)."),
    runs: int | None = typer.Option(
        None, "--runs", parser=Count("--runs", 1, RUN_LIMIT), help="Number of trials."
    ),
    seed: int | None = typer.Option(
        None, "--seed", parser=Seed(), help="Run seed (trial seeds derive from it)."
    ),
    overrides: list[str] = typer.Option([], "--set", help="Config override key=value (repeat)."),
    workers: int | None = typer.Option(
        None,
        "--workers",
        parser=Count("--workers", 1, WORKER_LIMIT),
        help="Local Dask cluster of N workers.",
    ),
    scheduler: str | None = typer.Option(None, "--scheduler", help="Dask scheduler tcp://H:P."),
    out: Path | None = typer.Option(None, "--out", help="Results folder (default results/NAME/…)."),
    resume: bool = typer.Option(False, "--resume", help="Run only the missing trials of a run."),
) -> None:
    """Run an experiment's trials and write its results folder. NAME may be a pattern
    ('speed-*'): every matching experiment runs in turn, each into its own results folder
    (--out/NAME with --out), with its default trials.

    Example: kiseki experiment run 'speed-*' --seed 0"""
    import fnmatch

    # here, not at the top: start-up time (the registry imports every experiment)
    from kiseki_experiments.harness.registry import all_experiments
    from kiseki_experiments.harness.runner import run_experiment

    names, pattern = [name], any(c in name for c in "*?[")
    if pattern:
        names = sorted(fnmatch.filter(all_experiments(), name))
        if not names:
            raise KisekiError(f"no experiment matches {name!r} (see: kiseki experiment list)")
        if runs is not None or overrides or resume:
            raise KisekiError("a pattern runs several experiments: no --runs, --set or --resume")
    for each in names:
        where = out / each if out is not None and pattern else out
        result = run_experiment(each, runs, seed, overrides, workers, scheduler, where, resume)
        console.print(
            f"{result.run_dir}: {result.runs} trials ({result.executed} run now, "
            f"{result.failed} failed) in {result.wall_seconds:.1f} s"
        )


@sim_app.command("run")
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
    seed: int = typer.Option(0, parser=Seed(), help="Seed of every noise source of the run."),
    variant: str = typer.Option("teach", help="Scene variant: teach or playback."),
    overwrite: bool = typer.Option(False, help="Replace an existing output file."),
) -> None:
    """Simulate a scene and log the run (ground truth, odometry, sensors) to MCAP.

    Example: kiseki sim run data/worlds/factory_corridor.yaml -o run.mcap --seed 0"""
    from kiseki.sim.run import SimConfig, read_commands, simulate
    from kiseki.sim.scene import load_scene

    if controller not in ("route", "commands"):
        raise ValueError(f"--controller must be route or commands, got {controller!r}")
    if (controller == "commands") != (commands is not None):
        raise ValueError("--commands FILE goes with --controller commands, and only with it")
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
        c = summary.collision
        console.print(
            f"COLLISION at t = {c.t:.2f} s: {c.robot} hit {c.hit} at "
            f"({c.contact[0]:.3f}, {c.contact[1]:.3f}); the run ended there"
        )


@sim_app.command("render")
@guarded(inputs=("run_file", "scene_file"), outputs=("output",))
@interruptible()
def sim_render(
    run_file: Path = typer.Argument(..., metavar="RUN", help="MCAP file of a run."),
    output: Path = typer.Option(..., "-o", "--output", help="GIF to write."),
    scene_file: Path | None = typer.Option(None, "--scene", help="Scene (default: from run)."),
) -> None:
    """Animate a recorded run over its scene (GIF).

    Example: kiseki sim render run.mcap -o run.gif"""
    from kiseki.io.runlog import read_run
    from kiseki.sim.render import render_run
    from kiseki.sim.scene import load_scene
    from kiseki.teach.scene_identity import resolve_scene_file

    check_suffix("--output", output, (".gif",))
    run = read_run(run_file)
    recorded = run.metadata.get("scene_file", "")
    # a teaching log records its scene from its own folder, a simulated run from the cwd
    path = scene_file or resolve_scene_file(recorded, run_file.parent) or Path(recorded)
    if not str(path) or not path.is_file():
        raise FileNotFoundError(f"{run_file}: its scene file {path} is not found: give --scene")
    check_outputs({"--output": output}, {"the run's scene": path})  # named inside the run
    render_run(load_scene(path), run, output)
    console.print(f"{output}: animation written")


MAX_OCTREE_VOXELS = 5e7  # a few GB of OcTree nodes; the factory fills 2.6e5 at 0.05 m


@sim_app.command("show")
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
    from kiseki import _core
    from kiseki.sim.render import render_scene
    from kiseki.sim.scene import load_scene

    if octree is None:
        refuse_given(ctx, ["resolution"], "without --octree (the voxels of the .bt export)")
    check_suffix("--output", output, FIGURE_SUFFIXES)
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
        from kiseki._support.atomic import atomic_write

        tree = _core.OctreeWorld.from_boxes(scene.world, resolution)
        atomic_write(octree, tree.write_binary)
    console.print(f"{output}: scene drawn" + (f"; {octree} written" if octree else ""))


@coop_app.command("simulate")
@guarded(outputs=("plot",))
@interruptible()
def coop_simulate(
    form: int | None = typer.Option(
        None,
        parser=Count("--form", 1, 2),
        help="Movement form: 1 (pair and scout, the default) or 2 (leapfrog).",
    ),
    # kiseki.coop.plan's limits: up to 1000 moves, angles of 5..85 deg (the triangles of the
    # formation degenerate beyond); an angle SD of 10 deg or more leaves nothing to triangulate
    moves: int | None = typer.Option(
        None,
        parser=Count("--moves", 1, 1000),
        help="Moves to the goal (form 1: odd; default 15).",
    ),
    angle: float | None = typer.Option(
        None,
        parser=Degrees("--angle", 5, 85),
        help="Representative angle (deg); default: the start's width kept, as the paper.",
    ),
    runs: int = typer.Option(100, parser=Count("--runs", 1, 1_000_000), help="Noisy runs."),
    sigma: float = typer.Option(
        0.1,
        parser=Degrees("--sigma", 0, 10, hi_open=True),
        help="SD of each measured angle (deg).",
    ),
    seed: int = typer.Option(0, parser=Seed(), help="Seed of the angle noise."),
    # a goal within a kilometre: the paper's lies 10 m ahead, and the error grows with the moves
    goal: tuple[float, float] = typer.Option(
        (0.0, 10.0), parser=Metres("--goal", -1000, 1000), help="Goal x y (m)."
    ),
    plot: Path | None = typer.Option(None, help="Draw the paths and error ellipses to this PNG."),
    planner: bool = typer.Option(
        False, "--planner", help="Let the move planner choose the moves (not --form/--moves)."
    ),
) -> None:
    """Three robots advance to the goal by turns (Hirose, Nagata and Kurazume); prints the
    error at the goal over the runs.

    Example: kiseki coop simulate --form 2 --moves 7 --plot g.png"""
    import math

    from kiseki.coop import START, plan, simulate
    from kiseki.coop.render import render_run

    check_suffix("--plot", plot, FIGURE_SUFFIXES)
    if planner and (form, moves, angle) != (None, None, None):
        raise ValueError("--planner chooses the moves itself: drop --form, --moves and --angle")
    form = 1 if form is None else form
    moves = 15 if moves is None else moves
    if planner:
        from kiseki.coop.planner import plan_moves

        the_plan = plan_moves(START, goal, math.radians(sigma))
        what = f"planner, {the_plan.moves} moves"
    else:
        the_plan = plan(form, moves, None if angle is None else math.radians(angle), START, goal)
        what = (
            f"form {form}, {moves} moves, representative angle "
            f"{math.degrees(the_plan.angle):.1f} deg"
        )
    run = simulate(the_plan, runs, math.radians(sigma), seed)
    e = run.goal_errors
    console.print(
        f"{what}, {runs} runs, {sigma} deg: error at the goal mean {1000 * e.mean():.1f} mm, SD "
        f"{1000 * e.std():.1f} mm, max {1000 * e.max():.1f} mm",
        soft_wrap=True,  # one line, also when piped
    )
    if plot is not None:
        render_run(run, plot)
        console.print(f"{plot}: paths and error ellipses drawn", soft_wrap=True)


@app.command("teach")
@guarded(inputs=("scene_file", "keys"), output_folders=("out",))
def teach_command(
    ctx: typer.Context,
    scene_file: Path = typer.Argument(
        ..., metavar="SCENE", help="Scene YAML (with a route unless --keyboard)."
    ),
    out: Path = typer.Option(..., "-o", "--out", help="Folder for maps, waypoints and the log."),
    seed: int = typer.Option(0, parser=Seed(), help="Seed of the run's noise."),
    resume: bool = typer.Option(False, help="Rebuild maps and waypoints from OUT/teach.mcap."),
    overwrite: bool = typer.Option(False, help="Replace an existing teaching log."),
    keyboard: bool = typer.Option(
        False,
        help="Push the robot from the terminal instead of along the route: w/s or Up/Down "
        "speed +-0.1 m/s, a/d or Left/Right turn +-0.1 rad/s, space stop, m mark waypoint "
        "P0, P1, ..., q finish.",
    ),
    keys: Path | None = typer.Option(
        None,
        help="With --keyboard: read timed keys from this file (lines TIME KEY [KEY ...], TIME "
        "in simulated seconds, ending with q) instead of the terminal.",
    ),
    merge: str | None = typer.Option(
        None,
        help="Merge rule of the environment maps: thesis (L free over M occupied -> free; the "
        "default) or evidence (a cell turns free only when its free observations outweigh its "
        "hits). With --resume: the rule the log was taught with, unless given.",
    ),
) -> None:
    """Teach a route: push the robot along the scene's route (simulated) or from the keyboard,
    build the environment maps with the thesis' merge rules (or --merge evidence), record the
    waypoints and measure the maps against the scene's truth (map_truth.json); the run is
    logged as it goes.

    Example: kiseki teach data/worlds/factory_corridor.yaml -o taught"""
    from kiseki.apps.teach.teaching import recover, teach
    from kiseki.sim.scene import load_scene

    if merge is not None:
        _merge_rule(merge)
    if resume:  # the run is rebuilt from its log, as it was taught (a merge rule may be given)
        refuse_given(
            ctx,
            ["seed", "overwrite", "keyboard", "keys"],
            "with --resume (it rebuilds the maps and waypoints from OUT/teach.mcap)",
        )
    if keys is not None and not keyboard:
        raise ValueError("--keys FILE goes with --keyboard")
    if keyboard and keys is None and not resume and not sys.stdin.isatty():
        raise ValueError("--keyboard needs a terminal on stdin (or --keys FILE of timed keys)")
    scene = load_scene(scene_file)
    log = out / "teach.mcap"
    if resume:
        if not log.is_file():
            raise FileNotFoundError(f"{log}: no teaching log to resume from")
        result = recover(scene, log, out, merge)
    elif log.exists() and not overwrite:
        raise FileExistsError(
            f"{log}: a teaching log exists; --resume rebuilds from it, --overwrite replaces it"
        )
    elif keyboard:
        from kiseki.apps.teach.keyboard import KeyScript, TerminalKeys, teach_keyboard

        source = KeyScript(keys) if keys is not None else TerminalKeys(sys.stdin.fileno(), 0.1)
        try:
            with source:
                result = teach_keyboard(
                    scene, out, source, seed, overwrite=overwrite, merge=merge or "thesis"
                )
        except (KeyboardInterrupt, SystemExit) as stop:  # Ctrl-C; SIGTERM exits 143
            typer.echo(
                f"kiseki: interrupted; {log} is kept: add --resume to build the maps and "
                "waypoints from it",
                err=True,
            )
            raise typer.Exit(stop.code if isinstance(stop, SystemExit) else 130) from None
    else:
        result = teach(
            scene, out, seed, overwrite=overwrite, progress=True, merge=merge or "thesis"
        )
    names = ", ".join(m["name"] for m in result.marks)
    console.print(
        f"{out}: {result.steps} steps, waypoints {names or 'none'}; maps "
        + ", ".join(str(p) for p in result.maps.values())
        + f" ({result.merge} merge)"
    )
    for band, t in (result.truth or {}).items():
        console.print(
            f"  {band} map against the scene's truth: {100 * t['erased_share']:.1f} % of "
            f"{t['obstacle_cells']} obstacle cells in reach erased, "
            f"{100 * t['false_occupied_share']:.1f} % of {t['visible_free_cells']} visible "
            "free cells occupied"
        )


@app.command("playback")
@guarded(
    inputs=("scene_file", "taught", _TAUGHT_WAYPOINTS, "waypoints", "map_file"),
    outputs=("log",),
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
    method: str = typer.Option("proposal2", help="conventional, proposal1, proposal2 or both."),
    seed: int = typer.Option(0, parser=Seed(), help="Seed of the run's noise."),
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

    from kiseki.apps.teach import PlaybackConfig, playback
    from kiseki.apps.teach.teaching import load_route
    from kiseki.io.ros_map import load_map
    from kiseki.sim.scene import load_scene
    from kiseki.teach.local_maps import METHODS
    from kiseki.teach.scene_identity import check_scene, taught_scene_of

    if (taught is None) == (waypoints is None):
        raise ValueError("give either --taught FOLDER or --waypoints FILE (with --map MAP.yaml)")
    if taught is not None and map_file is not None:
        raise ValueError("--map goes with --waypoints, not with --taught")
    if speed_limit not in SPEED_LIMITS:
        raise ValueError(f"--speed-limit must be {', '.join(SPEED_LIMITS)}, got {speed_limit!r}")
    config = PlaybackConfig(method=method, seed=seed)
    band, _ = METHODS[method]
    names = [n.strip() for n in route.split(",")]
    if taught is not None:
        waypoints = taught / "waypoints.yaml"
    map_path, marks = load_route(waypoints, band, names, map_file)
    if not scene_file.is_file():
        raise FileNotFoundError(f"{scene_file}: scene file not found")
    taught_scene = taught_scene_of(waypoints)
    identity = check_scene(taught_scene, scene_file, variant)
    if log is not None and log.exists():
        raise FileExistsError(f"--log {log} exists; give a new file")
    scene, environment = load_scene(scene_file, "playback"), load_map(map_path)
    limiter = _speed_limiter(speed_limit, scene, environment, config.speed)
    result = playback(scene, environment, marks, config, limiter, log, taught_scene, variant)
    console.print(_stop_summary(method, result, marks[-1]))
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


SPEED_LIMITS = ("none", "occlusion", "occlusion-width")


def _stop_summary(method: str, result, goal: dict) -> str:
    """Where a playback stopped: estimated, against the goal, and true, against where the goal
    was taught when the waypoint file records it ('truth' is optional: a hand-made file or a
    real robot has none)."""
    import math

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
    """The --speed-limit limiter on the taught map (kiseki.speed; playback never imports it)."""
    if name == "none":
        return None
    sensors = scene.robot_specs[0]["sensors"]
    if not any(isinstance(s, dict) and s.get("type") == "laser" for s in sensors):
        raise ValueError(f"--speed-limit {name}: scene {scene.path} has no laser")
    try:
        from kiseki.speed import SpeedLimiter, SpeedLimiterConfig
    except ImportError as err:
        raise RuntimeError(f"--speed-limit {name} needs kiseki.speed ({err})") from None
    config = SpeedLimiterConfig(
        v_max=v_max, use_occlusion=True, use_width=name == "occlusion-width"
    )
    return SpeedLimiter(grid, config)


@app.command("serve")
@guarded(inputs=(_SERVED, "scene"), outputs=("history",))
def serve_command(
    taught: Path = typer.Option(..., help="Folder written by kiseki teach (or kiseki demo's)."),
    scene: Path | None = typer.Option(
        None, help="Scene YAML the run was taught in (default: the one its log records)."
    ),
    method: str = typer.Option("both", help="conventional, proposal1, proposal2 or both."),
    host: str = typer.Option("127.0.0.1", help="Address to bind; beyond loopback a token."),
    port: int = typer.Option(8000, parser=Count("--port", 1, 65_535), help="TCP port."),
    # at most an hour at the goal (the page waits for the robot's return), and at most 1000x
    # real time (a 10 Hz robot would step 10,000 times a wall-clock second)
    dwell: float = typer.Option(
        5.0,
        parser=Seconds("--dwell", 0, 3600),
        help="Seconds the robot waits at the goal (part taken).",
    ),
    speed_up: float = typer.Option(
        1.0,
        parser=Fraction("--speed-up", 0, 1000, lo_open=True),
        help="Simulated seconds per wall-clock second.",
    ),
    particles: int = typer.Option(
        1000,
        parser=Count("--particles", 1, PARTICLE_LIMIT),
        help="Particles of the localization filter.",
    ),
    seed: int = typer.Option(0, parser=Seed(), help="Seed of the run's noise."),
    history: Path | None = typer.Option(
        None,
        help="JSON file of the finished routes: loaded at start, rewritten (atomically) after "
        "each route (default: route_history.json in the --taught folder).",
    ),
) -> None:
    """Serve the route-instruction page and its JSON API over a taught run: a worker picks
    start, via and goal waypoints, the simulated AGV drives there, stops within 0.1 m, dwells
    and returns home, watched live over a websocket. Binding beyond loopback prints an access
    token that every API request must carry (Authorization: Bearer TOKEN).

    Example: kiseki serve --taught results/demo/teach"""
    import secrets

    from kiseki.serve import HISTORY_FILE, LOOPBACK, build_server, listening_sockets

    token = None if host in LOOPBACK else secrets.token_urlsafe(24)
    history = taught / HISTORY_FILE if history is None else history
    server = build_server(
        taught, scene, method, token, dwell, speed_up, particles, seed,
        host=host, port=port, history=history,
    )  # fmt: skip
    import uvicorn

    # bound before anything is printed: a port in use or a bad --host is one line, exit 1
    sockets = listening_sockets(host, port)
    names = ", ".join(w["name"] for w in server.taught.waypoints)
    # the token rides in the URL's fragment: the browser never sends it, so no log has it
    url = f"http://{f'[{host}]' if ':' in host else host}:{port}/"
    console.print(
        f"kiseki serve: {taught} ({method}, waypoints {names}; scene {server.scene}; history "
        f"{history}) on {url}{'' if token is None else f'#token={token}'}",
        soft_wrap=True,
    )
    if token is not None:
        console.print(f"access token: {token}  (Authorization: Bearer TOKEN)", soft_wrap=True)
    config = uvicorn.Config(server.app, host=host, port=port, log_level="warning")
    try:
        uvicorn.Server(config).run(sockets=sockets)
    except KeyboardInterrupt:  # Ctrl-C: the server has shut down (as uvicorn.run ends)
        pass
    finally:
        for sock in sockets:
            sock.close()


@app.command("localize")
@guarded(
    inputs=("log", "map_file"),
    outputs=("output", _CONFIG_BESIDE, _GLOBAL_REPORT, "plot"),
)
@interruptible()
def localize_command(
    ctx: typer.Context,
    log: Path = typer.Argument(
        ...,
        help="CARMEN log (.log, .log.gz), kiseki run (.mcap), CMU Wean robotdata log, ROS 1 bag "
        "(.bag) or ROS 2 bag (folder, .db3 or .mcap).",
    ),
    map_file: Path = typer.Option(
        ..., "--map", help="ROS map YAML of the log's building, or a CMU .dat(.gz) map."
    ),
    method: str = typer.Option(
        "likelihood-field", help="beam, likelihood-field, space-observation or odometry."
    ),
    seed: int = typer.Option(
        0, parser=Seed(), help="Seed of the filter and of the odometry noise."
    ),
    # the defaults are the configs' (LocalizeConfig; GlobalConfig with --global), shown here
    # an SD up to the step itself: beyond it the odometry says nothing of the motion
    odometry_noise: float | None = typer.Option(
        None,
        parser=Fraction("--odometry-noise", 0, 1),
        help="Odometry noise SD, fraction of each step (default "
        f"{LocalizeConfig.odometry_noise:g}); not with --global.",
    ),
    particles: int | None = typer.Option(
        None,
        parser=Count("--particles", 1, PARTICLE_LIMIT),
        help=f"Particles (default {LocalizeConfig.particles:,}; {GlobalConfig.particles:,} at the "
        "start with --global); with --kld the maximum.",
    ),
    kld: bool = typer.Option(False, "--kld", help="Adapt the particle count by KLD sampling."),
    beams: int | None = typer.Option(
        None,
        parser=Count("--beams", 0, BEAM_LIMIT, "0 = every beam"),
        help=f"Beams used per scan, nav2's max_beams (default {LocalizeConfig.beams}; "
        f"{GlobalConfig.beams} with --global); not with space-observation.",
    ),
    recovery: str | None = typer.Option(
        None,
        help="none, augmented (Augmented MCL) or resetting (expansion, then sensor resetting); "
        f"with --global from the cloud's convergence on (default {LocalizeConfig.recovery}).",
    ),
    threads: int | None = typer.Option(
        None,
        parser=Count("--threads", 0, THREAD_LIMIT, "0 = every core"),
        help=f"Threads of the filter (0 = every core; default {LocalizeConfig.threads}).",
    ),
    global_start: bool = typer.Option(
        False,
        "--global",
        help="Global localization: start uniformly over the map's free cells (no initial pose).",
    ),
    tracking_particles: int | None = typer.Option(
        None,
        parser=Count("--tracking-particles", 1, PARTICLE_LIMIT),
        help="With --global: particles kept once the cloud has converged (default "
        f"{GlobalConfig.tracking_particles:,}).",
    ),
    plot: Path | None = typer.Option(
        None, help="With --global: draw the map, the estimates and where they converged (PNG)."
    ),
    output: Path = typer.Option(
        ..., "-o", "--output", help="CSV t,x,y,theta,reliability to write."
    ),
    scan_topic: str = typer.Option("/scan", help="ROS bags: the sensor_msgs/LaserScan topic."),
    odom_topic: str = typer.Option(
        "/odom", help="ROS bags: the nav_msgs/Odometry topic (if absent: odom -> base on /tf)."
    ),
    reference_topic: str | None = typer.Option(
        None, help="ROS bags: a nav_msgs/Odometry topic of reference poses, e.g. /ground_truth."
    ),
    as_json: bool = typer.Option(
        False, "--json", help="Print the errors (and the convergence report) as one JSON object."
    ),
) -> None:
    """Localize along a log: position tracking from its first reference pose, or with --global
    from a uniform start. Prints the absolute pose error against the log's reference poses when
    it has them; with --global also the convergence report (written to OUTPUT.json too); with
    --json the same numbers as one JSON object. The settings it ran with are written beside the
    output as OUTPUT-STEM.config.yaml.

    Example: kiseki localize run.mcap --map data/maps/factory_corridor.yaml -o track.csv --json"""
    from kiseki.datasets import open_scans
    from kiseki.io.ros_map import load_map
    from kiseki.metrics import ape

    _refuse_unused_by_localize(ctx, method, global_start)

    check_suffix("--plot", plot, FIGURE_SUFFIXES)
    if not global_start:
        for name, value in (("--tracking-particles", tracking_particles), ("--plot", plot)):
            if value is not None:
                raise ValueError(f"{name} applies only with --global")
    if global_start and output.suffix.lower() == ".json":
        raise ValueError(f"{output}: the report goes to OUTPUT.json: give a .csv output")
    scans = open_scans(
        log, scan_topic=scan_topic, odom_topic=odom_topic, reference_topic=reference_topic
    )
    grid = load_map(map_file)
    reliability = np.full(len(scans), np.nan)
    shared = dict(method=method, seed=seed, particles=particles, kld=kld, beams=beams)
    shared.update(recovery=recovery, threads=threads)
    if global_start:
        from kiseki.filters import global_localize

        gconfig = GlobalConfig(**_given(**shared, tracking_particles=tracking_particles))
        saved_config = {"command": "localize --global", **asdict(gconfig)}
        result = global_localize(scans, grid, gconfig, progress=True)
        trajectory, reliability = result.estimates, result.reliability
    else:
        from kiseki.filters import localize

        config = LocalizeConfig(**_given(**shared, odometry_noise=odometry_noise))
        if not scans.has_reference_poses:
            raise ValueError(f"{log}: the log has no reference poses to start from: use --global")
        saved_config = {"command": "localize", **config.to_dict()}
        tracked = localize(scans, grid, config, progress=True)
        trajectory, reliability = tracked.estimates, tracked.reliability
    saved_config.update(log=str(log), map=str(map_file))
    _write_trajectory(output, scans.times, trajectory, reliability)
    if not global_start:
        _warn_if_off_the_map(grid, trajectory, scans, map_file)
    elif result.report.converged and result.report.fit is not None:  # from convergence on
        _warn_if_off_the_map(grid, trajectory, scans, map_file, result.report.fit.within_1_cell)
    config_path = output.with_name(output.stem + ".config.yaml")
    _write_yaml(config_path, saved_config)
    summary: dict = {"output": str(output), "poses": len(scans), "method": method}
    summary["invalid_ranges"] = scans.invalid_ranges  # skipped (kiseki.scans' rule)
    lines = [f"{output}: {len(scans)} poses; the log has no reference poses"]
    if scans.has_reference_poses:
        position = ape(trajectory, scans.poses)
        heading = ape(trajectory, scans.poses, "rotation_deg")
        summary.update(position_rmse_m=position.rmse, position_max_m=position.max)
        summary.update(heading_rmse_deg=heading.rmse)
        lines = [
            f"{output}: {len(scans)} poses; {method}: position RMSE {position.rmse:.3f} m "
            f"(max {position.max:.3f} m), heading RMSE {heading.rmse:.2f} deg"
        ]
    lines[0] += f"; {scans.invalid_ranges} invalid range readings skipped"
    if global_start:
        from kiseki.filters import describe, write_report

        report_path = write_report(result, output.with_suffix(".json"))
        lines.append(describe(result.report) + f" (report: {report_path})")
        summary.update(report_file=str(report_path), convergence=result.report.to_dict())
    _print_report(lines, summary, as_json)
    if global_start and plot is not None:
        from kiseki.filters import render_global

        render_global(grid, result, plot, title=f"{log.name}: global {method}")


def _given(**settings) -> dict:
    """The settings the command line gave (not None): the others keep their config's default,
    so that each default lives in one place (LocalizeConfig, GlobalConfig)."""
    return {name: value for name, value in settings.items() if value is not None}


def _refuse_unused_by_localize(ctx: typer.Context, method: str, global_start: bool) -> None:
    """Options the chosen method or start does not use are errors, not silently ignored."""
    if method == "odometry":  # the odometry alone: no filter, no sensor model, no start
        refuse_given(
            ctx,
            ["particles", "kld", "beams", "recovery", "threads", "global_start"],
            "to --method odometry (the odometry alone: no particle filter)",
        )
    elif method == "space-observation":  # a local map of the whole scan: no beam selection
        refuse_given(ctx, ["beams"], "to --method space-observation (it weighs the whole scan)")
    if global_start:
        refuse_given(ctx, ["odometry_noise"], "with --global (it is for logs with reference poses)")


def _print_report(lines: list[str], summary: dict, as_json: bool) -> None:
    """A command's report: its sentences for people (never wrapped when piped, so each stays
    one line for grep), or the same numbers as one JSON object with --json."""
    if as_json:
        from kiseki._support.table import show_fields

        show_fields("", summary, as_json=True)
    elif sys.stdout.isatty():
        for line in lines:
            console.print(line)
    else:
        for line in lines:
            typer.echo(line)


OFF_MAP_SHARE = 0.5  # below this share of endpoints near a wall the map is not the log's


def _warn_if_off_the_map(
    grid, trajectory: np.ndarray, scans, map_file: Path, share: float | None = None
) -> None:
    """One warning line when most scan endpoints, at the estimated poses, miss the map's walls
    (a map of another building, a 1x1 map): the poses alone look fine in such a case.
    ``share``: the share already measured (global localization's, from convergence on)."""
    from kiseki.mapping import endpoint_agreement

    if share is None:
        finite = np.isfinite(trajectory).all(axis=1)
        # endpoint_agreement's endpoints: finite readings in (0, max_range), float32 as the core
        # reads them, compared in double as it does; with none (no estimate, or every reading
        # at max_range) the share is undefined and there is nothing to warn about
        ranges = np.asarray(scans.ranges, dtype=np.float32)[finite].astype(np.float64)
        if not (np.isfinite(ranges) & (ranges > 0.0) & (ranges < scans.max_range)).any():
            return
        share = endpoint_agreement(
            grid, trajectory[finite], scans.ranges[finite], scans.angles, scans.max_range
        )
    if share < OFF_MAP_SHARE:
        typer.echo(
            f"kiseki: warning: only {100 * share:.1f} % of the scan endpoints fall on or next to "
            f"an occupied cell of {map_file} at the estimated poses: the map is probably not "
            "the log's building, or the localization is lost",
            err=True,
        )


def _write_trajectory(
    output: Path, times: np.ndarray, trajectory: np.ndarray, reliability: np.ndarray
) -> None:
    from kiseki._support.atomic import atomic_write

    rows = np.column_stack([times, trajectory, reliability])
    text = "t,x,y,theta,reliability\n" + "\n".join(
        ",".join(f"{v:.6f}" for v in row) for row in rows
    )
    atomic_write(output, lambda tmp: Path(tmp).write_text(text + "\n", encoding="utf-8"))


def _write_yaml(path: Path, doc: dict) -> None:
    import yaml

    from kiseki._support.atomic import atomic_write

    def plain(value):
        if isinstance(value, tuple | list):
            return [plain(v) for v in value]
        if isinstance(value, np.generic):
            return value.item()
        return value

    text = yaml.safe_dump({k: plain(v) for k, v in doc.items()}, sort_keys=False)
    atomic_write(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


@app.command("report")
@guarded(inputs=("results",), outputs=("output",))
@interruptible()
def report(
    results: Path = typer.Option(Path("results"), help="Results folder of the experiments."),
    output: Path = typer.Option(Path("REPRODUCTION.md"), "-o", "--output", help="File to write."),
    as_json: bool = typer.Option(False, "--json", help="Print the summary as one JSON object."),
) -> None:
    """Gather the latest result of every experiment into REPRODUCTION.md and print a summary
    (claims, how many hold, the experiments without a result): a table on a terminal,
    tab-separated field/value lines when piped, or JSON with --json.

    Example: kiseki report --results results -o REPRODUCTION.md"""
    from kiseki._support.table import show_fields
    from kiseki_experiments.harness.report import write_reproduction  # here: start-up time

    total, held, missing = write_reproduction(results, output)
    summary = {"output": str(output), "claims": total, "hold": held, "missing": missing}
    show_fields(str(output), summary, as_json=as_json, console=console)


def _terminate(signum, frame) -> None:
    """SIGTERM ends a command as Ctrl-C does, through its cleanup: files being written are
    closed properly (a run's MCAP keeps its summary) and temporary files are removed."""
    sys.exit(128 + signum)


def _warn_in_one_line(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings (a truncated MCAP read, ...) as one line for people, not Python's two."""
    text = str(message).strip().splitlines()
    typer.echo(f"kiseki: warning: {text[0] if text else category.__name__}", err=True)


EXIT_OK, EXIT_BAD_INPUT, EXIT_USAGE, EXIT_INTERNAL = 0, 1, 2, 3


def main() -> None:
    """Entry point: runs the app and turns input errors into one line and exit status 1.
    Usage errors (an unknown option, a missing argument) exit 2 (click's own); anything else
    is a bug in kiseki: its traceback, one line asking for a report, and exit status 3."""
    import signal
    import warnings

    signal.signal(signal.SIGTERM, _terminate)
    warnings.showwarning = _warn_in_one_line
    try:
        app()
    except (KisekiError, ValueError, OSError, RuntimeError, IndexError) as err:
        message = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        typer.echo(f"kiseki: error: {message}", err=True)
        sys.exit(EXIT_BAD_INPUT)
    except Exception as err:  # the last resort: a bug, not the user's input
        import traceback

        traceback.print_exc()
        typer.echo(
            f"kiseki: internal error: {type(err).__name__} (a bug in kiseki: please report it "
            "with the lines above)",
            err=True,
        )
        sys.exit(EXIT_INTERNAL)


if __name__ == "__main__":
    main()
