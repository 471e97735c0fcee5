# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The teaching-and-playback thesis' experiments in the simulated factory (data/worlds):

- exp1-corridor (Tables 4.1-4.4): P0 -> P1 -> P2, proposal 2; localization and odometry error
  at P1 and P2, every stop within 0.1 m;
- exp2-turn (Tables 4.5, 4.6): the route with a turn, conventional vs proposal 1 vs proposal 2
  (and both proposals together): stop error, its SD, estimate error, stops within 0.1 m;
- exp3-boxes (Table 4.7): proposal 2 with three unknown boxes placed at random each run.

Each trial teaches the route once (its own seed: odometry and sensor noise) and plays it back.
Errors are taken relative to the goal waypoint: the stop error is the distance between where the
robot truly came to rest in playback and where it truly rested when the goal was marked in
teaching; the estimate error is the distance between the estimate's offset from the taught goal
(map frame) and the true offset, at rest. Every noise parameter is the simulator's, the same for
every method. Each trial also records the one-step likelihood around the true goal pose (where
it peaks, how fast it falls along the track and sideways); with boxes, each run is repeated
without them as a control.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from matplotlib.patches import Circle

from kiseki._support.inputs import YAML_LIMIT, read_input_text
from kiseki._support.yaml import safe_load_12
from kiseki.apps.teach import PlaybackConfig, playback, teach
from kiseki.core import Random, derive_seed
from kiseki.io.ros_map import load_map
from kiseki.models import SpaceObservationModel
from kiseki.plots import new_figure
from kiseki.sim.scene import load_scene
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.teach.environment_map import MERGE_RULES
from kiseki.teach.local_maps import METHODS, LocalMapMaker
from kiseki_experiments.harness.base import Analysis, Claim, Experiment, TrialOutput
from kiseki_experiments.harness.config import Boxes, Particles
from kiseki_experiments.harness.paths import WORLDS


@dataclass(frozen=True)
class Exp1Config:
    scene: str = str(WORLDS / "factory_corridor.yaml")
    methods: list[str] = field(default_factory=lambda: ["proposal2"])
    particles: Particles = 1000
    boxes: Boxes = 0  # unknown boxes placed at random for playback (Exp. 3)
    merge: str = "thesis"  # the taught maps' merge rule: thesis or evidence


@dataclass(frozen=True)
class Exp2Config:
    scene: str = str(WORLDS / "factory_turn.yaml")
    methods: list[str] = field(
        default_factory=lambda: ["conventional", "proposal1", "proposal2", "both"]
    )
    particles: Particles = 1000
    boxes: Boxes = 0
    merge: str = "thesis"


@dataclass(frozen=True)
class Exp3Config:
    scene: str = str(WORLDS / "factory_turn.yaml")
    methods: list[str] = field(default_factory=lambda: ["proposal2"])
    particles: Particles = 1000
    boxes: Boxes = 3
    merge: str = "thesis"


def _errors(result, goal: dict) -> dict:
    gx, gy = goal["truth"][0], goal["truth"][1]
    tx, ty = result.stop_true[0] - gx, result.stop_true[1] - gy
    ex, ey = result.stop_estimate[0] - goal["x"], result.stop_estimate[1] - goal["y"]
    return {
        "stop_dx": tx,
        "stop_dy": ty,
        "stop_error": math.hypot(tx, ty),
        "estimate_error": math.hypot(ex - tx, ey - ty),
        "reached": bool(result.reached),
    }


def _with_boxes(scene_file: Path, count: int, seed: int, tmp: Path) -> Path:
    """A copy of the scene with `count` unknown 0.4 x 0.4 x 0.6 m boxes, playback only, placed
    at random beside the route (kept 0.6 m clear of it so the robot can pass)."""
    doc = safe_load_12(read_input_text(scene_file, "scene files", YAML_LIMIT))
    rng = Random(seed)
    pts = np.asarray(doc["route"]["waypoints"], dtype=float)
    placed = 0
    while placed < count:
        i = int(rng.below(len(pts) - 1))
        f = rng.uniform(0.15, 0.85, 1)[0]
        side = 1 if rng.uniform(0, 1, 1)[0] < 0.5 else -1
        a, b = pts[i], pts[i + 1]
        normal = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)
        c = a + f * (b - a) + side * rng.uniform(0.8, 1.1, 1)[0] * normal
        doc["objects"].append(
            {
                "type": "box",
                "center": [float(c[0]), float(c[1])],
                "size": [0.4, 0.4, 0.6],
                "only_in": "playback",
            }
        )
        placed += 1
    out = tmp / scene_file.name
    out.write_text(yaml.safe_dump(doc), encoding="utf-8")
    return out


