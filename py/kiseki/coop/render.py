# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Pictures of a cooperative positioning run: the robots' planned paths, the measurements of
each move, and the spread of the estimates over the runs as error ellipses."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from kiseki.coop.simulation import CoopRun
from kiseki.plots import new_figure, save_figure

if TYPE_CHECKING:
    from matplotlib.patches import Ellipse

COLOURS = ("tab:blue", "tab:orange", "tab:green")


def _ellipse(points: np.ndarray, scale: float, colour: str) -> Ellipse | None:
    if len(points) < 3:
        return None
    cov = np.cov(points.T)
    values, vectors = np.linalg.eigh(cov)
    values = np.clip(values, 0.0, None)
    angle = np.degrees(np.arctan2(vectors[1, 1], vectors[0, 1]))
    width, height = 2 * 2 * scale * np.sqrt(values[::-1])  # 2 SD each side, magnified
    from matplotlib.patches import Ellipse  # imported when a picture is drawn

    return Ellipse(points.mean(axis=0), width, height, angle=angle, fill=False, color=colour, lw=1)


def render_run(run: CoopRun, path: str | os.PathLike, magnify: float | None = None) -> Path:
    """Draws the group's paths (planned moves as arrows, the standing robots' lines of sight as
    thin lines) and, at every robot's place after each move, the 2-SD ellipse of its estimates
    over the runs, magnified so that it shows (the factor is in the legend)."""
    truth, est = run.truth, run.estimates
    spread = max(float(np.abs(est - truth[None]).max()), 1e-9)
    extent = float(np.ptp(truth[..., 1])) or 1.0
    if magnify is None:
        magnify = max(1.0, round(0.04 * extent / spread))
    fig = new_figure(figsize=(5.5, 8), dpi=120)
    ax = fig.subplots()
    for k, move in enumerate(run.plan.steps):
        before, after = truth[k], truth[k + 1]
        for s in move.standing:
            ax.plot(*np.stack([before[s], after[move.robot]]).T, color="0.8", lw=0.6, zorder=1)
        ax.annotate(
            "",
            after[move.robot],
            before[move.robot],
            arrowprops={"arrowstyle": "->", "color": COLOURS[move.robot], "lw": 1.2},
        )
        e = _ellipse(est[:, k + 1, move.robot], magnify, COLOURS[move.robot])
        if e is not None:
            ax.add_patch(e)
    for r in range(3):
        ax.plot(*truth[0, r], "s", color=COLOURS[r], label=f"robot {r + 1}")
    goal = run.plan.steps[-1].target
    ax.plot(*goal, "r*", ms=12, label="goal")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    what = (
        f"planner, {run.plan.moves} moves"
        if run.plan.form == 0
        else f"form {run.plan.form}, {run.plan.moves} moves, {np.degrees(run.plan.angle):.0f} deg"
    )
    ax.set_title(f"{what}; 2-SD ellipses x{magnify:g}", fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    return save_figure(fig, path)
