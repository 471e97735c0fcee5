# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""mcl-excursions: is a filter ever lost for good on real logs? Along each CARMEN log (odometry
rebuilt from the corrected poses with noise F = 0.1 of each increment), the teaching-and-playback
thesis' space observation model on the log's teaching map (0.1 m, the thesis' merge rules) and
the likelihood field on its log-odds map (0.05 m) track from the first pose, each with the
recovery setting of ``recoveries``. An *excursion* is a run of scans whose position error
exceeds ``excursion_distance`` (0.5 m); its length is the number of scans until the error is
back below it (or to the end of the log: never back). Trial i is log i mod 4 with its own seed.

For the excursions longer than ``max_return_scans``, ``long_seen_share`` is the share of their
scans on which the truth explains the scan better than the estimate by the resets' evidence
margin (a Bayes factor of 10). Near 0, the model itself cannot tell the estimate from the
truth there (the space observation model penalises seeing through walls, not falling short of
them, so it is blind along a corridor), and no recovery that weighs with it can act.

The claims are declared in ``mcl_excursions_claims``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated

import numpy as np
import pandas as pd

from kiseki.datasets import read_carmen_log
from kiseki.filters import (
    RECOVERY_MODES,
    RESET_PROPOSALS,
    LocalizeConfig,
    MclConfig,
    localize,
    scan_model,
    scan_preparer,
)
from kiseki.mapping import MapBuildConfig, map_of_log
from kiseki.metrics import ape
from kiseki.plots import new_figure
from kiseki.teach.environment_map import build_teaching_map
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import (
    Count,
    NonEmpty,
    NonNegativeReal,
    Particles,
    PositiveReal,
    Scans,
    Threads,
)
from kiseki_experiments.harness.paths import CARMEN_LOGS, shared_data
from kiseki_experiments.harness.verdict import Evidence
from kiseki_experiments.mcl.mcl_excursions_claims import CLAIMS

METHODS = ("space-observation", "likelihood-field", "ray-space-observation")
#: the fraction of each log after which a filter must never be more than ``lost_distance`` off
SETTLING_SHARE = 0.1


@dataclass(frozen=True)
class ExcursionsConfig:
    data_dir: str = ""  # folder of the .log.gz files; "" = ../shared/data/carmen
    logs: list[str] = field(default_factory=lambda: list(CARMEN_LOGS))
    methods: Annotated[list[str], NonEmpty] = field(default_factory=lambda: list(METHODS))
    recoveries: list[str] = field(default_factory=lambda: ["resetting"])
    particles: Particles = 500
    odometry_noise: NonNegativeReal = 0.1
    excursion_distance: PositiveReal = 0.5  # m
    max_return_scans: Scans = 20  # the claim: every excursion ends within this many scans
    lost_distance: PositiveReal = 2.0  # m: "lost" after the first SETTLING_SHARE of the scans
    # kiseki's ray space observation model's weight of an unmapped object (LocalizeConfig's)
    z_intrusion: PositiveReal = LocalizeConfig.z_intrusion
    max_scans: Scans = 0  # 0 = whole logs
    # the sensor reset's candidates (uniform or matcher) and its look-elsewhere term
    sensor_reset_proposal: str = LocalizeConfig.sensor_reset_proposal
    # with the matcher: a search on every this-many-th sensor reset of a lost spell
    matcher_search_every: Count = LocalizeConfig.matcher_search_every
    reset_look_elsewhere: bool = LocalizeConfig.reset_look_elsewhere
    # the resets' agreement check and confirmation (false: the resets before them)
    reset_needs_agreement: bool = LocalizeConfig.reset_needs_agreement
    sensor_reset_confirm: bool = LocalizeConfig.sensor_reset_confirm
    # kiseki's ray model's resets judged by penetration only (LocalizeConfig's
    # intrusion_tolerant_resets) in its resetting arms; the other arms are run as they are
    intrusion_tolerant_resets: bool = LocalizeConfig.intrusion_tolerant_resets
    threads: Threads = 1


def preflight(config: ExcursionsConfig) -> None:
    for m in config.methods:
        if m not in METHODS:
            raise ValueError(f"mcl-excursions: unknown method {m!r} ({', '.join(METHODS)})")
    for r in config.recoveries:
        if r not in RECOVERY_MODES:
            raise ValueError(f"mcl-excursions: unknown recovery {r!r}")
    if config.sensor_reset_proposal not in RESET_PROPOSALS:  # failed in every trial
        raise ValueError(
            f"mcl-excursions: sensor_reset_proposal must be one of {', '.join(RESET_PROPOSALS)}, "
            f"got {config.sensor_reset_proposal!r}"
        )
    ray_resets = "ray-space-observation" in config.methods and "resetting" in config.recoveries
    if config.intrusion_tolerant_resets and not ray_resets:
        raise ValueError(
            "mcl-excursions: intrusion_tolerant_resets needs the ray-space-observation method and "
            "the resetting recovery among the arms"
        )
    folder = shared_data("carmen", config.data_dir)
    missing = [n for n in config.logs if not (folder / f"{n}.log.gz").is_file()]
    if missing:
        raise FileNotFoundError(f"mcl-excursions: {folder}: missing {', '.join(missing)}")


def excursions(errors: np.ndarray, threshold: float) -> list[int]:
    """Lengths (scans) of the runs of errors above threshold; a run that reaches the end of the
    log counts as -1 (never back)."""
    out, run = [], 0
    for e in errors:
        if e > threshold:
            run += 1
        elif run:
            out.append(run)
            run = 0
    if run:
        out.append(-1)
    return out


def excursion_spans(errors: np.ndarray, threshold: float) -> list[tuple[int, int]]:
    """(start, stop) scan indices of the runs of errors above threshold."""
    above = np.concatenate([[False], errors > threshold, [False]])
    edges = np.flatnonzero(np.diff(above.astype(np.int8)))
    return list(zip(edges[0::2].tolist(), edges[1::2].tolist(), strict=True))


def model_sees(scans, grid, lc: LocalizeConfig, estimates: np.ndarray, index: np.ndarray):
    """Per scan of ``index``: does the truth explain the scan better than the estimate by the
    resets' evidence margin (MclConfig.reset_evidence, tempered as the weights are)? Where it
    does not, the model itself cannot tell the estimate from the truth, and no recovery that
    weighs with it can prefer the truth."""
    prepare = scan_preparer(scan_model(lc.method, grid, lc), scans)
    margin = MclConfig().reset_evidence
    out = np.zeros(len(index), dtype=bool)
    for n, k in enumerate(index):
        model = prepare(int(k))
        ll = model.log_likelihoods(np.stack([scans.poses[k], estimates[k]]))
        out[n] = lc.likelihood_power * (ll[0] - ll[1]) > margin
    return out


def trial(config: ExcursionsConfig, index: int, seed: int) -> TrialOutput:
    name = config.logs[index % len(config.logs)]
    path = shared_data("carmen", config.data_dir) / f"{name}.log.gz"
    scans = read_carmen_log(path).scans.first(config.max_scans)
    maps = {
        "space-observation": build_teaching_map(
            scans.poses, scans.ranges, scans.angles, scans.max_range, 0.1
        ),
        "likelihood-field": map_of_log(scans, MapBuildConfig(0.05)),
    }
    maps["ray-space-observation"] = maps["likelihood-field"]
    record: dict = {"log": name, "scans": len(scans)}
    timings: dict = {}
    for method in config.methods:
        for recovery in config.recoveries:
            key = f"{method}_{recovery}"
            lc = LocalizeConfig(
                method=method,
                seed=seed,
                odometry_noise=config.odometry_noise,
                particles=config.particles,
                recovery=recovery,
                threads=config.threads,
                z_intrusion=config.z_intrusion,
                sensor_reset_proposal=config.sensor_reset_proposal,
                matcher_search_every=config.matcher_search_every,
                reset_look_elsewhere=config.reset_look_elsewhere,
                reset_needs_agreement=config.reset_needs_agreement,
                sensor_reset_confirm=config.sensor_reset_confirm,
                intrusion_tolerant_resets=config.intrusion_tolerant_resets
                and method == "ray-space-observation"
                and recovery == "resetting",
            )
            result = localize(scans, maps[method], lc)
            d = result.estimates - scans.poses
            errors = np.hypot(d[:, 0], d[:, 1])
            runs = excursions(errors, config.excursion_distance)
            long = [
                np.arange(a, b)
                for a, b in excursion_spans(errors, config.excursion_distance)
                if b - a > config.max_return_scans
            ]
            long_index = np.concatenate(long) if long else np.zeros(0, dtype=np.int64)
            sees = model_sees(scans, maps[method], lc, result.estimates, long_index)
            record |= {
                f"{key}_rmse_m": ape(result.estimates, scans.poses).rmse,
                f"{key}_heading_rmse_deg": ape(result.estimates, scans.poses, "rotation_deg").rmse,
                f"{key}_excursions": len(runs),
                f"{key}_longest": -1 if -1 in runs else max(runs, default=0),
                f"{key}_late_max_m": float(errors[int(SETTLING_SHARE * len(errors)) :].max()),
                f"{key}_resets": int(np.sum(result.resets != "none")),
                f"{key}_long_scans": int(long_index.size),
                f"{key}_long_seen": int(sees.sum()),
            }
            timings[f"{key}_ms_per_update"] = 1000.0 * float(np.mean(result.update_seconds))
    return TrialOutput(record, timings)


def analyze(config: ExcursionsConfig, trials: pd.DataFrame, timings: pd.DataFrame, figures: Path):
    ok = trials[trials["error"].isna()].merge(timings, on="trial")
    rows = []
    for log, group in ok.groupby("log", sort=False):
        for method in config.methods:
            for recovery in config.recoveries:
                key = f"{method}_{recovery}"
                longest = group[f"{key}_longest"]
                rows.append(
                    {
                        "log": log,
                        "method": method,
                        "recovery": recovery,
                        "seeds": len(group),
                        "rmse_mean_m": group[f"{key}_rmse_m"].mean(),
                        "rmse_max_m": group[f"{key}_rmse_m"].max(),
                        "excursions": int(group[f"{key}_excursions"].sum()),
                        "longest_scans": -1 if (longest == -1).any() else int(longest.max()),
                        "resets": int(group[f"{key}_resets"].sum()),
                        "late_max_m": group[f"{key}_late_max_m"].max(),
                        "long_excursion_scans": int(group[f"{key}_long_scans"].sum()),
                        "long_seen_share": (
                            group[f"{key}_long_seen"].sum() / group[f"{key}_long_scans"].sum()
                            if group[f"{key}_long_scans"].sum()
                            else float("nan")
                        ),
                        "ms_per_update": group[f"{key}_ms_per_update"].median(),
                    }
                )
    table = pd.DataFrame(rows)
    evidence = []
    for row in table.itertuples():
        if row.method == "ray-space-observation":
            evidence += _ray_evidence(config, ok, row)
        if row.method != "space-observation":
            continue
        key = f"{row.method}_{row.recovery}"
        longest = ok.loc[ok["log"] == row.log, f"{key}_longest"].astype(float)
        evidence.append(
            Evidence.of(
                "returns",
                longest.where(longest >= 0, np.inf),  # never back: infinitely long
                subject=f"{row.log}, {row.recovery}",
                shown="never back in a seed"
                if row.longest_scans == -1
                else f"longest of all seeds {row.longest_scans}",
                note=(
                    f"{row.excursions} excursions over {row.seeds} seeds"
                    + (
                        f"; in the {row.long_excursion_scans} scans of the longer ones the "
                        f"truth explains the scan better than the estimate by a Bayes factor "
                        f"of 10 in {100 * row.long_seen_share:.0f} %"
                        if row.long_excursion_scans
                        else ""
                    )
                ),
            )
        )
    fig = new_figure(figsize=(8, 3.5), dpi=120)
    ax = fig.subplots()
    labels = [f"{r.log.replace('-corrected', '')}\n{r.method[:5]}" for r in table.itertuples()]
    ax.bar(np.arange(len(table)), table["rmse_mean_m"], color="tab:blue")
    ax.set_xticks(np.arange(len(table)), labels, fontsize=6)
    ax.set_ylabel("position RMSE (m), mean over seeds")
    path = figures / "excursions.png"
    fig.savefig(path, bbox_inches="tight")
    notes = (
        f"{config.particles} particles, odometry noise {config.odometry_noise}, recoveries "
        f"{', '.join(config.recoveries)}; an excursion is a run of scans with the position "
        f"error above {config.excursion_distance} m; -1 = never back before the log ends."
    )
    return Analysis(tables={"per_log": table}, figures=[path], notes=notes, evidence=evidence)


def _ray_evidence(config: ExcursionsConfig, ok: pd.DataFrame, row) -> list[Evidence]:
    """The issue's targets for kiseki's ray space observation model on one log and recovery:
    never lost after the first tenth, every excursion back within max_return_scans, RMSE at
    most 1.5 times the likelihood field's (per seed, same odometry)."""
    group = ok[ok["log"] == row.log]
    key = f"ray-space-observation_{row.recovery}"
    subject = f"{row.log}, {row.recovery}"
    longest = group[f"{key}_longest"].astype(float)
    late = group[f"{key}_late_max_m"]
    out = [
        Evidence.of(
            "ray-never-lost",
            late,
            subject=subject,
            shown=f"worst seed {late.max():.2f} m",
        ),
        Evidence.of(
            "ray-returns",
            longest.where(longest >= 0, np.inf),
            subject=subject,
            shown="never back in a seed"
            if row.longest_scans == -1
            else f"longest of all seeds {row.longest_scans}",
        ),
    ]
    field_key = f"likelihood-field_{row.recovery}_rmse_m"
    if field_key in group:
        ratio = group[f"{key}_rmse_m"] / group[field_key]
        out.append(
            Evidence.of(
                "ray-rmse",
                ratio,
                subject=subject,
                shown=f"{group[f'{key}_rmse_m'].mean():.3f} vs {group[field_key].mean():.3f} m",
            )
        )
    return out


EXPERIMENT = Experiment(
    name="mcl-excursions",
    paper="localization engine (beyond the papers)",
    artefact="space observation model on real logs, with recovery",
    description="excursions beyond 0.5 m and their return, space observation vs likelihood field",
    config_type=ExcursionsConfig,
    trial=trial,
    analyze=analyze,
    default_runs=5 * len(CARMEN_LOGS),
    preflight=preflight,
    claims=CLAIMS,
)
