# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""speed-fig4: paper 004's Fig. 4: the occluded region's corner seen from 1.5 m at phi = 0..60
deg in 5 deg steps (data/worlds/speed_corner.yaml's ``poses``), the robot heading +y; method 1's
limit v_max * ratio (eq. 1, theta = 90 deg) at each pose, and the hidden region at phi = 20 and
60 deg (Figs. 4c, 4d). One trial per pose; the scan carries the laser's noise (seeded).

The paper's point: at the same distance from the corner, the limit follows the geometry (how
much of the free space ahead is hidden), not the distance. The figure's own values are not in
the text, so the claims are the paper's qualitative statements, measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki._support.yaml import safe_load_12
from kiseki.plots import draw_map, new_figure
from kiseki.sim.scene import load_scene
from kiseki.sim.sensors import LASER_PRESETS, Laser2D, Mount
from kiseki.speed import occlusion_labels
from kiseki_experiments.harness.base import Analysis, Claim, Experiment, TrialOutput
from kiseki_experiments.harness.config import PositiveReal, Speed
from kiseki_experiments.speed.speed_common import WORLDS, laser_mount, prior_map

__all__ = ["EXPERIMENT", "Fig4Config"]


@dataclass(frozen=True)
class Fig4Config:
    scene: str = str(WORLDS / "speed_corner.yaml")
    v_max: Speed = 0.5  # m/s, the paper's
    half_angle_deg: PositiveReal = 90.0  # theta, the paper's


def _sweep(config: Fig4Config) -> tuple[list, tuple[float, float]]:
    scene = load_scene(config.scene)
    if not scene.poses:
        raise ValueError(f"{config.scene}: speed-fig4 needs a scene with 'poses'")
    corner = safe_load_12(Path(config.scene).read_text(encoding="utf-8"))["poses"]["corner"]
    return scene.poses, (float(corner[0]), float(corner[1]))


def preflight(config: Fig4Config) -> None:
    _sweep(config)
    if not 0 < config.half_angle_deg <= 180 or not config.v_max > 0:
        raise ValueError("speed-fig4: need 0 < half_angle_deg <= 180 and v_max > 0")


def _view(config: Fig4Config, index: int, seed: int):
    """(phi, robot pose, ratio, labels) of pose `index` with the laser's noise of `seed`."""
    poses, corner = _sweep(config)
    scene = load_scene(config.scene)
    prior = prior_map(config.scene)
    mount = laser_mount(scene)
    laser = Laser2D(LASER_PRESETS["speed_lrf"], Mount(*mount), seed)
    pose = poses[index]
    sensor, ranges = laser.scan(prior, pose)  # the world is the map here: no unknown objects
    ratio, labels = occlusion_labels(
        prior,
        sensor,
        laser.params.angles,
        ranges,
        laser.params.max_range,
        math.radians(config.half_angle_deg),
        pose[2],
    )
    phi = math.degrees(math.atan2(corner[1] - pose[1], corner[0] - pose[0]))
    return phi, pose, ratio, labels, prior, math.dist(corner, pose[:2])


def trial(config: Fig4Config, index: int, seed: int) -> TrialOutput:
    phi, pose, ratio, labels, _, distance = _view(config, index, seed)
    return TrialOutput(
        {
            "phi_deg": round(phi, 6),
            "x": pose[0],
            "y": pose[1],
            "corner_distance_m": distance,
            "ratio": ratio,
            "v_ref": config.v_max * ratio,
            "seen_cells": int((labels == 2).sum()),
            "region_cells": int((labels > 0).sum()),
        }
    )


