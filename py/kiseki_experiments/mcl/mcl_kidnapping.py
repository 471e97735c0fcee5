# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""mcl-kidnapping: the kidnapped robot, in simulation and on real logs, for the three recovery
settings of kiseki's Monte Carlo engine (none, Augmented MCL, expansion + sensor resetting),
with the engine's reliability estimate before and after the jump; and resetting with Augmented
MCL's injection added (``resetting+injection``).

A trial makes one log and splices it: the scans up to the kidnapping (scan k) are followed by
the scans from another place of the same run (scan j, at least ``min_jump`` metres away), while
the odometry goes on as if nothing had happened (the increment across the seam is the one the
robot made at j). The filter tracks from the log's reference pose at the start of the spliced
log, with the same map, model, particles and seed for every recovery setting. A trial
*recovers* when the estimate is back within ``recover_distance`` (0.5 m) and
``recover_heading`` (10 deg) of the truth and stays there for ``recover_hold`` (10) updates; the
recovery time is from the jump to the first of those updates.

* ``mcl-kidnapping``: simulated runs of a scene with a 2-D laser (default the thesis' factory
  aisle with the turn, `data/worlds/factory_turn.yaml`), one run per trial (its seed drives the
  robot's odometry error and the laser noise); the map is the scene's ground truth at the
  laser's height (0.05 m cells). The run's odometry is the robot's; the laser's is that
  composed with the laser's mount.
* ``mcl-kidnapping-carmen``: the four CARMEN logs, trial i on log i mod 4 with its own seed; the
  map is built from the corrected poses (0.05 m), the odometry is rebuilt from them with noise
  (F = 0.1 of each increment, as the README's runs).

The config and its checks are in ``mcl_kidnapping_config``, the claims in
``mcl_kidnapping_claims``, the tables, figures and evidence in ``mcl_kidnapping_report``.
"""

from __future__ import annotations

import copy
import math
import tempfile
from pathlib import Path

import numpy as np

from kiseki.core import Pose2, derive_seed
from kiseki.datasets import read_carmen_log
from kiseki.filters import (
    LEARNED_RELIABILITY,
    LocalizeConfig,
    ReliabilityModel,
    localize,
)
from kiseki.filters.reliability import learned_model
from kiseki.grid import OccupancyGrid
from kiseki.io.runlog import read_run
from kiseki.mapping import MapBuildConfig, map_of_log
from kiseki.scans import LaserScans
from kiseki.sim.run import SimConfig, simulate
from kiseki.sim.scene import load_scene
from kiseki_experiments.harness.base import Experiment, TrialOutput
from kiseki_experiments.harness.paths import CARMEN_LOGS, PROJECT, shared_data
from kiseki_experiments.mcl.mcl_kidnapping_claims import CARMEN_CLAIMS, SIM_CLAIMS
from kiseki_experiments.mcl.mcl_kidnapping_config import (
    BLIND_RELIABILITY,
    CarmenKidnapConfig,
    KidnapConfig,
    arm_recovery,
    preflight_carmen,
    preflight_sim,
)
from kiseki_experiments.mcl.mcl_kidnapping_report import analyze
from kiseki_experiments.mcl.mcl_reliability_folds import REAL_LOG_FOLDS


def splice(scans: LaserScans, k: int, j: int, before: int, after: int) -> LaserScans:
    """Scans [k - before, k) then [j, j + after): the robot is carried from scan k to scan j's
    place, and the odometry, which does not see it, goes on from scan k - 1 with the
    increments the robot made from scan j - 1 on."""
    start, stop = max(0, k - before), min(len(scans), j + after)
    head = np.arange(start, k)
    tail = np.arange(j, stop)
    odom = [scans.odometry[i] for i in head]
    anchor = Pose2(*scans.odometry[k - 1])
    origin = Pose2(*scans.odometry[j - 1]).inverse()
    odom += [(anchor * (origin * Pose2(*scans.odometry[i]))).to_array() for i in tail]
    index = np.concatenate([head, tail])
    times = np.concatenate(
        [scans.times[head], scans.times[k - 1] + (scans.times[tail] - scans.times[j - 1])]
    )
    return LaserScans(
        times,
        scans.poses[index],
        np.array(odom),
        np.ascontiguousarray(scans.ranges[index]),
        scans.angles,
        scans.max_range,
    )


def choose_jump(scans: LaserScans, config: KidnapConfig, seed: int) -> tuple[int, int]:
    """The kidnapping scan k (after 20 % of the run, with 20 scans of tracking) and the scan j it
    is carried to: min_jump away, with min_after scans left."""
    rng = np.random.default_rng(derive_seed(seed, 7))
    n = len(scans)
    for _ in range(1000):
        k = int(rng.uniform(max(20, 0.2 * n), max(21, 0.6 * n)))
        far = np.hypot(*(scans.poses[:, :2] - scans.poses[k, :2]).T) >= config.min_jump
        ok = np.flatnonzero(far[1 : n - config.min_after]) + 1
        if k < n and ok.size:
            return k, int(ok[int(rng.uniform(0, ok.size))])
    raise ValueError("kidnapping: the run has no two places min_jump apart with scans left")


def _recovery(errors: np.ndarray, headings: np.ndarray, seam: int, config: KidnapConfig):
    """Updates from the jump to the first of recover_hold in a row within the tolerances."""
    good = (errors < config.recover_distance) & (headings < config.recover_heading)
    run = 0
    for i in range(seam, len(good)):
        run = run + 1 if good[i] else 0
        if run >= config.recover_hold:
            return i - config.recover_hold + 1 - seam
    return None


def _trial(scans: LaserScans, grid, config: KidnapConfig, seed: int, name: str) -> TrialOutput:
    k, j = choose_jump(scans, config, seed)
    if not config.kidnap:  # the control: no jump, the log goes on
        j = k
    spliced = splice(scans, k, j, config.before_scans, config.after_scans)
    seam = min(k, config.before_scans)
    jump = float(np.hypot(*(scans.poses[j, :2] - scans.poses[k, :2])))
    record: dict = {"source": name, "kidnap_scan": k, "to_scan": j, "jump_m": jump}
    timings: dict = {}
    for arm in config.recoveries:
        recovery = config.resetting_runs if arm == "resetting" else arm
        lc = LocalizeConfig(
            method=config.method,
            seed=seed,
            odometry_noise=config.odometry_noise if name != "sim" else 0.0,
            particles=config.particles,
            beams=config.beams,
            **arm_recovery(config, arm),
            sensor_reset_proposal=config.sensor_reset_proposal,
            matcher_search_every=config.matcher_search_every,
            reset_look_elsewhere=config.reset_look_elsewhere,
            reset_needs_agreement=config.reset_needs_agreement,
            sensor_reset_confirm=config.sensor_reset_confirm,
            threads=config.threads,
            reliability=config.reliability,
        )
        result = localize(spliced, grid, lc, reliability_model=_reliability_model(config, name))
        d = result.estimates - spliced.poses
        errors = np.hypot(d[:, 0], d[:, 1])
        headings = np.degrees(np.abs(np.remainder(d[:, 2] + np.pi, 2 * np.pi) - np.pi))
        steps = _recovery(errors, headings, seam, config)
        rel = result.reliability
        recovery = arm  # recorded under the arm's name
        record |= _reliability_record(arm, result, errors, headings, seam)
        record |= {
            f"{recovery}_tracked_before": bool(errors[seam - 10 : seam].max() < 0.5),
            f"{recovery}_recovered": steps is not None,
            f"{recovery}_recovery_scans": -1 if steps is None else int(steps),
            f"{recovery}_reliability_before": float(rel[seam - 10 : seam].mean()),
            # the mean over the 10 updates from the jump on (every scan is an update here)
            f"{recovery}_reliability_after": float(rel[seam : seam + 10].mean()),
            f"{recovery}_final_error_m": float(errors[-1]),
            f"{recovery}_errors": [round(float(e), 3) for e in errors[seam - 20 :]],
            f"{recovery}_reliability": [round(float(r), 3) for r in rel[seam - 20 :]],
        }
        timings[f"{recovery}_ms_per_update"] = 1000.0 * float(np.mean(result.update_seconds))
    return TrialOutput(record, timings)


def _reliability_model(config: KidnapConfig, log: str) -> ReliabilityModel:
    """The learned estimate's coefficients for a trial on ``log`` ("sim" for a simulated run):
    with ``learned-real``, those fitted without that log (leave one log out; a log none of
    them was fitted on gets the model of every log); then the controls' changes."""
    if config.blind:  # the control: no feature moves it
        odds = math.log(BLIND_RELIABILITY / (1.0 - BLIND_RELIABILITY))
        return ReliabilityModel((odds, 0.0, 0.0), "blind to the scan (a control)")
    base = learned_model(config.reliability) or LEARNED_RELIABILITY
    if config.reliability == "learned-real":
        base = REAL_LOG_FOLDS.get(log, base)
    b0, b_agreement, b_drop = base.coefficients
    return ReliabilityModel(
        (b0 + config.odds_offset, b_agreement, b_drop * config.drop_weight), base.provenance
    )


def _reliability_record(arm: str, result, errors, headings, seam: int) -> dict:
    """What the reliability claims count, for the reported estimate and the engine's: whether
    the filter was more than 1 m off at each of the 10 updates from the jump, whether the
    estimate fell below 0.5 within them, and how many updates tracked within 0.3 m (and 10 deg)
    read above 0.9."""
    window = slice(seam, seam + 10)
    tracking = result.updated & (errors < 0.3) & (headings < 10.0)
    out = {f"{arm}_lost_after": bool(errors[window].min() > 1.0)}
    out[f"{arm}_tracking_updates"] = int(tracking.sum())
    for name, rel in (("", result.reliability), ("agreement_", result.agreement_reliability)):
        out[f"{arm}_{name}low_within_10"] = bool((rel[window] < 0.5).any())
        out[f"{arm}_{name}tracking_high"] = int((rel[tracking] > 0.9).sum())
    out[f"{arm}_agreement_reliability_after"] = float(result.agreement_reliability[window].mean())
    out[f"{arm}_agreement_reliability"] = [
        round(float(r), 3) for r in result.agreement_reliability[seam - 20 :]
    ]
    return out


def _laser_mount(spec: dict) -> Pose2:
    for s in spec.get("sensors", []):
        if s.get("type") == "laser":
            x, y, _z, yaw = (list(s.get("mount", [0, 0, 0, 0])) + [0, 0, 0, 0])[:4]
            return Pose2(float(x), float(y), math.radians(float(yaw)))
    raise ValueError("mcl-kidnapping: the scene's robot has no laser")


def trial_sim(config: KidnapConfig, index: int, seed: int) -> TrialOutput:
    """One simulated run of the scene (laser only), spliced and tracked."""
    scans, grid = simulated_run(config.scene, seed)
    return _trial(scans, grid, config, seed, "sim")


def simulated_run(scene_path: str, seed: int) -> tuple[LaserScans, OccupancyGrid]:
    """One simulated run of a scene (laser only; path relative to the project): its scans,
    with the laser's odometry and reference poses, and the map (the scene's ground truth at
    the laser's height, 0.05 m cells)."""
    scene = load_scene(PROJECT / scene_path)
    spec = dict(scene.robot_specs[0])
    spec["sensors"] = [s for s in spec.get("sensors", []) if s.get("type") == "laser"]
    mount = _laser_mount(spec)
    scene = copy.copy(scene)
    scene.robot_specs = [spec]
    with tempfile.TemporaryDirectory() as tmp:
        simulate(scene, Path(tmp) / "run.mcap", SimConfig(seed=seed), progress=False)
        scans = read_run(Path(tmp) / "run.mcap").laser_scans()
    odometry = np.array([(Pose2(*o) * mount).to_array() for o in scans.odometry])
    scans = LaserScans(
        scans.times, scans.poses, odometry, scans.ranges, scans.angles, scans.max_range
    )
    return scans, scene.ground_truth(0.35, 0.45, resolution=0.05)


def trial_carmen(config: CarmenKidnapConfig, index: int, seed: int) -> TrialOutput:
    name = config.logs[index % len(config.logs)]
    path = shared_data("carmen", config.data_dir) / f"{name}.log.gz"
    scans = read_carmen_log(path).scans
    grid = map_of_log(scans, MapBuildConfig(resolution=0.05))
    return _trial(scans, grid, config, seed, name)


SIM = Experiment(
    name="mcl-kidnapping",
    paper="localization engine (beyond the papers)",
    artefact="kidnapped robot, simulated factory aisle",
    description="kidnapping recovery and reliability: none / augmented / resetting (simulation)",
    config_type=KidnapConfig,
    trial=trial_sim,
    analyze=analyze,
    # resetting recovered 50 of 50 (the README's run): Wilson's lower end is then 0.929, below
    # 0.95; from 73 of 73 on it is above (n / (n + 1.96^2) >= 0.95): 80 decide it
    default_runs=80,
    preflight=preflight_sim,
    claims=SIM_CLAIMS,
)

CARMEN = Experiment(
    name="mcl-kidnapping-carmen",
    paper="localization engine (beyond the papers)",
    artefact="kidnapped robot, CARMEN logs",
    description="kidnapping recovery and reliability: none / augmented / resetting (real logs)",
    config_type=CarmenKidnapConfig,
    trial=trial_carmen,
    analyze=analyze,
    default_runs=20 * len(CARMEN_LOGS),  # as the simulated runs: 80 decide a share >= 0.95
    preflight=preflight_carmen,
    claims=CARMEN_CLAIMS,
)