PROFILE_OFFSETS = np.round(np.arange(-0.4, 0.401, 0.05), 2)


def _goal_profile(scene, environment, goal: dict, method: str) -> dict:
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


def _profile_figure(config, trials: pd.DataFrame, figures: Path) -> Path:
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


def _boxes_beside_final_leg(scene_file: Path) -> dict:
    """How many of the playback-only boxes stand beside the route's final leg, left and right
    (the cameras see them on the way to the goal)."""
    doc = safe_load_12(read_input_text(scene_file, "scene files", YAML_LIMIT))
    a, b = (np.asarray(p, dtype=float) for p in doc["route"]["waypoints"][-2:])
    along = (b - a) / np.linalg.norm(b - a)
    left = right = 0
    for o in doc["objects"]:
        if o.get("only_in") != "playback":
            continue
        d = np.asarray(o["center"], dtype=float) - a
        if 0.0 <= d @ along <= np.linalg.norm(b - a):
            side = along[0] * d[1] - along[1] * d[0]
            left, right = left + int(side > 0), right + int(side < 0)
    return {"final_leg_boxes_left": left, "final_leg_boxes_right": right}


def teach_route(config: Exp1Config, seed: int, folder: Path):
    """The trial's teaching run (the same for every config with this scene, merge and seed)."""
    return teach(
        load_scene(Path(config.scene)), folder, seed=derive_seed(seed, 1), merge=config.merge
    )


def trial(config: Exp1Config, index: int, seed: int, taught=None) -> TrialOutput:
    """Teaching (or `taught`, :func:`teach_route`'s result for this config and seed, when
    given), then playback with each method."""
    del index
    scene_file = Path(config.scene)
    methods = config.methods
    record = {}
    with tempfile.TemporaryDirectory() as tmp:
        if taught is None:
            taught = teach_route(config, seed, Path(tmp) / "teach")
        for band, t in taught.truth.items():
            record[f"taught_{band}_erased_share"] = t["erased_share"]
            record[f"taught_{band}_false_occupied_share"] = t["false_occupied_share"]
        play_file = scene_file
        if config.boxes:
            play_file = _with_boxes(scene_file, config.boxes, derive_seed(seed, 3), Path(tmp))
            record.update(_boxes_beside_final_leg(play_file))
        scene = load_scene(play_file, "playback")
        maps = {band: load_map(path) for band, path in taught.maps.items()}
        goal = taught.marks[-1]
        for method in methods:
            band, _ = METHODS[method]
            result = playback(
                scene,
                maps[band],
                taught.marks,
                PlaybackConfig(
                    method=method, particles=config.particles, seed=derive_seed(seed, 2)
                ),
                taught_scene=taught.scene,
                variant="exp3-boxes" if config.boxes else None,  # the copy with the boxes
            )
            # which scene file it played in: its SHA-1 and the variant label of a changed copy
            record["scene_sha1"] = result.scene_identity["scene_sha1"]
            record["scene_variant"] = result.scene_identity.get("variant", "")
            for k, v in _errors(result, goal).items():
                record[f"{method}_{k}"] = v
            for k, v in _goal_profile(scene, maps[band], goal, method).items():
                record[f"{method}_{k}"] = v
            if config.boxes:  # the control: the same run without the boxes
                control = playback(
                    load_scene(scene_file, "playback"),
                    maps[band],
                    taught.marks,
                    PlaybackConfig(
                        method=method, particles=config.particles, seed=derive_seed(seed, 2)
                    ),
                    taught_scene=taught.scene,
                )
                for k, v in _errors(control, goal).items():
                    if k.startswith("stop_"):
                        record[f"{method}_nobox_{k}"] = v
            for name, poses in result.passes.items():
                mark = next(m for m in taught.marks if m["name"] == name)
                t, e, o = poses["true"], poses["estimate"], poses["odometry"]
                # localization error: the estimate's offset from the waypoint minus the truth's
                record[f"{method}_{name}_loc_dx"] = (e[0] - mark["x"]) - (t[0] - mark["truth"][0])
                record[f"{method}_{name}_loc_dy"] = (e[1] - mark["y"]) - (t[1] - mark["truth"][1])
                record[f"{method}_{name}_odo_dx"] = o[0] - t[0]
                record[f"{method}_{name}_odo_dy"] = o[1] - t[1]
    return TrialOutput(record)


