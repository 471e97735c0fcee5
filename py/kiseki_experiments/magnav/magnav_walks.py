# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnetic-walks: travel distance on recorded hand-held walks (Kok and Solin's ``eight.mat`` and
``square.mat``), the thesis' filter as printed beside kiseki's loop filter
(:mod:`kiseki.magnetic.loop_travel_distance`), with no reference positions given to kiseki's.

Trial i is walk i mod (number of walks) with the trial's seed, which draws the odometry
(:class:`kiseki.magnetic.travel_distance_walk.WalkOdometry`: scale error e ~ N(0, 0.05^2) per
walk, N(0, (0.1 |dp|)^2) per step) and the filters' randomness. Per trial, the along-track RMSE
(m, around the loop) of:

* ``thesis``: the thesis' filter (sec. 4.4.1, a = 50, l = 6 m), each later lap restarted at the
  map's start from the reference's lap boundaries (:func:`~kiseki.magnetic.travel_distance_walk.
  localize_walk`), and ``thesis_dr``, its dead reckoning (the same restarts);
* ``kiseki``: the loop filter from the loop's start, the rest of the walk as one stream;
  ``kiseki_global``: the same from an unknown start (uniform over the loop);
* ``dr``: the same odometry from the same start, continued around the loop (what a user has
  without a filter); ``dr_lap``: it restarted at each lap's true beginning (reference-aided);
