# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The config of mcl-kidnapping and mcl-kidnapping-carmen
(kiseki_experiments.mcl.mcl_kidnapping) and its checks before a run."""

from __future__ import annotations

from dataclasses import dataclass, field

from kiseki.filters import RECOVERY_MODES, RELIABILITY_ESTIMATES, LocalizeConfig
from kiseki_experiments.harness.config import (
    Count,
    NonNegativeReal,
    Particles,
    PositiveReal,
    Real,
    Scans,
    Threads,
)
from kiseki_experiments.harness.paths import CARMEN_LOGS, PROJECT, shared_data

__all__ = [
    "BLIND_RELIABILITY",
    "CarmenKidnapConfig",
    "KidnapConfig",
    "preflight_carmen",
    "preflight_sim",
]

# The blind control's estimate: about the share of localised updates in the learned fits
# (0.682 in simulation, 0.693-0.727 on the recorded logs), which an estimate that ignores the
# scan would have to say to be calibrated.
BLIND_RELIABILITY = 0.7


@dataclass(frozen=True)
class KidnapConfig:
    scene: str = "data/worlds/factory_turn.yaml"  # mcl-kidnapping: relative to the project
    data_dir: str = ""  # mcl-kidnapping-carmen: folder of the logs; "" = ../shared/data/carmen
    logs: list[str] = field(default_factory=lambda: list(CARMEN_LOGS))
    method: str = "likelihood-field"
    particles: Particles = 1000
    beams: Count = 90
    # "resetting+injection": resetting with Augmented MCL's injection as well
    recoveries: list[str] = field(default_factory=lambda: [*RECOVERY_MODES, "resetting+injection"])
    odometry_noise: NonNegativeReal = 0.1  # CARMEN: added to the corrected poses' increments
    min_jump: NonNegativeReal = 2.0  # m between the pose before and after the kidnapping
    before_scans: Scans = 200  # scans of tracking before the kidnapping (at most)
    after_scans: Scans = 400  # scans after it (at most)
    min_after: Scans = 80  # a trial needs at least this many scans after the jump
    recover_distance: PositiveReal = 0.5  # m
    recover_heading: PositiveReal = 10.0  # deg
    recover_hold: Scans = 10  # updates
    threads: Threads = 1  # per trial (trials run in parallel)
    # the sensor reset's candidates (uniform or matcher) and its look-elsewhere term
    sensor_reset_proposal: str = LocalizeConfig.sensor_reset_proposal
    # with the matcher: a search on every this-many-th sensor reset of a lost spell
    matcher_search_every: Count = LocalizeConfig.matcher_search_every
    reset_look_elsewhere: bool = LocalizeConfig.reset_look_elsewhere
    # the resets' agreement check and confirmation (false: the resets before them)
    reset_needs_agreement: bool = LocalizeConfig.reset_needs_agreement
    sensor_reset_confirm: bool = LocalizeConfig.sensor_reset_confirm
    # with method ray-space-observation: resets judged by penetration only (LocalizeConfig),
    # in the resetting arms
    intrusion_tolerant_resets: bool = LocalizeConfig.intrusion_tolerant_resets
    # the claims' controls: the recovery that runs in the arm named "resetting", and whether
    # the robot is carried at all (false: the log goes on from scan k, no jump)
    resetting_runs: str = "resetting"
    kidnap: bool = True
    # the reliability reported: "learned" or "learned-real" (kiseki.filters.reliability) or
    # the engine's "agreement" (the engine's is recorded too); the learned one's controls: its
    # log-likelihood drop weighed by drop_weight (0: agreement alone) and its log-odds moved
    # by odds_offset
    reliability: str = "learned"
    drop_weight: NonNegativeReal = 1.0
    odds_offset: Real = 0.0
    # a control: the learned estimate blind to the scan, BLIND_RELIABILITY at every update
    blind: bool = False


@dataclass(frozen=True)
class CarmenKidnapConfig(KidnapConfig):
    """mcl-kidnapping-carmen's config: on recorded logs the reliability reported is the one
    fitted on recorded logs, each trial's with its own log left out of the fit."""

    reliability: str = "learned-real"


def _check(config: KidnapConfig) -> None:
    for r in [*config.recoveries, config.resetting_runs]:
        if r not in (*RECOVERY_MODES, "resetting+injection"):
            raise ValueError(f"kidnapping: unknown recovery {r!r} ({', '.join(RECOVERY_MODES)})")
    if not config.recoveries:
        raise ValueError("kidnapping: recoveries is empty")
    if config.reliability not in RELIABILITY_ESTIMATES:
        raise ValueError(f"kidnapping: reliability must be one of {RELIABILITY_ESTIMATES}")
    if not (config.min_jump > 0 and config.recover_distance > 0 and config.recover_hold >= 1):
        raise ValueError("kidnapping: min_jump, recover_distance and recover_hold must be > 0")
    if config.before_scans < 20 or config.after_scans < config.min_after:
        raise ValueError("kidnapping: need before_scans >= 20 and after_scans >= min_after")
    # each arm's settings as LocalizeConfig checks them (ValueError naming the problem)
    arms = [arm_recovery(config, arm) for arm in config.recoveries]
    for settings in arms:
        LocalizeConfig(method=config.method, reliability=config.reliability, **settings)
    if config.intrusion_tolerant_resets and not any(a["intrusion_tolerant_resets"] for a in arms):
        raise ValueError("kidnapping: intrusion_tolerant_resets applies to no arm (no resetting)")


def arm_recovery(config: KidnapConfig, arm: str) -> dict:
    """LocalizeConfig's recovery settings of one arm (the arm "resetting" runs
    ``resetting_runs``, its control's switch)."""
    recovery = config.resetting_runs if arm == "resetting" else arm
    base = recovery.split("+")[0]
    return {
        "recovery": base,
        "resetting_injects": recovery == "resetting+injection",
        "intrusion_tolerant_resets": config.intrusion_tolerant_resets and base == "resetting",
    }


def preflight_sim(config: KidnapConfig) -> None:
    _check(config)
    path = PROJECT / config.scene
    if not path.is_file():
        raise FileNotFoundError(f"mcl-kidnapping: scene {path} not found")


def preflight_carmen(config: KidnapConfig) -> None:
    _check(config)
    folder = shared_data("carmen", config.data_dir)
    missing = [n for n in config.logs if not (folder / f"{n}.log.gz").is_file()]
    if missing:
        raise FileNotFoundError(f"mcl-kidnapping-carmen: {folder}: missing {', '.join(missing)}")