def _stop_table(config, trials: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for method in config.methods:
        stop, est = trials[f"{method}_stop_error"], trials[f"{method}_estimate_error"]
        rows.append(
            {
                "method": method,
                "runs": len(stop),
                "stop_error_mean_m": stop.mean(),
                "stop_error_sd_m": stop.std(ddof=1),
                "estimate_error_mean_m": est.mean(),
                "stops_within_0.1m": int((stop <= 0.1).sum()),
                "along_track_share": float(
                    (trials[f"{method}_stop_dx"].abs() > trials[f"{method}_stop_dy"].abs()).mean()
                ),
            }
        )
    return pd.DataFrame(rows)


def _taught_table(config, trials: pd.DataFrame) -> pd.DataFrame:
    """The taught maps against the scene's truth (kiseki.metrics.taught_map_truth), per band:
    mean and worst share of obstacle cells in reach erased, and of visible free cells marked
    occupied, over the trials (each teaches its own map)."""
    rows = []
    for band in ("plane", "band"):
        erased = trials.get(f"taught_{band}_erased_share")
        if erased is None:
            continue
        occupied = trials[f"taught_{band}_false_occupied_share"]
        rows.append(
            {
                "map": band,
                "merge": config.merge,
                "erased_share_mean": erased.mean(),
                "erased_share_max": erased.max(),
                "false_occupied_share_mean": occupied.mean(),
                "false_occupied_share_max": occupied.max(),
            }
        )
    return pd.DataFrame(rows)


def _stop_figure(config, trials: pd.DataFrame, figures: Path) -> Path:
    fig = new_figure(figsize=(5, 5), dpi=120)
    ax = fig.subplots()
    for method in config.methods:
        ax.plot(trials[f"{method}_stop_dx"], trials[f"{method}_stop_dy"], "o", label=method)
    circle = Circle((0, 0), 0.1, fill=False, linestyle="--", color="grey")
    ax.add_patch(circle)
    ax.set_aspect("equal")
    ax.set_xlabel("stop error x (m)")
    ax.set_ylabel("stop error y (m)")
    ax.legend(fontsize=8)
    path = figures / "stop_positions.png"
    fig.savefig(path, bbox_inches="tight")
    return path


def _diagnostics(config, trials: pd.DataFrame) -> pd.DataFrame:
    """Per method: where the robot stopped relative to the goal (x along the final leg, y to
    its left in the scenes' frames), the estimate's error at the stop, and the one-step
    likelihood around the true goal pose: where it peaks and how much it drops 0.1 m / 0.3 m
    off the truth along the track and sideways (1 - mean of the two sides)."""
    rows = []
    for m in config.methods:

        def drop(axis, off, m=m):
            cols = [f"{m}_goal_like_{axis}_{o:+.2f}" for o in (-off, off)]
            return float(1.0 - trials[cols].to_numpy().mean())

        rows.append(
            {
                "method": m,
                "stop_dx_mean_m": trials[f"{m}_stop_dx"].mean(),
                "stop_dy_mean_m": trials[f"{m}_stop_dy"].mean(),
                "estimate_error_mean_m": trials[f"{m}_estimate_error"].mean(),
                "goal_peak_along_mean_m": trials[f"{m}_goal_peak_along"].mean(),
                "goal_peak_side_mean_m": trials[f"{m}_goal_peak_side"].mean(),
                "drop_along_0.1m": drop("along", 0.1),
                "drop_side_0.1m": drop("side", 0.1),
                "drop_along_0.3m": drop("along", 0.3),
                "drop_side_0.3m": drop("side", 0.3),
            }
        )
    return pd.DataFrame(rows)


def _diagnosis(diag: pd.DataFrame, turn_route: bool = True) -> str:
    """Why the stops differ from the thesis, from this run's measurements (and, on the route
    with the turn, the causes found with scripts/teach_playback_diagnostics.py)."""
    d = diag.set_index("method")
    lines = [
        "Stop error = where the robot comes to rest (it decelerates at its acceleration limit "
        "after the estimate is within 0.1 m of the goal) minus where it rested when the goal "
        "was marked in teaching; the estimate error is the estimate's error at that moment. "
        "Both stop poses are taken at rest, so the braking distance cancels up to about "
        "0.02 m (the controller slows so that its braking distance is 0.8 of the distance "
        "left). Diagnostics per method (table `diagnostics`, figure "
        "`goal_likelihood_profiles.png`):",
    ]
    for m, r in d.iterrows():
        a1, a3 = 100 * r["drop_along_0.1m"], 100 * r["drop_along_0.3m"]
        s1, s3 = 100 * r["drop_side_0.1m"], 100 * r["drop_side_0.3m"]
        lines.append(
            f"- {m}: mean stop offset ({r.stop_dx_mean_m:+.3f}, {r.stop_dy_mean_m:+.3f}) m, "
            f"estimate error {r.estimate_error_mean_m:.3f} m; one-step likelihood around the "
            f"true goal peaks at ({r.goal_peak_along_mean_m:+.2f} along, "
            f"{r.goal_peak_side_mean_m:+.2f} left) m and drops by only {a1:.1f} % / {a3:.1f} % "
            f"0.1 / 0.3 m along the track vs {s1:.1f} % / {s3:.1f} % sideways."
        )
    if not turn_route:
        return "\n".join(lines)
    lines += [
        "",
        "Why the numbers differ from the thesis (scripts/teach_playback_diagnostics.py "
        "reproduces the perfect-teacher runs): (1) one local map constrains the pose only "
        "weakly (the drops above: about 1 % 0.1 m off the truth), so the filter integrates "
        "many steps; the sideways cameras see little along the track, as the thesis says. "
        "(2) The methods now stop within a few centimetres of each other, less than the "
        "spread of each, so the thesis' ordering (conventional 0.13 > proposal 1 0.09 > "
        "proposal 2 0.07 m) does not appear. Until the local maps' column rule was fixed, "
        "a depth column without a reading (a bench under the cameras' 0.5 m minimum range) "
        "became a free ray to 10 m, and the thesis' merge made it permanent: with perfect "
        "poses and noise-free images 23.7 % of the obstacle cells in reach were erased in the "
        "plane map and 9.6 % in the band map (now 2.6 % and 1.7 %, table `taught_maps` for "
        "these runs with odometry). Those holes were the cells 'that L marks occupied behind "
        "walls but the map knows as free' that drew the raw-cut-out methods forward; the "
        "earlier explanation of the ordering rested on them. (3) Why the fixed plane does as "
        "well as the band here: the thesis' plane at 0.4 m 'sees only table legs' in its "
        "factory, but in kiseki's L-shaped aisle (an assumption: the thesis does not give its "
        "layout) the 2.5 m walls stand right behind the benches, 1.05 m from the route, and "
        "the plane sees them between the legs: along the taught route 95 % of the plane's "
        "beam ends lie on a wall (75 % of the band's; the band adds table tops). A layout "
        "whose plane sees only legs is needed to test the thesis' ordering. (4) The heading "
        "likelihood is nearly flat within a few degrees, so the heading that leaves the 90 deg "
        "turn is mostly the filter's own motion noise; 1 deg becomes 0.05 m sideways over the "
        "3 m final leg, which is why the errors are about as large sideways as along the "
        "track (stop_dx, stop_dy above). The motion noise is set from the simulated "
        "odometry's error model (PlaybackConfig.alphas, the same for every method). "
        "(5) The taught maps' shares in `taught_maps` are against the scene's truth in the "
        "world frame; the maps are built in the odometry frame, so a drifting teaching run "
        "(up to 0.2-0.5 m sideways by the end of a route) shifts walls by more than the one "
        "cell the measure forgives, and its erased share grows with the drift rather than "
        "with holes.",
    ]
    return "\n".join(lines)


def analyze_exp1(config, trials, timings, figures) -> Analysis:
    ok = trials[trials["error"].isna()]
    m = (config.methods)[0]
    rows = []
    for point in ("P1", "P2"):
        rows.append(
            {
                "point": point,
                "loc_dx_mean": ok[f"{m}_{point}_loc_dx"].mean(),
                "loc_dy_mean": ok[f"{m}_{point}_loc_dy"].mean(),
                "odo_dx_mean": ok[f"{m}_{point}_odo_dx"].mean(),
                "odo_dy_mean": ok[f"{m}_{point}_odo_dy"].mean(),
                "odo_dy_max_abs": ok[f"{m}_{point}_odo_dy"].abs().max(),
            }
        )
    errors = pd.DataFrame(rows)
    stops = _stop_table(config, ok)
    p2 = errors.iloc[1]
    claims = [
        Claim(
            "all stops within 0.1 m of P2",
            "11/11",
            f"{stops.iloc[0]['stops_within_0.1m']}/{len(ok)}",
            "runs",
            bool(stops.iloc[0]["stops_within_0.1m"] == len(ok)),
        ),
        Claim(
            "localization error at P2 smaller than odometry error",
            "(-0.03, 0.01) vs (0.01, -0.20) m",
            f"({p2.loc_dx_mean:+.3f}, {p2.loc_dy_mean:+.3f}) vs "
            f"({p2.odo_dx_mean:+.3f}, {p2.odo_dy_mean:+.3f})",
            "m",
            bool(
                math.hypot(p2.loc_dx_mean, p2.loc_dy_mean)
                < math.hypot(p2.odo_dx_mean, p2.odo_dy_mean)
            ),
        ),
        Claim(
            "odometry error at P2 is mostly sideways",
            "|y| 0.20 >> |x| 0.01",
            f"|y| {abs(p2.odo_dy_mean):.3f}, |x| {abs(p2.odo_dx_mean):.3f}",
            "m",
            bool(abs(p2.odo_dy_mean) > abs(p2.odo_dx_mean)),
        ),
    ]
    notes = (
        "Localization error: the estimate's offset from the taught waypoint minus the true "
        "offset, when the estimate passes the waypoint. Odometry error: playback odometry "
        "minus truth. The thesis' odometry y reached -0.49 m in one run; ours: "
        f"{errors.iloc[1]['odo_dy_max_abs']:.3f} m at most."
    )
    diag = _diagnostics(config, ok)
    return Analysis(
        tables={
            "errors_at_waypoints": errors,
            "stops": stops,
            "diagnostics": diag,
            "taught_maps": _taught_table(config, ok),
        },
        figures=[_stop_figure(config, ok, figures), _profile_figure(config, ok, figures)],
        claims=claims,
        notes=notes + "\n\n" + _diagnosis(diag, turn_route=False),
    )


THESIS_TABLE_4_5 = {
    "conventional": (0.13, 0.01, 0.13, 0),
    "proposal1": (0.09, 0.01, 0.08, 4),
    "proposal2": (0.07, 0.01, 0.05, 5),
}


def analyze_exp2(config, trials, timings, figures) -> Analysis:
    ok = trials[trials["error"].isna()]
    stops = _stop_table(config, ok)
    by = stops.set_index("method")
    claims = []
    for method, (mean, _sd, _est, within) in THESIS_TABLE_4_5.items():
        if method not in by.index:
            continue
        row = by.loc[method]
        claims.append(
            Claim(
                f"{method}: stops within 0.1 m",
                f"{within}/5",
                f"{int(row['stops_within_0.1m'])}/{int(row['runs'])}",
                "runs",
                bool(row["stops_within_0.1m"] / row["runs"] >= within / 5 - 1e-9),
            )
        )
        claims.append(
            Claim(
                f"{method}: stop error mean",
                f"{mean:.2f}",
                f"{row['stop_error_mean_m']:.3f}",
                "m",
                bool(row["stop_error_mean_m"] <= mean + 0.02),
            )
        )
    if {"conventional", "proposal1", "proposal2"} <= set(by.index):
        order = [by.loc[m, "stop_error_mean_m"] for m in ("conventional", "proposal1", "proposal2")]
        claims.append(
            Claim(
                "ordering conventional > proposal 1 > proposal 2",
                "0.13 > 0.09 > 0.07",
                " > ".join(f"{v:.3f}" for v in order),
                "m",
                bool(order[0] > order[1] > order[2]),
            )
        )
    diag = _diagnostics(config, ok)
    return Analysis(
        tables={"stops": stops, "diagnostics": diag, "taught_maps": _taught_table(config, ok)},
        figures=[_stop_figure(config, ok, figures), _profile_figure(config, ok, figures)],
        claims=claims,
        notes="Thesis Tables 4.5/4.6: 5 runs per method; 'both' is not in the thesis.\n\n"
        + _diagnosis(diag),
    )


def analyze_exp3(config, trials, timings, figures) -> Analysis:
    ok = trials[trials["error"].isna()]
    stops = _stop_table(config, ok)
    row = stops.iloc[0]
    claims = [
        Claim(
            "proposal 2 with unknown boxes: stop error mean",
            "0.07 (SD 0.02)",
            f"{row['stop_error_mean_m']:.3f} (SD {row['stop_error_sd_m']:.3f})",
            "m",
            bool(row["stop_error_mean_m"] <= 0.09),
        ),
        Claim(
            "proposal 2 with unknown boxes: estimate error mean",
            "0.06",
            f"{row['estimate_error_mean_m']:.3f}",
            "m",
            bool(row["estimate_error_mean_m"] <= 0.08),
        ),
    ]
    diag = _diagnostics(config, ok)
    m = config.methods[0]
    cols = ["final_leg_boxes_left", "final_leg_boxes_right", f"{m}_stop_dx", f"{m}_stop_dy"]
    cols += [f"{m}_nobox_stop_dx", f"{m}_nobox_stop_dy"]
    boxes = ok[["trial", *cols]] if "final_leg_boxes_left" in ok else pd.DataFrame()
    notes = (
        "Three 0.4 x 0.4 x 0.6 m boxes per run, only in playback, 0.8-1.1 m beside a random "
        "route leg (the thesis moved three cardboard boxes between runs; their positions are "
        "not given). Table `boxes_final_leg` compares each run with the same run without the "
        "boxes (same teaching, same seeds). A box 0.2-0.5 m in front of an aisle wall hides "
        "the wall from the sideways camera; the intrusion term, which the thesis makes cheap "
        "(sigma 130 %), is what resists the pose sliding toward the box. With the fixed local "
        "maps the boxes move the stop by a few centimetres at most. Before the fix, when the "
        "taught maps had free rays through the walls behind the benches, a box beside the "
        "final leg pulled the stop 0.34-0.36 m toward the other side (mean stop error "
        "0.254 m): the holes, not the boxes, made the penetration term blind there.\n\n"
        + _diagnosis(diag)
    )
    return Analysis(
        tables={
            "stops": stops,
            "diagnostics": diag,
            "boxes_final_leg": boxes,
            "taught_maps": _taught_table(config, ok),
        },
        figures=[_stop_figure(config, ok, figures), _profile_figure(config, ok, figures)],
        claims=claims,
        notes=notes,
    )


def _preflight(config: Exp1Config) -> None:
    if not Path(config.scene).is_file():
        raise FileNotFoundError(f"scene {config.scene} not found")
    for m in config.methods or []:
        if m not in METHODS:
            raise ValueError(f"unknown method {m!r} (known: {', '.join(METHODS)})")
    if config.merge not in MERGE_RULES:
        raise ValueError(f"unknown merge rule {config.merge!r} (known: {', '.join(MERGE_RULES)})")


EXP1 = Experiment(
    name="exp1-corridor",
    paper="000_7c5a0f8de3fa28f5.txt",
    artefact="Tables 4.1-4.4",
    description="corridor P0 -> P1 -> P2, proposal 2: localization vs odometry error, stops",
    config_type=Exp1Config,
    trial=trial,
    analyze=analyze_exp1,
    default_runs=11,
    preflight=_preflight,
)
EXP2 = Experiment(
    name="exp2-turn",
    paper="000_7c5a0f8de3fa28f5.txt",
    artefact="Tables 4.5, 4.6",
    description="route with a turn: conventional vs proposal 1 vs proposal 2 (and both)",
    config_type=Exp2Config,
    trial=trial,
    analyze=analyze_exp2,
    default_runs=5,
    preflight=_preflight,
)
EXP3 = Experiment(
    name="exp3-boxes",
    paper="000_7c5a0f8de3fa28f5.txt",
    artefact="Table 4.7",
    description="route with a turn, three unknown boxes at random each run, proposal 2",
    config_type=Exp3Config,
    trial=trial,
    analyze=analyze_exp3,
    default_runs=5,
    preflight=_preflight,
)