* ``kiseki_e0`` and ``kiseki_e10``: the loop filter with the scale error fixed at 0 and at
  ``scale_error`` (the issue's 10 %), the same seed otherwise.

Claims, per walk, over 5 seeds each (a bootstrap interval of the mean of per-seed ratios):
kiseki / dr <= 0.5 (the issue's "at most half of dead reckoning's"); kiseki / dr_lap <= 0.5 (the
same against the baseline that is given the lap starts); kiseki_e10 / kiseki_e0 <= 1.2 (the
issue's scale target). Control for all three: ``use_field=false``, the loop filter without its
readings (odometry with the scale's prior), which must fail each.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path

from kiseki.datasets.kok import read_kok_walk
from kiseki.datasets.magnetic import MagneticSamples
from kiseki.magnetic.loop_travel_distance import LoopTravelConfig
from kiseki.magnetic.loop_walk import LoopWalkMap, localize_walk_loop, map_walk_loop
from kiseki.magnetic.travel_distance_walk import WalkOdometry, localize_walk
from kiseki_experiments.harness.base import Experiment, TrialOutput
from kiseki_experiments.harness.config import Particles, Real
from kiseki_experiments.harness.paths import shared_data
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion
from kiseki_experiments.magnav.magnav_walks_report import analyze

__all__ = ["EXPERIMENT", "WalksConfig", "WALKS"]

WALKS = ("eight", "square")


@dataclass(frozen=True)
class WalksConfig:
    data_dir: str = ""  # folder of the walks' .mat files; "" = ../shared/data/magnetic/kok_1d
    walks: list[str] = field(default_factory=lambda: list(WALKS))
    scale_error: Real = 0.10  # the 10 % odometry scale error arm
    particles: Particles = 1000
    use_field: bool = True  # the control: False, the loop filter without its readings


def _folder(config: WalksConfig) -> Path:
    return shared_data("magnetic/kok_1d", config.data_dir)


def preflight(config: WalksConfig) -> None:
    if not config.walks:
        raise ValueError("magnetic-walks: no walk named")
    folder = _folder(config)
    missing = [n for n in config.walks if not (folder / f"{n}.mat").is_file()]
    if missing:
        raise FileNotFoundError(f"magnetic-walks: {folder}: missing {', '.join(missing)}")
    if not -0.5 < config.scale_error < 0.5:
        raise ValueError(
            f"magnetic-walks: scale_error must be in (-0.5, 0.5), got {config.scale_error}"
        )


@functools.lru_cache(maxsize=4)
def _walk(path: str) -> tuple[MagneticSamples, LoopWalkMap]:
    """The walk and its mapping lap's loop, fitted once per process."""
    walk = read_kok_walk(path)
    return walk, map_walk_loop(walk)


def trial(config: WalksConfig, index: int, seed: int) -> TrialOutput:
    name = config.walks[index % len(config.walks)]
    walk, wm = _walk(str(_folder(config) / f"{name}.mat"))

    def loop(odometry: WalkOdometry, start: str = "known"):
        cfg = LoopTravelConfig(particles=config.particles, start=start)
        return localize_walk_loop(wm, seed, odometry, cfg, use_field=config.use_field)

    drawn = loop(WalkOdometry())
    thesis = localize_walk(walk, seed, WalkOdometry())
    record = {
        "walk": name,
        "seed": seed,
        "scale_error_drawn": drawn.scale_error,
        "loop_m": wm.length,
        "laps_localized": len(wm.laps.laps) - 1,
        "samples": len(drawn.t),
        "thesis": thesis.rmse("s_est"),
        "thesis_dr": thesis.rmse("s_odom"),
        "kiseki": drawn.rmse("s_est"),
        "dr": drawn.rmse("s_dr"),
        "dr_lap": drawn.rmse("s_dr_lap"),
        "kiseki_global": loop(WalkOdometry(), "global").rmse("s_est"),
        "kiseki_e0": loop(WalkOdometry(scale_error=0.0)).rmse("s_est"),
        "kiseki_e10": loop(WalkOdometry(scale_error=config.scale_error)).rmse("s_est"),
        "scale_estimate_drawn": float(drawn.scale[-1]),
    }
    return TrialOutput(record, {})


NO_FIELD = Control(
    name="the loop filter without its readings",
    overrides=("walks=square", "use_field=false"),
    runs=5,
    why="without the field the filter is odometry with a spread scale: its error is dead "
    "reckoning's, and it grows with the odometry's scale error",
)

CLAIMS = (
    ClaimSpec(
        key="half-of-dead-reckoning",
        claim="kiseki's loop filter's along-track RMSE is at most half of dead reckoning's "
        "(the same odometry from the same start, around the loop)",
        unit="RMSE ratio",
        criterion=Criterion(
            paper_value="(the issue's target)",
            compare="<=",
            threshold=0.5,
            why="the issue's target: at most half of dead reckoning's RMSE",
            bounds=(0.0, 100.0),
        ),
        control=NO_FIELD,
        measure="one seed's RMSE of the loop filter over that of dead reckoning",
    ),
    ClaimSpec(
        key="half-of-lap-dead-reckoning",
        claim="kiseki's loop filter's along-track RMSE is at most half of dead reckoning "
        "restarted at each lap's true beginning",
        unit="RMSE ratio",
        criterion=Criterion(
            paper_value="(the issue's target, against the reference-aided baseline)",
            compare="<=",
            threshold=0.5,
            why="the issue's target against the baseline of the thesis' filter on these walks",
            bounds=(0.0, 100.0),
        ),
        control=NO_FIELD,
        measure="one seed's RMSE of the loop filter over that of the restarted dead reckoning",
    ),
    ClaimSpec(
        key="scale-error",
        claim="with a 10 % odometry scale error, kiseki's loop filter's RMSE is at most 1.2x "
        "its RMSE without it",
        unit="RMSE ratio",
        criterion=Criterion(
            paper_value="(the issue's target)",
            compare="<=",
            threshold=1.2,
            why="the issue's target for an odometry scale error of 10 %",
            bounds=(0.0, 100.0),
        ),
        control=NO_FIELD,
        measure="one seed's RMSE with the scale error over that without it",
    ),
)

EXPERIMENT = Experiment(
    name="magnetic-walks",
    paper="002_74cea16d239c028f.txt",
    artefact="sec. 4.4.1 on recorded hand-held walks (beyond the thesis)",
    description="travel distance on real walks: the thesis' filter and kiseki's loop filter",
    config_type=WalksConfig,
    trial=trial,
    analyze=analyze,
    # 61 seeds per walk: at 5 the eight walk's two ratio claims were undecided and the report
    # asked 17 and 61 per walk (184 s) (issue 29: the default trials decide at least 80 % of
    # the claims)
    default_runs=122,
    preflight=preflight,
    claims=CLAIMS,
)
