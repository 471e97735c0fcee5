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
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.apps.teach import PlaybackConfig, playback, teach
from kiseki.core import derive_seed
from kiseki.io.ros_map import load_map
from kiseki.sim.scene import load_scene
from kiseki.teach.environment_map import MERGE_RULES
from kiseki.teach.local_maps import METHODS
from kiseki.teach.route_check import travelled_poses
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.verdict import Evidence
from kiseki_experiments.teach.teach_boxes import (  # noqa: F401 (tp.BOX_*)
    BOX_OFFSET_M,
    BOX_SIZE_M,
    boxes_beside_final_leg,
    with_boxes,
)
from kiseki_experiments.teach.teach_goal_profile import (  # noqa: F401 (tp.PROFILE_OFFSETS)
    PROFILE_OFFSETS,
    goal_profile,
)
from kiseki_experiments.teach.teach_goal_profile import profile_figure as _profile_figure
from kiseki_experiments.teach.teach_playback_claims import (  # noqa: F401 (tp.X for the tests)
    ALL_CONVENTIONAL,
    EXP1_CLAIMS,
    EXP2_CLAIMS,
    EXP3_CLAIMS,
    STOP_TOLERANCE_M,
    THESIS_ODOMETRY_P2_M,
    THESIS_ODOMETRY_Y_WORST_M,
    THESIS_RUNS,
    THESIS_TABLE_4_5,
    THESIS_TABLE_4_7,
    exp2_evidence,
    exp3_evidence,
)
from kiseki_experiments.teach.teach_playback_config import (  # noqa: F401 (tp.X)
    RAY_MODEL,
    Exp1Config,
    Exp2Config,
    Exp3Config,
    stand_ins,
)
from kiseki_experiments.teach.teach_playback_tables import (  # noqa: F401 (tp.TAUGHT_SHARES)
    TAUGHT_SHARES,
    diagnosis,
    diagnostics_table,
    stop_figure,
    stop_table,
    taught_table,
)


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
        "collided": result.collision is not None,  # the run ended on an obstacle
    }


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
            for key in TAUGHT_SHARES:
                record[f"taught_{band}_{key}"] = t[key]
        play_file = scene_file
        if config.boxes:
            play_file = with_boxes(scene_file, config.boxes, derive_seed(seed, 3), Path(tmp))
            record.update(boxes_beside_final_leg(play_file))
        scene = load_scene(play_file, "playback")
        maps = {band: load_map(path) for band, path in taught.maps.items()}
        goal = taught.marks[-1]
        before = taught.marks[-2] if len(taught.marks) > 1 else goal
        record["final_leg_m"] = math.hypot(goal["x"] - before["x"], goal["y"] - before["y"])
        played, runs = stand_ins(config), {}
        travelled = travelled_poses(taught.log)
        for method in methods:
            actual = played.get(method, method)  # a negative control plays another method
            if actual not in runs:  # a method played twice on one seed is the same run
                runs[actual] = _play(config, scene, maps, taught, actual, seed, travelled)
            identity, out = runs[actual]
            record.update(identity)
            record.update({f"{method}_{k}": v for k, v in out.items()})
            if getattr(config, "ray", False):
                _, ray = _play(config, scene, maps, taught, actual, seed, travelled, RAY_MODEL)
                record.update({f"{method}_ray_{k}": v for k, v in ray.items()})
    return TrialOutput(record)


