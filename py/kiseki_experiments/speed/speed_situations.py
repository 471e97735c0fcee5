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

One trial per (situation, method, repeat): ``repeats`` drives of each, the laser noise of a
trial from its seed, so each claim has one value per repeat and an interval over repeats. The
paper prints no numbers for these figures: the claims are its statements, measured.
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
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import Count, Index, Seconds
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence
from kiseki_experiments.speed.speed_common import (
    METHODS,
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
    repeats: Count = 5  # drives of each run, each with its own laser noise
    # what runs in each arm (the controls swap them): the arm without speed control, method 1's
    # arms and situation 3's methods 1 + 2 arm
    baseline: str = "none"
    method_1: str = "occlusion"
    method_12: str = "occlusion-width"


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
    known = set(METHODS) | {"offline-map"}
    for arm in ("baseline", "method_1", "method_12"):
        if getattr(config, arm) not in known:
            raise ValueError(f"speed-situations: {arm} must be one of {', '.join(sorted(known))}")
    for name in {r[1] for r in RUNS}:
        if not (Path(config.worlds) / name).is_file():
            raise FileNotFoundError(f"speed-situations: {Path(config.worlds) / name} not found")


def _runs_as(config: SituationsConfig, method: str) -> str:
    """The method that runs in an arm named ``method`` (as RUNS names it)."""
    arms = {"none": config.baseline, "occlusion": config.method_1}
    return {**arms, "occlusion-width": config.method_12}.get(method, method)


def trial(config: SituationsConfig, index: int, seed: int) -> TrialOutput:
    situation, name, variant, goal, method = RUNS[config.runs[index % len(config.runs)]]
    runs = _runs_as(config, method)
    scene_file = Path(config.worlds) / name
    prior = prior_map(scene_file)
    scene = load_scene(scene_file, variant)
    limiter = OfflineMapLimiter(prior) if runs == "offline-map" else None
    d = drive(
        scene, goal, "occlusion" if limiter else runs, seed, prior, config.max_duration, limiter
    )
    return TrialOutput(
        {
            "situation": situation,
            "method": method,
            "runs": runs,
            "repeat": index // len(config.runs),
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


def _evidence(runs: dict, repeats: list[int]) -> list[Evidence]:
    """Each claim's values, one per repeat that has the runs it compares."""
    near, far = CROSSING
    box = (2.0, 4.9)  # from where the box is in reach until the robot passes it
    width = (1.5, CORRIDOR_END - 1.0)
    values: dict[str, list[float]] = {k: [] for k in ("full", "slows", "speeds", "box", "width")}
    for r in repeats:
        if (1, "none", r) in runs:
            values["full"].append(_between(runs[(1, "none", r)], 1.0, 9.0).min() / V_MAX)
        if (1, "occlusion", r) in runs:
            m1 = runs[(1, "occlusion", r)]
            before = _between(m1, 0.5, near).min()
            values["slows"].append(before / V_MAX)
            values["speeds"].append(_between(m1, near + 0.35, far).mean() - before)
        if (2, "occlusion", r) in runs and (2, "offline-map", r) in runs:
            scan = _between(runs[(2, "occlusion", r)], *box, "ratio").min()
            mapped = _between(runs[(2, "offline-map", r)], *box, "ratio").min()
            values["box"].append(mapped - scan)
        if (3, "occlusion", r) in runs and (3, "occlusion-width", r) in runs:
            a = _between(runs[(3, "occlusion", r)], *width).mean()
            b = _between(runs[(3, "occlusion-width", r)], *width).mean()
            values["width"].append(b / a)
    f15 = 1 / (1 + math.exp(-4.9 * (1.5 - 1.3)))
    shown = {
        "full": "min speed y 1-9 m / v_max",
        "slows": f"min speed before the crossing's near face (y = {near} m) / v_max",
        "speeds": "mean speed inside minus the min before (m/s)",
        "box": "eq. 1 ratio's min, y 2.0-4.9 m: map only minus scan",
        "width": f"mean speed y 1.5-5 m, methods 1 + 2 over method 1 (f(1.5 m) = {f15:.3f})",
    }
    return [Evidence.of(k, v, shown=shown[k]) for k, v in values.items() if v]


V_MAX = 0.5  # m/s, the paper's robot (kiseki.sim.robot_params)


def analyze(config: SituationsConfig, trials: pd.DataFrame, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    runs = {(int(r["situation"]), r["method"], int(r["repeat"])): r for _, r in ok.iterrows()}
    table = ok[["situation", "method", "runs", "repeat", "reached", "duration_s", "collision"]]
    table = table.copy()
    table["min_speed_en_route"] = [_en_route(r).min() for _, r in ok.iterrows()]
    table["mean_speed"] = [float(np.mean(r["speed"])) for _, r in ok.iterrows()]
    evidence = _evidence(runs, sorted({k[2] for k in runs}))
    first = {k[:2]: r for k, r in runs.items() if k[2] == 0}  # the figures: the first repeat
    figure_paths = [_plot(first, s, figures) for s in (1, 2, 3) if any(k[0] == s for k in first)]
    notes = (
        "Closed loop: the FPM chooses the direction, the limiter caps the speed, the omni robot "
        "keeps facing +y; the prior map is the scene's ground truth at the laser's height "
        "(teach variant, outside the building unknown). Speeds are the simulated robot's; the "
        "figures show the first repeat."
    )
    return Analysis(
        {"runs": table.reset_index(drop=True)}, figure_paths, notes=notes, evidence=evidence
    )


def _control(name: str, runs: str, overrides: tuple[str, ...], why: str) -> Control:
    """A control that drives only the runs its claims compare (``runs``), 5 repeats each."""
    count = len(runs.split(","))
    return Control(name, (f"runs={runs}", "repeats=5", *overrides), 5 * count, why)


NO_LIMIT_IN_METHOD_1 = _control(
    "method 1's arm without speed control",
    "1",
    ("method_1=none",),
    "without a limit the robot keeps v_max before and inside the crossing",
)
CLAIMS = (
    ClaimSpec(
        key="full",
        claim="situation 1 without speed control crosses at full speed (Fig. 5a)",
        unit="min speed, y 1-9 m / v_max",
        criterion=Criterion(
            paper_value="v_max through the crossing",
            compare=">=",
            threshold=0.98,
            why="2 % of v_max (1 cm/s) for the FPM's steering and the speed command's rounding",
            bounds=(0.0, 1.0),
        ),
        control=_control(
            "method 1 in the arm without speed control",
            "0",
            ("baseline=occlusion",),
            "method 1 slows before the crossing",
        ),
        measure="one drive's min speed",
    ),
    ClaimSpec(
        key="slows",
        claim="situation 1 with method 1 slows before the crossing (Fig. 5b)",
        unit="min speed before the crossing / v_max",
        criterion=Criterion(
            paper_value="slows before entering",
            compare="<=",
            threshold=0.8,
            why="a fifth of v_max: a slowdown, not the 2 % the FPM's steering costs",
            bounds=(0.0, 1.0),
        ),
        control=NO_LIMIT_IN_METHOD_1,
        measure="one drive's min speed before the near face",
    ),
    ClaimSpec(
        key="speeds",
        claim="... and speeds up inside it (Fig. 5c)",
        unit="m/s",
        criterion=Criterion(
            paper_value="accelerates once inside",
            compare=">=",
            threshold=0.1,
            why="a fifth of v_max (0.1 m/s) above the min before the crossing",
            bounds=(-V_MAX, V_MAX),
        ),
        control=NO_LIMIT_IN_METHOD_1,
        measure="one drive's mean speed inside minus its min before",
    ),
    ClaimSpec(
        key="box",
        claim="situation 2: method 1 slows for the occlusion of an object the map lacks; a "
        "limit from the map alone does not (Fig. 6)",
        unit="eq. 1 ratio (map only minus scan), y 2.0-4.9 m",
        criterion=Criterion(
            paper_value="slows for the unknown box",
            compare=">=",
            threshold=0.05,
            why="5 % of v_max: above the ratio's change from the laser's noise",
            bounds=(-1.0, 1.0),
        ),
        control=_control(
            "the map-only limit in method 1's arm",
            "3,4",
            # 18 s of each drive: past y = 4.9 m, where the claim's window ends
            ("method_1=offline-map", "max_duration=18"),
            "both arms see only the map: the box hides nothing from either",
        ),
        measure="one repeat's difference between the two arms",
    ),
    ClaimSpec(
        key="width",
        claim="situation 3: the width term lowers the speed in the 1.5 m corridor (Fig. 7)",
        unit="mean speed y 1.5-5 m, methods 1 + 2 / method 1",
        criterion=Criterion(
            paper_value="lower speed with method 2",
            compare="<=",
            threshold=0.9,
            why="a tenth lower; f(1.5 m) = 0.727 of eq. 4 would give 0.73",
            bounds=(0.0, math.inf),
        ),
        control=_control(
            "method 1 in the methods 1 + 2 arm (no width term)",
            "5,6",
            ("method_12=occlusion", "max_duration=18"),  # past y = 5 m, the window's end
            "the same method in both arms: a ratio of ~1",
        ),
        measure="one repeat's ratio of the two arms' mean speeds",
    ),
)


def _plot(runs: dict, situation: int, figures: Path) -> Path:
    name = "speed_crossroad.yaml" if situation < 3 else "speed_corridor.yaml"
    variant = "playback" if situation == 2 else "teach"
    grid = load_scene(WORLDS / name, variant).ground_truth(0.28, 0.32)
    fig = new_figure(figsize=(10, 4.5), dpi=120)
    ax_map, ax_speed = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.6]})
    draw_map(ax_map, grid)
    for (s, method), row in sorted(runs.items(), key=lambda item: item[0]):
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
    default_runs=5 * len(RUNS),
    preflight=preflight,
    trial_count=lambda config: len(config.runs) * config.repeats,
    claims=CLAIMS,
    scenes=tuple(sorted({r[1] for r in RUNS})),
)
