# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki teach``: teach a route (the factory AGV's main job, with ``kiseki playback``)."""

from __future__ import annotations

import sys
from pathlib import Path

import typer
from rich.console import Console

from kiseki._support.guard import guarded
from kiseki._support.options import Seed, refuse_given
from kiseki._support.replaced_files import refuse_replacing
from kiseki.apps.teach.keyboard import KeyScript, TerminalKeys, teach_keyboard
from kiseki.apps.teach.teaching import TEACHING_FILES, recover, teach
from kiseki.sim.scene import load_scene
from kiseki.teach.environment_map import MERGE_RULES

__all__ = ["app", "merge_rule"]

app = typer.Typer()
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


def merge_rule(value: str) -> str:
    """A checked --merge value (the taught maps' merge rule; kiseki demo's too)."""
    if value not in MERGE_RULES:
        raise ValueError(f"--merge must be {' or '.join(MERGE_RULES)}, got {value!r}")
    return value


def _check_out(out: Path, log: Path, resume: bool, overwrite: bool) -> None:
    """Before any work: --resume needs the log; without --resume or --overwrite, the folder
    holds no file a teaching run writes (the log, or a user's own map or waypoint file)."""
    if resume:
        if not log.is_file():
            raise FileNotFoundError(f"{log}: no teaching log to resume from")
    elif not overwrite:
        if log.exists():
            raise FileExistsError(
                f"{log}: a teaching log exists; --resume rebuilds from it, --overwrite replaces it"
            )
        refuse_replacing(
            out, TEACHING_FILES, "--out", "give a new or empty folder as --out, or add --overwrite"
        )


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
    overwrite: bool = typer.Option(
        False, help="Replace the teaching log, maps and waypoint file OUT holds."
    ),
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
    if merge is not None:
        merge_rule(merge)
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
    _check_out(out, log, resume, overwrite)
    if resume:
        result = recover(scene, log, out, merge)
    elif keyboard:
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
    if result.waypoints is None:
        names = "none (no waypoints.yaml: playback and serve need a waypoint marked with m)"
    console.print(
        f"{out}: {result.steps} steps, waypoints {names}; maps "
        + ", ".join(str(p) for p in result.maps.values())
        + f" ({result.merge} merge)"
    )
    for band, t in (result.truth or {}).items():
        console.print(
            f"  {band} map against the scene's truth: {100 * t['erased_share']:.1f} % of "
            f"{t['obstacle_cells']} obstacle cells in reach erased, "
            f"{100 * t['false_occupied_share']:.1f} % of {t['visible_free_cells']} visible "
            "free cells occupied (a one-cell shift forgiven); cell by cell "
            f"{100 * t['erased_share_cellwise']:.1f} % and "
            f"{100 * t['false_occupied_share_cellwise']:.1f} %"
        )
