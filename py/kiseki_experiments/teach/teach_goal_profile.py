# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A teaching method's one-step likelihood around the true goal pose (along the track and
sideways), as each teaching experiment's trial records it, and its figure."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.models import SpaceObservationModel
from kiseki.plots import new_figure
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.teach.local_maps import METHODS, LocalMapMaker

__all__ = ["PROFILE_OFFSETS", "goal_profile", "profile_figure"]


PROFILE_OFFSETS = np.round(np.arange(-0.4, 0.401, 0.05), 2)


def goal_profile(scene, environment, goal: dict, method: str) -> dict:
    """The method's one-step likelihood around the true goal pose (the taught mark, map frame)
    with a noise-free local map taken there: along the goal heading (sideways offset 0) and
    sideways (along offset 0), normalised to the peak of the whole along x sideways grid, and
    where that peak is. A model without bias peaks at offset 0."""
    band, occlusion = METHODS[method]
    setup = build_robot(scene, 0)
    cameras = [s.device for s in build_sensors(scene, setup, 0, 0.1) if s.kind == "depth_camera"]
    model = SpaceObservationModel(environment, occlusion_aware=occlusion)
    truth = tuple(goal["truth"])
    images = [c.render(scene.world, truth, noise=False) for c in cameras]
    model.set_local_map(LocalMapMaker(cameras, band).make(images))
    x, y, th = goal["x"], goal["y"], goal["theta"]
    c, s = math.cos(th), math.sin(th)
    fine = np.arange(-0.4, 0.401, 0.01)
    a, b = (v.ravel() for v in np.meshgrid(fine, fine, indexing="ij"))
    poses = np.column_stack([x + c * a - s * b, y + s * a + c * b, np.full(a.size, th)])
    like = model.likelihoods(poses)
    peak = like.max()
    out = {"goal_peak_along": float(a[like.argmax()]), "goal_peak_side": float(b[like.argmax()])}
    grid = like.reshape(len(fine), len(fine)) / peak
    idx = np.round((PROFILE_OFFSETS + 0.4) / 0.01).astype(int)
    mid = len(fine) // 2
    for off, i in zip(PROFILE_OFFSETS, idx, strict=True):
        out[f"goal_like_along_{off:+.2f}"] = float(grid[i, mid])
        out[f"goal_like_side_{off:+.2f}"] = float(grid[mid, i])
    return out


def profile_figure(config, trials: pd.DataFrame, figures: Path) -> Path:
    fig = new_figure(figsize=(9, 3.5), dpi=120)
    axes = fig.subplots(1, 2, sharey=True)
    for ax, axis in zip(axes, ("along", "side"), strict=True):
        for method in config.methods:
            cols = [f"{method}_goal_like_{axis}_{o:+.2f}" for o in PROFILE_OFFSETS]
            ax.plot(PROFILE_OFFSETS, trials[cols].mean().to_numpy(), "o-", ms=3, label=method)
        ax.axvline(0.0, color="grey", lw=0.8)
        ax.set_xlabel(f"{'along-track' if axis == 'along' else 'sideways (left +)'} offset (m)")
    axes[0].set_ylabel("one-step likelihood / peak")
    axes[0].legend(fontsize=7)
    fig.suptitle("around the true goal pose: taught map, noise-free local map", fontsize=9)
    path = figures / "goal_likelihood_profiles.png"
    fig.savefig(path, bbox_inches="tight")
    return path
