# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki coop``: cooperative positioning: robots triangulate each other (Hirose, Nagata and
Kurazume)."""

from __future__ import annotations

import math
from pathlib import Path

import typer
from rich.console import Console

from kiseki._support.guard import guarded
from kiseki._support.interrupt import interruptible
from kiseki._support.options import Count, Degrees, Metres, Seed
from kiseki._support.outputs import FIGURE_SUFFIXES, check_suffix
from kiseki.coop import START, plan, simulate
from kiseki.coop.planner import plan_moves
from kiseki.coop.positioning import FORM1_READINGS, MAX_MOVES
from kiseki.coop.render import render_run

__all__ = ["app"]

app = typer.Typer(
    no_args_is_help=True, help="Cooperative positioning: robots triangulate each other."
)
console = Console(soft_wrap=True)  # piped: one line stays one line (grep, awk)


@app.command("simulate")
@guarded(outputs=("plot",))
@interruptible()
def coop_simulate(
    form: int | None = typer.Option(
        None,
        parser=Count("--form", 1, 2),
        help="Movement form: 1 (pair and scout, the default) or 2 (leapfrog).",
    ),
    # kiseki.coop.plan's limits: up to MAX_MOVES moves, angles of 5..85 deg (the triangles of the
    # formation degenerate beyond); an angle SD of 10 deg or more leaves nothing to triangulate
    moves: int | None = typer.Option(
        None,
        parser=Count("--moves", 1, MAX_MOVES),
        help="Moves to the goal (form 1: odd; default 15).",
    ),
    angle: float | None = typer.Option(
        None,
        parser=Degrees("--angle", 5, 85),
        help="Representative angle (deg); default: the start's width kept, as the paper.",
    ),
    reading: str | None = typer.Option(
        None, help="Form 1's reading: pair-scout (the default) or crossing."
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
    check_suffix("--plot", plot, FIGURE_SUFFIXES)
    if planner and (form, moves, angle) != (None, None, None):
        raise ValueError("--planner chooses the moves itself: drop --form, --moves and --angle")
    form = 1 if form is None else form
    if reading is not None and (planner or form != 1):
        raise ValueError("--reading does not apply to --form 2 or --planner (form 1's readings)")
    reading = FORM1_READINGS[0] if reading is None else reading
    moves = 15 if moves is None else moves
    if planner:
        the_plan = plan_moves(START, goal, math.radians(sigma))
        what = f"planner, {the_plan.moves} moves"
    else:
        the_plan = plan(
            form, moves, None if angle is None else math.radians(angle), START, goal, reading
        )
        what = (
            f"form {form}{f' ({reading})' if form == 1 else ''}, {moves} moves, "
            f"representative angle {math.degrees(the_plan.angle):.1f} deg"
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
