# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""speed-situations: paper 004's three simulations (Figs. 5-7), driven closed-loop (the Fuzzy
Potential Method toward the goal, kiseki_experiments.speed.speed_common) in the simulator:

- Situation 1 (Fig. 5): straight through a crossroad of 2.3 m corridors
  (data/worlds/speed_crossroad.yaml), without speed control and with method 1;
- Situation 2 (Fig. 6): the same with an unknown 0.60 x 0.80 m box at (-1.45, 4.5) m (the
  scene's playback variant; the map is the teach variant's), without speed control, with
  method 1, and with method 1 fed a scan cast in the prior map instead of the real one: what a
  speed limit computed offline from the map alone (the paper's refs. [5][6]) would give;
- Situation 3 (Fig. 7): a 1.5 m corridor opening into a hall (speed_corridor.yaml), method 1
  against methods 1 + 2.

One trial per (situation, method); the laser noise of a trial comes from its seed. The paper
prints no numbers for these figures: the claims are its statements, measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.plots import draw_map, new_figure
from kiseki.sim.scene import load_scene
from kiseki.speed import SpeedLimiter, SpeedLimiterConfig
from kiseki_experiments.harness.base import Analysis, Claim, Experiment, TrialOutput
from kiseki_experiments.harness.config import Index, Seconds
from kiseki_experiments.speed.speed_common import (
    WORLDS,
    RecordingLimiter,
    drive,
    prior_map,
)

__all__ = ["EXPERIMENT", "OfflineMapLimiter", "SituationsConfig"]

# (situation, scene file, variant, goal, method)
RUNS = (
    (1, "speed_crossroad.yaml", "teach", (0.0, 11.0), "none"),
    (1, "speed_crossroad.yaml", "teach", (0.0, 11.0), "occlusion"),
    (2, "speed_crossroad.yaml", "playback", (0.0, 11.0), "none"),
    (2, "speed_crossroad.yaml", "playback", (0.0, 11.0), "occlusion"),
    (2, "speed_crossroad.yaml", "playback", (0.0, 11.0), "offline-map"),
    (3, "speed_corridor.yaml", "teach", (0.0, 12.0), "occlusion"),
    (3, "speed_corridor.yaml", "teach", (0.0, 12.0), "occlusion-width"),
)
CROSSING = (3.85, 6.15)  # y of the crossing's near and far faces, speed_crossroad.yaml
CORRIDOR_END = 6.0  # y where speed_corridor.yaml's corridor opens into the hall


@dataclass(frozen=True)
class SituationsConfig:
    worlds: str = str(WORLDS)
    max_duration: Seconds = 120.0  # s, a run that has not arrived by then fails
    runs: list[Index] = field(default_factory=lambda: list(range(len(RUNS))))


class OfflineMapLimiter:
    """Method 1 computed from the prior map alone: each update's scan is replaced by one cast
    in the map from the same pose (noise-free), so obstacles the map lacks never count."""

    def __init__(self, prior) -> None:
        self.prior = prior
        self.inner = RecordingLimiter(SpeedLimiter(prior, SpeedLimiterConfig(use_width=False)))
        self.terms = self.inner.terms

    def update(self, sensor_pose, angles, ranges, max_range, dt, heading=None):
        pose = np.asarray(sensor_pose, dtype=float).reshape(1, 3)
        mapped = self.prior.cast_scans(pose, np.asarray(angles), max_range=max_range)[0]
        return self.inner.update(sensor_pose, angles, mapped, max_range, dt, heading)


def preflight(config: SituationsConfig) -> None:
    for index in config.runs:
        if not 0 <= index < len(RUNS):
            raise ValueError(f"speed-situations: runs must lie in 0..{len(RUNS) - 1}")
    for name in {r[1] for r in RUNS}:
        if not (Path(config.worlds) / name).is_file():
            raise FileNotFoundError(f"speed-situations: {Path(config.worlds) / name} not found")


def trial(config: SituationsConfig, index: int, seed: int) -> TrialOutput:
    situation, name, variant, goal, method = RUNS[config.runs[index]]
    scene_file = Path(config.worlds) / name
    prior = prior_map(scene_file)
    scene = load_scene(scene_file, variant)
    limiter = OfflineMapLimiter(prior) if method == "offline-map" else None
    d = drive(
        scene, goal, "occlusion" if limiter else method, seed, prior, config.max_duration, limiter
    )
    return TrialOutput(
        {
            "situation": situation,
            "method": method,
            "reached": d.reached,
            "duration_s": d.duration,
            "collision": "" if d.collision is None else d.collision["hit"],
            "t": d.t.tolist(),
            "x": d.pose[:, 0].tolist(),
            "y": d.pose[:, 1].tolist(),
            "speed": d.speed.tolist(),
            "limit": d.limit.tolist(),
            "ratio": d.ratio.tolist(),
            "width_factor": d.width_factor.tolist(),
        }
    )


def _between(row, y0: float, y1: float, what: str = "speed") -> np.ndarray:
    y = np.asarray(row["y"])
    return np.asarray(row[what])[(y >= y0) & (y <= y1)]


def _en_route(row) -> np.ndarray:
    """The speeds past the start's ramp (1 s) and before the goal's braking (the last 1.5 s)."""
    t, v = np.asarray(row["t"]), np.asarray(row["speed"])
    return v[(t >= 1.0) & (t <= t[-1] - 1.5)]


def _argmin_y(row, y0: float, y1: float) -> float:
    """The y at which the speed is lowest between y0 and y1."""
    y, v = np.asarray(row["y"]), np.asarray(row["speed"])
    inside = (y >= y0) & (y <= y1)
    return float(y[inside][np.argmin(v[inside])])


def analyze(config: SituationsConfig, trials: pd.DataFrame, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    runs = {(int(r["situation"]), r["method"]): r for _, r in ok.iterrows()}
    table = ok[["situation", "method", "reached", "duration_s", "collision"]].copy()
    table["min_speed_en_route"] = [_en_route(r).min() for _, r in ok.iterrows()]
    table["mean_speed"] = [float(np.mean(r["speed"])) for _, r in ok.iterrows()]
    claims: list[Claim] = []
    v_max = 0.5
    near, far = CROSSING
    if (1, "none") in runs and (1, "occlusion") in runs:
        plain, m1 = runs[(1, "none")], runs[(1, "occlusion")]
        before = _between(m1, 0.5, near)
        inside = _between(m1, near + 0.35, far)
        claims += [
            Claim(
                claim="situation 1 without speed control crosses at full speed (Fig. 5a)",
                paper_value="v_max through the crossing",
                measured_value=f"min {_between(plain, 1.0, 9.0).min():.3f} m/s, y 1-9 m",
                unit="m/s",
                holds=bool(_between(plain, 1.0, 9.0).min() >= 0.98 * v_max),
            ),
            Claim(
                claim="situation 1 with method 1 slows before the crossing (Fig. 5b)",
                paper_value="slows before entering",
                measured_value=f"min {before.min():.3f} m/s at y = "
                f"{_argmin_y(m1, 0.5, near):.2f} m",
                unit="m/s",
                holds=bool(before.min() <= 0.8 * v_max),
                note=f"the crossing's near face is at y = {near} m",
            ),
            Claim(
                claim="... and speeds up inside it (Fig. 5c)",
                paper_value="accelerates once inside",
                measured_value=f"{inside.mean():.3f} m/s inside vs {before.min():.3f} m/s min "
                "before",
                unit="m/s",
                holds=bool(inside.mean() >= before.min() + 0.1),
            ),
        ]
    if all((2, m) in runs for m in ("occlusion", "offline-map")):
        m1, offline = runs[(2, "occlusion")], runs[(2, "offline-map")]
        s1 = runs.get((1, "occlusion"))
        box = (2.0, 4.9)  # from where the box is in reach until the robot passes it
        with_box = float(_between(m1, *box, "ratio").min())
        offline_min = float(_between(offline, *box, "ratio").min())
        claims.append(
            Claim(
                claim="situation 2: method 1 slows for the occlusion of an object the map "
                "lacks; a limit from the map alone does not (Fig. 6)",
                paper_value="slows for the unknown box",
                measured_value=f"ratio min {with_box:.3f} (scan) vs {offline_min:.3f} (map only)"
                + (
                    f"; {float(_between(s1, *box, 'ratio').min()):.3f} without the box"
                    if s1 is not None
                    else ""
                ),
                unit="eq. 1 ratio, y 2.0-4.9 m",
                holds=bool(with_box <= offline_min - 0.05),
            )
        )
    if (3, "occlusion") in runs and (3, "occlusion-width") in runs:
        m1, m12 = runs[(3, "occlusion")], runs[(3, "occlusion-width")]
        a = _between(m1, 1.5, CORRIDOR_END - 1.0).mean()
        b = _between(m12, 1.5, CORRIDOR_END - 1.0).mean()
        f15 = 1 / (1 + math.exp(-4.9 * (1.5 - 1.3)))
        claims.append(
            Claim(
                claim="situation 3: the width term lowers the speed in the 1.5 m corridor (Fig. 7)",
                paper_value="lower speed with method 2",
                measured_value=f"{b:.3f} vs {a:.3f} m/s (ratio {b / a:.3f}; f(1.5 m) = {f15:.3f})",
                unit="mean speed, y 1.5-5 m",
                holds=bool(b <= 0.9 * a),
            )
        )
    figure_paths = [_plot(runs, s, figures) for s in (1, 2, 3) if any(k[0] == s for k in runs)]
    notes = (
        "Closed loop: the FPM chooses the direction, the limiter caps the speed, the omni robot "
        "keeps facing +y; the prior map is the scene's ground truth at the laser's height "
        "(teach variant, outside the building unknown). Speeds are the simulated robot's."
    )
    return Analysis({"runs": table.reset_index(drop=True)}, figure_paths, claims, notes)


def _plot(runs: dict, situation: int, figures: Path) -> Path:
    name = "speed_crossroad.yaml" if situation < 3 else "speed_corridor.yaml"
    variant = "playback" if situation == 2 else "teach"
    grid = load_scene(WORLDS / name, variant).ground_truth(0.28, 0.32)
    fig = new_figure(figsize=(10, 4.5), dpi=120)
    ax_map, ax_speed = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.6]})
    draw_map(ax_map, grid)
    for (s, method), row in sorted(runs.items()):
        if s != situation:
            continue
        ax_map.plot(row["x"], row["y"], lw=1, label=method)
        ax_speed.plot(row["t"], row["speed"], label=f"{method}: speed")
        if method != "none":
            ax_speed.plot(row["t"], row["limit"], ":", lw=1, label=f"{method}: limit")
    ax_map.set_title(f"situation {situation}: trajectories", fontsize=9)
    ax_speed.set_xlabel("time (s)")
    ax_speed.set_ylabel("speed (m/s)")
    ax_speed.set_ylim(0, 0.55)
    ax_speed.legend(fontsize=7)
    ax_speed.set_title(f"situation {situation} (Fig. {4 + situation}): speed", fontsize=9)
    fig.tight_layout()
    path = figures / f"speed_situation{situation}.png"
    fig.savefig(path)
    return path


EXPERIMENT = Experiment(
    name="speed-situations",
    paper="004_01c22fe90d48d1c0.txt",
    artefact="Figs. 5-7 (situations 1-3)",
    description="crossroad, unknown box and narrow corridor: speed with and without the method",
    config_type=SituationsConfig,
    trial=trial,
    analyze=analyze,
    default_runs=len(RUNS),
    preflight=preflight,
    trial_count=lambda config: len(config.runs),
)