def analyze(config: Fig4Config, trials: pd.DataFrame, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()].sort_values("phi_deg")
    if ok.empty:
        return Analysis(notes="every trial failed: nothing to analyse")
    table = ok[["phi_deg", "corner_distance_m", "ratio", "v_ref", "seen_cells", "region_cells"]]
    spread = float(ok["v_ref"].max() - ok["v_ref"].min())
    claims = [
        Claim(
            claim="at one distance from the corner, the limit follows the geometry (Fig. 4b)",
            paper_value="differs with phi at 1.5 m",
            measured_value=f"{ok['v_ref'].min():.3f}-{ok['v_ref'].max():.3f} m/s over phi "
            f"{ok['phi_deg'].min():.0f}-{ok['phi_deg'].max():.0f} deg, distance "
            f"{ok['corner_distance_m'].min():.3f}-{ok['corner_distance_m'].max():.3f} m",
            unit="m/s",
            holds=bool(spread >= 0.1 * config.v_max),
            note="holds when the limit spans at least 10 % of v_max across phi",
        )
    ]
    at = {round(p): r for p, r in zip(ok["phi_deg"], ok["v_ref"], strict=True)}
    if 20 in at and 60 in at:
        claims.append(
            Claim(
                claim="the hidden region differs between phi = 20 and 60 deg (Figs. 4c, 4d)",
                paper_value="the view differs",
                measured_value=f"{at[20]:.3f} vs {at[60]:.3f} m/s",
                unit="m/s",
                holds=bool(abs(at[20] - at[60]) >= 0.05 * config.v_max),
                note="from further back (60 deg) the corner hides more of the side corridor",
            )
        )
    fig = new_figure(figsize=(12, 4.2), dpi=120)
    axes = fig.subplots(1, 3)
    axes[0].plot(ok["phi_deg"], ok["v_ref"], "o-")
    axes[0].set_xlabel("phi (deg)")
    axes[0].set_ylabel("v_max^ref (m/s)")
    axes[0].set_ylim(0, config.v_max)
    axes[0].set_title("(b) method 1's limit, corner at 1.5 m", fontsize=9)
    index = {round(p): i for i, p in enumerate(_phis(config))}
    for ax, phi, tag in ((axes[1], 20, "c"), (axes[2], 60, "d")):
        if phi in index:
            _draw_view(ax, config, index[phi], f"({tag}) phi = {phi} deg")
    fig.tight_layout()
    path = figures / "speed_fig4.png"
    fig.savefig(path)
    notes = (
        "Fig. 4's geometry is kiseki's reading (the figure is not in the text): an L-turn of "
        "2.3 m corridors, the robot at corner + 1.5 m (-cos phi, -sin phi) heading +y "
        "(data/worlds/speed_corner.yaml). The map is the scene's ground truth at the laser's "
        "height; the scan has the laser's noise."
    )
    return Analysis({"sweep": table.reset_index(drop=True)}, [path], claims, notes)


def _phis(config: Fig4Config) -> list[float]:
    poses, corner = _sweep(config)
    return [math.degrees(math.atan2(corner[1] - p[1], corner[0] - p[0])) for p in poses]


def _draw_view(ax, config: Fig4Config, index: int, title: str) -> None:
    phi, pose, ratio, labels, prior, _ = _view(config, index, 0)
    draw_map(ax, prior)
    res, ox, oy = prior.resolution, prior.origin.x, prior.origin.y
    extent = (ox, ox + prior.width * res, oy, oy + prior.height * res)
    shade = np.zeros((*labels.shape, 4))
    shade[labels == 1] = (0.85, 0.1, 0.1, 0.55)  # free, within reach, hidden
    shade[labels == 2] = (0.1, 0.5, 0.9, 0.35)  # seen
    ax.imshow(shade, origin="lower", extent=extent, interpolation="nearest")
    ax.plot(pose[0], pose[1], "ko", ms=4)
    ax.annotate("", (pose[0], pose[1] + 0.6), (pose[0], pose[1]), arrowprops={"arrowstyle": "->"})
    ax.set_title(f"{title}: ratio {ratio:.2f} (red hidden, blue seen)", fontsize=9)


EXPERIMENT = Experiment(
    name="speed-fig4",
    paper="004_01c22fe90d48d1c0.txt",
    artefact="Fig. 4",
    description="method 1's limit around a corner seen from 1.5 m at phi = 0..60 deg",
    config_type=Fig4Config,
    trial=trial,
    analyze=analyze,
    default_runs=13,
    preflight=preflight,
    trial_count=lambda config: len(_sweep(config)[0]),
)