def _play(
    config, scene, maps, taught, method: str, seed: int, travelled, model: str = "space-observation"
) -> tuple[dict, dict]:
    """One playback of `method` on the trial's taught maps (and, with boxes and the thesis'
    model, the same run without them): which scene it played in, and its record (keys without
    the method). With kiseki's ray model (`model`), only the stop and estimate errors.
    `travelled`: the teaching run's odometry poses, for the route check."""
    goal = taught.marks[-1]
    band, _ = METHODS[method]
    play = PlaybackConfig(
        method=method,
        particles=config.particles,
        seed=derive_seed(seed, 2),
        model=model,
        scan_beams=getattr(config, "ray_beams", PlaybackConfig.scan_beams),
        scan_range_scale=getattr(config, "ray_range_scale", PlaybackConfig.scan_range_scale),
    )
    result = playback(
        scene,
        maps[band],
        taught.marks,
        play,
        taught_scene=taught.scene,
        variant="exp3-boxes" if config.boxes else None,  # the copy with the boxes
        travelled=travelled,
    )
    # which scene file it played in: its SHA-1 and the variant label of a changed copy
    identity = {
        "scene_sha1": result.scene_identity["scene_sha1"],
        "scene_variant": result.scene_identity.get("variant", ""),
    }
    out = dict(_errors(result, goal))
    if model == RAY_MODEL:
        return identity, out
    out.update(goal_profile(scene, maps[band], goal, method))
    if config.boxes and getattr(config, "without_boxes", True):  # the same run without them
        plain = load_scene(Path(config.scene), "playback")
        control = playback(
            plain, maps[band], taught.marks, play, taught_scene=taught.scene, travelled=travelled
        )
        for k, v in _errors(control, goal).items():
            if k.startswith("stop_"):
                out[f"nobox_{k}"] = v
    for name, poses in result.passes.items():
        mark = next(m for m in taught.marks if m["name"] == name)
        t, e, o = poses["true"], poses["estimate"], poses["odometry"]
        # localization error: the estimate's offset from the waypoint minus the truth's
        out[f"{name}_loc_dx"] = (e[0] - mark["x"]) - (t[0] - mark["truth"][0])
        out[f"{name}_loc_dy"] = (e[1] - mark["y"]) - (t[1] - mark["truth"][1])
        out[f"{name}_odo_dx"] = o[0] - t[0]
        out[f"{name}_odo_dy"] = o[1] - t[1]
    return identity, out


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
    stops = stop_table(config, ok)
    within = int(stops.iloc[0]["stops_within_0.1m"])
    loc = np.hypot(ok[f"{m}_P2_loc_dx"], ok[f"{m}_P2_loc_dy"])
    odo = np.hypot(ok[f"{m}_P2_odo_dx"], ok[f"{m}_P2_odo_dy"])
    evidence = [Evidence.share("exp1_within", within, len(ok), shown=f"{within}/{len(ok)}")]
    errors.loc[errors["point"] == "P2", "odo_minus_loc_mean_m"] = float((odo - loc).mean())
    notes = (
        "Localization error: the estimate's offset from the taught waypoint minus the true "
        "offset, when the estimate passes the waypoint. Odometry error: playback odometry "
        f"minus truth. The thesis' odometry y reached {THESIS_ODOMETRY_Y_WORST_M:+.2f} m in "
        "one run; ours: "
        f"{errors.iloc[1]['odo_dy_max_abs']:.3f} m at most. Whether the odometry error at P2 "
        f"is mostly sideways (thesis: x {THESIS_ODOMETRY_P2_M[0]:+.2f}, y "
        f"{THESIS_ODOMETRY_P2_M[1]:+.2f} m) is a table row (`errors_at_waypoints`), not a "
        "claim: no change to the localization method changes the odometry. So is whether "
        "the localization error at P2 is smaller than the odometry's (odo_minus_loc_mean_m, "
        "per run |odometry - truth| - |estimate's offset - true offset|): dead reckoning "
        "(one particle) left it undecided, not failed, so no control fails it."
    )
    diag = diagnostics_table(config, ok)
    return Analysis(
        tables={
            "errors_at_waypoints": errors,
            "stops": stops,
            "diagnostics": diag,
            "taught_maps": taught_table(config, ok),
        },
        figures=[stop_figure(config, ok, figures), _profile_figure(config, ok, figures)],
        evidence=evidence,
        notes=notes + "\n\n" + diagnosis(diag, ok, turn_route=False),
    )


def analyze_exp2(config, trials, timings, figures) -> Analysis:
    ok = trials[trials["error"].isna()]
    stops = stop_table(config, ok)
    thesis = pd.DataFrame(
        [
            {"method": m, "thesis_stop_error_mean_m": v[0], "thesis_stops_within_0.1m": v[3]}
            for m, v in THESIS_TABLE_4_5.items()
        ]
    )
    stops = stops.merge(thesis, on="method", how="left")
    diag = diagnostics_table(config, ok)
    return Analysis(
        tables={"stops": stops, "diagnostics": diag, "taught_maps": taught_table(config, ok)},
        figures=[stop_figure(config, ok, figures), _profile_figure(config, ok, figures)],
        evidence=exp2_evidence(ok, set(config.methods)),
        notes=f"Thesis Tables 4.5/4.6: {THESIS_RUNS} runs per method; 'both' is not in the "
        "thesis. Each method's own stop error and share within 0.1 m (with its 95 % Wilson "
        "interval) stand in table `stops` beside the thesis' (table rows, not claims: the "
        "thesis' findings are the comparisons between methods).\n\n" + diagnosis(diag, ok),
    )


