# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The terrain experiments' figure: the cost surface (eq. 4) over x, y at the best z, and the
S-DEM's cut at theta = -17 deg (the paper's Figs. 11-12: the virtual S-DEM of the previous map
seen from the estimate beside the current map), before and after the plane removal."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kiseki.plots import new_figure
from kiseki.terrain import sdem_from_points
from kiseki_experiments.terrain.terrain_common import slice_row

__all__ = ["SLICE_DEG", "draw_match", "virtual_sdem"]

SLICE_DEG = -17.0
"""Figs. 11-12's cut."""


def virtual_sdem(previous, translation):
    """The previous level S-DEM seen from ``translation`` (the virtual S-DEM, eq. 3)."""
    points, _ = previous.to_points()
    return sdem_from_points(points - np.asarray(translation, dtype=float), None, previous.grid)


def _cut(ax, maps_pair, translation, title: str) -> None:
    previous, current = maps_pair
    phi, r_virtual = slice_row(virtual_sdem(previous, translation), SLICE_DEG)
    _, r_current = slice_row(current, SLICE_DEG)
    ax.plot(phi, r_virtual, ".", ms=3, label="virtual S-DEM (previous, at the estimate)")
    ax.plot(phi, r_current, ".", ms=3, label="current S-DEM")
    ax.set_xlabel("phi (deg)")
    ax.set_ylabel("r (m)")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)


def draw_match(path: Path, maps, found, step: float, title: str) -> None:
    """Writes the figure (atomically) for one seed's maps and matches; ``found[0]`` is drawn."""
    first = found[0]
    fig = new_figure(figsize=(13, 4.2), dpi=110)
    axes = fig.subplots(1, 3)
    ax = axes[0]
    if first.costs is not None:
        k = int(round((first.translation[2] + 0.30) / step))
        surface = first.costs[:, :, min(max(k, 0), first.costs.shape[2] - 1)].T
        finite = np.isfinite(surface)
        shown = np.where(finite, surface, np.nan)
        image = ax.imshow(
            shown, origin="lower", aspect="auto", extent=(0.0, 0.70, -0.50, 0.50), cmap="viridis"
        )
        fig.colorbar(image, ax=ax, fraction=0.046)
    ax.plot(*maps.truth[:2], "r+", ms=12, mew=2, label="truth")
    ax.plot(*first.translation[:2], "mx", ms=9, mew=2, label="estimate")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"{title}: cost ({first.method}) at z = {first.translation[2]:.2f} m", fontsize=9)
    ax.legend(fontsize=7)
    _cut(axes[1], (maps.previous, maps.current), first.translation,
         f"theta = {SLICE_DEG:g} deg before removal")  # fmt: skip
    _cut(axes[2], first.kept_maps, first.translation,
         f"theta = {SLICE_DEG:g} deg after {first.method} removal")  # fmt: skip
    fig.tight_layout()
    tmp = path.with_name(path.name + ".tmp.png")
    fig.savefig(tmp)
    os.replace(tmp, path)
