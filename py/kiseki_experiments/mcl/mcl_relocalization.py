# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""mcl-relocalization: global relocalization from one scan on the shared CARMEN logs.

Each trial is one log (trial i: log i mod 4) and ``scans`` scans of it drawn by the trial's
seed, spread over the log: the log is cut into ``scans`` equal runs of consecutive scans and one
scan is drawn uniformly from each run. The map is the log's own (:func:`map_of_log` at
``resolution``), the matcher :class:`kiseki.filters.Relocalizer` with RelocalizeConfig's
defaults (60 beams, the likelihood field's parameters, ``top`` hypotheses), and the reference
pose is the log's corrected pose of the scan. Per scan:

* the best hypothesis' position and heading errors; the rank (1..``top``) of the first
  hypothesis within ``hit_distance`` and ``hit_angle_deg`` of the reference pose, 0 for none;
* ``truth``: the score (the likelihood field's log-likelihood of the scan, the matcher's beams
  and parameters) at the reference pose itself, which lies off the search lattice;
* ``near``: the best score of a lattice pose whose position is within ``near_radius`` (1 m)
  of the reference position, at any heading; ``far``: the best score of a lattice pose more than
  ``near_radius`` from it. Both are exact: the branch-and-bound searches restricted to each side
  of that disc (:class:`kiseki.filters.SearchDisc`) find the same maximum as scoring every
  lattice pose would (tested against a brute force). A top-k list is not exact for ``far``:
  the k-th distinct pose near the truth can push a far pose out of any fixed k.

*Identifiable* (the issue's "no pose more than 1 m from the truth scores within 5 % of the
truth's score"): the truth's score is taken as ``near``, the best the matcher could return near
the truth (the reference pose is off the lattice; its own score is recorded too, and the share
identifiable by it is reported beside). The score is a sum of log densities (1/m), so it is
positive when beams end close to walls and has no natural zero; "within 5 %" is read on its
magnitude: a scan is identifiable when ``far < near - score_tolerance * |near|``.

Claims: (a) per log, among the identifiable scans, the best hypothesis is within 0.3 m and 5 deg
for at least 90 %; (b) over all scans of all logs, a hypothesis of the top 5 is within 0.3 m and
5 deg for at least 99 % (a Wilson interval; 200 scans of one log could not bound a share at 0.99:
200 of 200 gives a lower end of 0.981). The time per scan (the top-``top`` search only, on
``threads`` threads) is a table figure, not a claim: it depends on the machine and its load.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Annotated

import numpy as np
from pydantic import Field

from kiseki.datasets import read_carmen_log
from kiseki.filters import RelocalizeConfig, Relocalizer, SearchDisc
from kiseki.mapping import MapBuildConfig, map_of_log
from kiseki_experiments.harness.base import Experiment, TrialOutput
from kiseki_experiments.harness.config import Count, PositiveReal, Resolution, Share, Threads
from kiseki_experiments.harness.paths import CARMEN_LOGS, shared_data
from kiseki_experiments.harness.records import pack
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion
from kiseki_experiments.mcl.mcl_relocalization_report import analyze

__all__ = ["EXPERIMENT", "RelocalizationConfig", "ScanOutcome", "draw_scans", "judge_scan"]

Turn = Annotated[float, Field(ge=-180.0, le=180.0, allow_inf_nan=False)]


@dataclass(frozen=True)
class RelocalizationConfig:
    data_dir: str = ""  # folder of the .log.gz files; "" = ../shared/data/carmen
    logs: list[str] = field(default_factory=lambda: list(CARMEN_LOGS))
    scans: Count = 200  # drawn per trial (the 200 per log)
    resolution: Resolution = 0.05  # m: the map of the log
    top: Count = RelocalizeConfig.hypotheses  # the top 5
    near_radius: PositiveReal = 1.0  # m: "no pose more than 1 m from the truth ..."
    score_tolerance: Share = 0.05  # "... scores within 5 % of the truth's score"
    hit_distance: PositiveReal = 0.3  # m
    hit_angle_deg: PositiveReal = 5.0
    # the control: the scan's beam angles turned by this much (the scan read at a wrong heading)
    scan_turn_deg: Turn = 0.0
    threads: Threads = 2  # the "2 cores"


def preflight(config: RelocalizationConfig) -> None:
    folder = shared_data("carmen", config.data_dir)
    missing = [n for n in config.logs if not (folder / f"{n}.log.gz").is_file()]
    if missing:
        raise FileNotFoundError(f"mcl-relocalization: {folder}: missing {', '.join(missing)}")


def draw_scans(total: int, count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` scan indices of ``total``: one drawn uniformly from each of ``count`` equal runs
    of consecutive scans (all of them when the log is shorter)."""
    if count >= total:
        return np.arange(total)
    edges = np.linspace(0, total, count + 1).round().astype(np.int64)
    return rng.integers(edges[:-1], edges[1:])


@dataclass(frozen=True)
class ScanOutcome:
    """What one scan's relocalization gave (see the module's docstring)."""

    error_m: float  # best hypothesis' position error (inf when none)
    turn_deg: float  # its heading error
    rank: int  # 1..top: the first hypothesis within the hit tolerances; 0: none
    truth: float  # score at the reference pose
    near: float  # best lattice score within near_radius of it (-inf when none)
    far: float  # best lattice score farther than near_radius (-inf when none)
    seconds: float  # the top-k search

    def identifiable(self, tolerance: float, score: float | None = None) -> bool:
        """No far pose scores within ``tolerance`` of ``score``'s magnitude (``near`` by
        default)."""
        s = self.near if score is None else score
        return bool(np.isfinite(s) and self.far < s - tolerance * abs(s))


def judge_scan(
    matcher: Relocalizer,
    near_matcher: Relocalizer,
    angles: np.ndarray,
    ranges: np.ndarray,
    truth: np.ndarray,
    config: RelocalizationConfig,
) -> ScanOutcome:
    """Relocalize one scan with ``matcher`` and judge it against the reference pose ``truth``;
    ``near_matcher`` (one hypothesis) gives the exact best score on each side of the disc."""
    start = time.perf_counter()
    found = matcher.match(angles, ranges)
    seconds = time.perf_counter() - start
    x, y, theta = (float(v) for v in truth)
    errors = [
        (math.hypot(h.x - x, h.y - y), abs(math.degrees(math.remainder(h.theta - theta, math.tau))))
        for h in found
    ]
    rank = next(
        (
            i
            for i, (d, a) in enumerate(errors, start=1)
            if d <= config.hit_distance and a <= config.hit_angle_deg
        ),
        0,
    )
    sides = [
        near_matcher.match(angles, ranges, SearchDisc(x, y, config.near_radius, inside))
        for inside in (True, False)
    ]
    near, far = (s[0].score if s else -math.inf for s in sides)
    return ScanOutcome(
        error_m=errors[0][0] if errors else math.inf,
        turn_deg=errors[0][1] if errors else math.inf,
        rank=rank,
        truth=float(matcher.scores(angles, ranges, truth[None, :])[0]),
        near=near,
        far=far,
        seconds=seconds,
    )


def trial(config: RelocalizationConfig, index: int, seed: int) -> TrialOutput:
    name = config.logs[index % len(config.logs)]
    scans = read_carmen_log(shared_data("carmen", config.data_dir) / f"{name}.log.gz").scans
    grid = map_of_log(scans, MapBuildConfig(config.resolution))
    rc = RelocalizeConfig(hypotheses=config.top, threads=config.threads)
    matcher = Relocalizer(grid, scans.max_range, rc)
    near_matcher = Relocalizer(
        grid, scans.max_range, RelocalizeConfig(hypotheses=1, threads=rc.threads)
    )
    picks = draw_scans(len(scans), config.scans, np.random.default_rng(seed))
    angles = scans.angles + math.radians(config.scan_turn_deg)
    outcomes = [
        judge_scan(matcher, near_matcher, angles, scans.ranges[i], scans.poses[i], config)
        for i in picks
    ]
    tol = config.score_tolerance
    column = {
        f: np.array([getattr(o, f) for o in outcomes], float) for f in ScanOutcome.__annotations__
    }
    identifiable = np.array([o.identifiable(tol) for o in outcomes])
    by_truth = np.array([o.identifiable(tol, o.truth) for o in outcomes])
    best_hit = column["rank"] == 1
    record = {
        "log": name,
        "scans": len(outcomes),
        "identifiable": int(identifiable.sum()),
        "identifiable_by_truth_score": int(by_truth.sum()),
        "best_hit_identifiable": int((best_hit & identifiable).sum()),
        "best_hit": int(best_hit.sum()),
        "top_hit": int((column["rank"] > 0).sum()),
        "picks": pack(picks),
    } | {f: pack(column[f]) for f in ("error_m", "turn_deg", "rank", "truth", "near", "far")}
    seconds = column["seconds"]
    timings = {
        "median_s": float(np.median(seconds)),
        "p90_s": float(np.quantile(seconds, 0.9)),
        "max_s": float(seconds.max()),
    }
    return TrialOutput(record, timings)


TURNED_SCAN = Control(
    name="the scan's beam angles turned by 90 degrees",
    overrides=("logs=intel-corrected", "scans=10", "scan_turn_deg=90.0"),
    runs=1,
    why="the scan then fits the map best at the true position turned by -90 degrees, so no "
    "hypothesis has the reference heading, while the truth stays as identifiable as before",
)

CLAIMS = (
    ClaimSpec(
        key="best-of-identifiable",
        claim="among the scans whose truth is identifiable, the best hypothesis lies within "
        "0.3 m and 5 deg of the reference pose (per log, 200 scans)",
        unit="share of identifiable scans",
        criterion=Criterion(
            paper_value="(the issue's target)",
            compare=">=",
            threshold=0.9,
            why="the issue's target for relocalization from one scan",
            bounds=(0.0, 1.0),
        ),
        control=TURNED_SCAN,
        measure="a scan's best hypothesis within 0.3 m and 5 deg (identifiable scans only)",
    ),
    ClaimSpec(
        key="top-5-of-all",
        claim="a hypothesis of the top 5 lies within 0.3 m and 5 deg of the reference pose "
        "(all scans of all logs)",
        unit="share of scans",
        criterion=Criterion(
            paper_value="(the issue's target)",
            compare=">=",
            threshold=0.99,
            why="the issue's target for relocalization from one scan",
            bounds=(0.0, 1.0),
        ),
        control=TURNED_SCAN,
        measure="a scan with a top-5 hypothesis within 0.3 m and 5 deg",
    ),
)


EXPERIMENT = Experiment(
    name="mcl-relocalization",
    paper="localization engine (beyond the papers)",
    artefact="relocalization from one scan on real logs",
    description="one-scan global relocalization: best and top-5 hypotheses vs the reference pose",
    config_type=RelocalizationConfig,
    trial=trial,
    analyze=analyze,
    default_runs=len(CARMEN_LOGS),
    preflight=preflight,
    claims=CLAIMS,
)