def analyze_exp3(config, trials, timings, figures) -> Analysis:
    ok = trials[trials["error"].isna()]
    stops = stop_table(config, ok)
    thesis = pd.DataFrame(
        [
            {
                "method": m,
                "thesis_stop_error_mean_m": v[0],
                "thesis_stop_error_sd_m": v[1],
                "thesis_estimate_error_mean_m": v[2],
            }  # fmt: skip
            for m, v in THESIS_TABLE_4_7.items()
        ]
    )
    stops = stops.merge(thesis, on="method", how="left")
    diag = diagnostics_table(config, ok)
    m = config.methods[0]
    cols = ["final_leg_boxes_left", "final_leg_boxes_right", f"{m}_stop_dx", f"{m}_stop_dy"]
    cols += [c for c in (f"{m}_nobox_stop_dx", f"{m}_nobox_stop_dy") if c in ok]
    boxes = ok[["trial", *cols]] if "final_leg_boxes_left" in ok else pd.DataFrame()
    size = " x ".join(f"{v:g}" for v in BOX_SIZE_M)
    shift = [
        float(
            np.hypot(
                ok[f"{m}_stop_dx"] - ok[f"{m}_nobox_stop_dx"],
                ok[f"{m}_stop_dy"] - ok[f"{m}_nobox_stop_dy"],
            ).max()
        )
        for m in config.methods
        if f"{m}_nobox_stop_dx" in ok
    ]
    notes = (
        f"{config.boxes} {size} m boxes per run, only in playback, {BOX_OFFSET_M[0]:g}-"
        f"{BOX_OFFSET_M[1]:g} m beside a random route leg (the thesis moved three cardboard "
        "boxes between runs; their positions are not given). Table `boxes_final_leg` compares "
        "each run with the same run without the boxes (same teaching, same seeds). A box in "
        "front of an aisle wall hides the wall from the sideways camera; the intrusion term, "
        "which the thesis makes cheap, is what resists the pose sliding toward the box."
        + (
            f" In these runs the boxes moved the stop by at most {max(shift):.3f} m."
            if shift
            else ""
        )
        + "\n\n"
        + diagnosis(diag, ok)
    )
    return Analysis(
        tables={
            "stops": stops,
            "diagnostics": diag,
            "boxes_final_leg": boxes,
            "taught_maps": taught_table(config, ok),
        },
        figures=[stop_figure(config, ok, figures), _profile_figure(config, ok, figures)],
        notes=notes,
        evidence=exp3_evidence(ok, config.methods),
    )


def _preflight(config: Exp1Config) -> None:
    if not Path(config.scene).is_file():
        raise FileNotFoundError(f"scene {config.scene} not found")
    for m in config.methods or []:
        if m not in METHODS:
            raise ValueError(f"unknown method {m!r} (known: {', '.join(METHODS)})")
    if config.merge not in MERGE_RULES:
        raise ValueError(f"unknown merge rule {config.merge!r} (known: {', '.join(MERGE_RULES)})")
    stand_ins(config)  # a malformed `plays` stops here, named


EXP1 = Experiment(
    name="exp1-corridor",
    paper="000_7c5a0f8de3fa28f5.txt",
    artefact="Tables 4.1-4.4",
    description="corridor P0 -> P1 -> P2, proposal 2: localization vs odometry error, stops",
    config_type=Exp1Config,
    trial=trial,
    analyze=analyze_exp1,
    # 15: at the thesis' 11 runs the share of stops within 0.1 m (10 of 11) was undecided and the
    # report asked 15 (51 s) (issue 29: the default trials decide at least 80 % of the claims)
    default_runs=15,
    preflight=_preflight,
    claims=EXP1_CLAIMS,
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
    claims=EXP2_CLAIMS,
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
    claims=EXP3_CLAIMS,
)
