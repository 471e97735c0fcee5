# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnav-navigators: the outdoor runs of the magnetic-navigation thesis
(``002_74cea16d239c028f.txt``, sec. 4.5.2, Figs. 4.9-4.13) on the simulated outdoor path
``data/worlds/magnetic_path.yaml``: each of the four navigators of sec. 4.3.2 alone and the
multi-navigator system, taught on the scene's ``teach`` variant and played back on its
``playback`` variant (the bicycle park beside x = 96-110 m rearranged, as the thesis' runs "one
day later, with the geometric conditions changed").

Each trial (one seed): one teaching run (the route driven on the true pose; the linear map from
its odometry, magnetometer and laser, :func:`kiseki.magnetic.linear_map_from_run`), then one
playback per method with the same playback seed (the same odometry errors and sensor noise),
by :func:`kiseki.apps.magnetic.navigate_run.navigate` with its defaults: the odometry navigator on
the odometry's travel distance, the others on the travel-distance filter with the azimuth
heading reset (sec. 4.4). The navigators' gates are the thesis' (r_z >= 0.998,
|g_n - g_t| <= 1.0 m) and the scene is the issue's: neither is tuned here.

The robot "leaves the path" when its true cross-track error first exceeds ``leave_xte`` (the
thesis does not define it); "completes the route" when it reaches the goal without leaving.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from kiseki._support.inputs import YAML_LIMIT, read_input_text
from kiseki._support.yaml import safe_load_12
from kiseki.apps.magnetic.navigate_run import GATES, TaughtMaps, cross_track, navigate
from kiseki.core import derive_seed
from kiseki.magnetic.gates import reading_noise_sd
from kiseki.magnetic.linear_map import path_identity
from kiseki.magnetic.linear_map_run import linear_map_from_run
from kiseki.magnetic.navigators import NAVIGATORS, RZ_MIN
from kiseki.sim.magnetic import DEFAULT_NOISE_SD
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import PositiveReal, Real
from kiseki_experiments.harness.paths import WORLDS
from kiseki_experiments.harness.records import pack
from kiseki_experiments.magnav.magnav_navigators_claims import CLAIMS
from kiseki_experiments.magnav.magnav_navigators_report import analyze_navigators
from kiseki_experiments.magnav.magnav_table_4_2 import cut_route

__all__ = ["EXPERIMENT", "METHODS", "NavigatorsConfig", "closed_form_validity"]

SCENE = WORLDS / "magnetic_path.yaml"
METHODS = ("odometry", "geometric", "magnetic", "magnetic-geometric", "multi")
EVERY = 5  # the trajectories keep every 5th control step (0.3 m) for the figures


@dataclass(frozen=True)
class NavigatorsConfig:
    scene: str = str(SCENE)
    length: PositiveReal = 118.0  # m of the route (the whole route: 118 m)
    leave_xte: PositiveReal = 2.0  # m of |cross-track error| that counts as leaving the path
    changed_from: Real = 96.0  # m along the route: the bicycle park that changed
    changed_to: Real = 110.0
    landmark_free_from: Real = 20.0  # m: the stretch without buildings (scene header)
    landmark_free_to: Real = 95.0
    disturbed: PositiveReal = 0.02  # G: a node whose mz is this far from the median is disturbed
    # the magnetic navigators' validity: "thesis" (r_z >= 0.998) or "sensor" (kiseki's rule)
    gates: str = "thesis"
    # the claims' controls (magnav_navigators_claims): the scene variant played back, the
    # navigators the multi system arbitrates, the gate's limit times gate_scale, and random
    # nodes (as many as the disturbed ones) called disturbed
    variant: str = "playback"
    multi_navigators: list[str] = field(default_factory=lambda: list(NAVIGATORS))
    gate_scale: PositiveReal = 1.0
    disturbed_placebo: bool = False


def _cut_scene(config: NavigatorsConfig, folder: Path) -> tuple[Path, np.ndarray]:
    """The scene with its route cut to ``length`` m, written to ``folder``."""
    doc = safe_load_12(read_input_text(config.scene, "scene files", YAML_LIMIT))
    points = np.asarray(doc["route"]["waypoints"], dtype=np.float64)
    waypoints = cut_route(points, config.length)
    doc["route"]["waypoints"] = waypoints.tolist()
    path = folder / "scene.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path, waypoints


def preflight(config: NavigatorsConfig) -> None:
    if not Path(config.scene).is_file():
        raise FileNotFoundError(f"magnav-navigators: {config.scene} not found")
    if config.gates not in GATES:
        raise ValueError(f"magnav-navigators: gates must be one of {GATES}, got {config.gates!r}")
    if config.variant not in ("teach", "playback"):
        raise ValueError(
            f"magnav-navigators: variant must be teach or playback, got {config.variant!r}"
        )
    unknown = set(config.multi_navigators) - set(NAVIGATORS)
    if not config.multi_navigators or unknown:
        raise ValueError(
            f"magnav-navigators: multi_navigators must be some of {', '.join(NAVIGATORS)}, "
            f"got {config.multi_navigators}"
        )
    if config.length < 5.0:
        raise ValueError(f"magnav-navigators: length must be at least 5 m, got {config.length}")
    if not (config.changed_from < config.changed_to):
        raise ValueError("magnav-navigators: changed_from must be below changed_to")
    if not (config.landmark_free_from < config.landmark_free_to):
        raise ValueError("magnav-navigators: landmark_free_from must be below landmark_free_to")


def closed_form_validity(counts, noise_sd: float, gate: float = 1.0 - RZ_MIN) -> float:
    """The share of steps the r_z gate passes on noise alone: the reading (noise ``noise_sd``)
    minus a node averaging c readings (noise ``noise_sd / sqrt(c)``) is N(0, noise_sd^2 (1 +
    1/c)); P(|.| <= gate) = erf(gate / (sqrt(2) sd)), averaged over the nodes' counts."""
    c = np.maximum(np.asarray(counts, dtype=np.float64), 1.0)
    sd = noise_sd * np.sqrt(1.0 + 1.0 / c)
    return float(np.mean([math.erf(gate / (math.sqrt(2.0) * s)) for s in sd]))


def _teach(scene_path: Path, waypoints: np.ndarray, seed: int, folder: Path):
    run = folder / "teach.mcap"
    scene = load_scene(scene_path, "teach")
    simulate(scene, run, SimConfig(seed=seed), overwrite=True, progress=False)
    center = linear_map_from_run(run, path_identity(waypoints), provenance={"path": "center"})
    return TaughtMaps(center, None, None, waypoints)


def _validity(config, maps, result, seed: int) -> dict:
    """Shares of the multi run's steps on which each navigator was valid, by stretch."""
    p = result.priorities
    fresh = p[:, list(result.navigators).index("odometry")] > 0
    cols = {n: p[:, list(result.navigators).index(n)] > 0 for n in result.navigators}
    lmap = maps.center
    mz = lmap.field[:, 2]
    _, node_along = cross_track(maps.waypoints, lmap.position)  # the nodes' true places
    order = np.argsort(node_along, kind="stable")
    k = np.searchsorted(node_along[order], result.along_track).clip(0, len(lmap) - 1)
    node = order[k]
    disturbed = np.abs(mz - np.median(mz)) > config.disturbed
    if config.disturbed_placebo:  # as many nodes, drawn at random
        disturbed = np.random.default_rng(seed).permutation(disturbed)
    at_dist = disturbed[node]
    free = (result.along_track >= config.landmark_free_from) & (
        result.along_track <= config.landmark_free_to
    )
    park = (result.along_track >= config.changed_from) & (result.along_track <= config.changed_to)

    def share(flag, where):
        where = where & fresh
        if flag is None or not where.any():  # a navigator the multi system was not given
            return float("nan")
        return float(flag[where].mean())

    every = np.ones(len(fresh), dtype=bool)
    others = ~free & ~park
    quiet_nodes = ~disturbed
    return {
        "valid_magnetic": share(cols.get("magnetic"), every),
        "valid_magnetic_quiet": share(cols.get("magnetic"), ~at_dist),
        "valid_magnetic_disturbed": share(cols.get("magnetic"), at_dist),
        "valid_geometric": share(cols.get("geometric"), every),
        "valid_geometric_landmarks": share(cols.get("geometric"), others),
        "valid_geometric_free": share(cols.get("geometric"), free),
        "valid_geometric_park": share(cols.get("geometric"), park),
        "closed_form_quiet": closed_form_validity(lmap.count[quiet_nodes], _noise_sd(config)),
        "mean_node_count": float(np.mean(lmap.count[lmap.count > 0])),
    }


def _noise_sd(config: NavigatorsConfig) -> float:
    scene = load_scene(config.scene, "playback")
    mag = [s for s in scene.sensors if s.get("type") == "magnetometer"]
    return float(mag[0].get("noise_sd", DEFAULT_NOISE_SD)) if mag else DEFAULT_NOISE_SD


def trial(config: NavigatorsConfig, index: int, seed: int) -> TrialOutput:
    record: dict = {}
    with tempfile.TemporaryDirectory(prefix="magnav-nav-") as tmp:
        folder = Path(tmp)
        scene_path, waypoints = _cut_scene(config, folder)
        maps = _teach(scene_path, waypoints, derive_seed(seed, 0), folder)
        for method in METHODS:
            r = navigate(
                scene_path,
                maps,
                method,
                folder / f"{method}.mcap",
                derive_seed(seed, 1),
                gates=config.gates,
                variant=config.variant,
                navigators=tuple(config.multi_navigators),
                gate_scale=config.gate_scale,
            )
            xte = np.abs(r.cross_track)
            out = np.flatnonzero(xte > config.leave_xte)
            leave = float(r.along_track[out[0]]) if len(out) else float("nan")
            record[f"{method}:mean_xte"] = float(xte.mean())
            record[f"{method}:max_xte"] = float(xte.max())
            record[f"{method}:leave_at"] = leave
            record[f"{method}:reached_goal"] = bool(r.reached_goal)
            record[f"{method}:completed"] = bool(r.reached_goal and not len(out))
            record[f"{method}:travel_error"] = float(np.abs(r.travel_error).mean())
            record[f"{method}:end_along"] = float(r.along_track[-1])
            record[f"{method}:xy"] = pack(r.truth[::EVERY, :2])
            record[f"{method}:xte"] = pack(np.column_stack([r.along_track, r.cross_track])[::EVERY])
            if method == "multi":
                drove = np.array([d if d is not None else "" for d in r.drove])
                for name in NAVIGATORS:
                    record[f"multi:drove_{name}"] = float(np.mean(drove == name))
                record["multi:priorities"] = pack(np.column_stack([r.along_track, r.priorities]))
                record["multi:navigators"] = ",".join(r.navigators)
                valid = _validity(config, maps, r, derive_seed(seed, 2))
                record.update({f"multi:{k}": v for k, v in valid.items()})
        lmap = maps.center
        record["noise_sd_from_map"] = reading_noise_sd(lmap.field[:, 2], lmap.count)
        record["route_m"] = float(np.sum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1)))
    return TrialOutput(record)


def analyze(config: NavigatorsConfig, trials, timings, figures: Path) -> Analysis:
    return analyze_navigators(config, trials, figures, METHODS, _noise_sd(config))


EXPERIMENT = Experiment(
    name="magnav-navigators",
    paper="002_74cea16d239c028f.txt",
    artefact="Figs. 4.9-4.13",
    description="the four navigators alone and the multi-navigator system, bicycle park changed",
    config_type=NavigatorsConfig,
    trial=trial,
    analyze=analyze,
    default_runs=10,
    preflight=preflight,
    claims=CLAIMS,
)
