# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Verdicts with uncertainty: the intervals against their closed forms, the three verdicts, the
trials that would decide an undecided claim, and how the reports count and show them."""

from __future__ import annotations

import math
from statistics import NormalDist

import numpy as np
import pandas as pd
import pytest
import yaml

from kiseki.metrics import wilson_interval
from kiseki_experiments.harness import base
from kiseki_experiments.harness.registry import get_experiment
from kiseki_experiments.harness.report import _saved_settings, _undecided, claims_frame, tally
from kiseki_experiments.harness.run_reader import _old_claims
from kiseki_experiments.harness.verdict import (
    UNMIGRATED,
    ClaimSpec,
    Control,
    Criterion,
    Estimate,
    Evidence,
    decide,
    estimate,
    trials_to_decide,
)

AT_LEAST = Criterion("0.5", ">=", 0.5, "a test's threshold", bounds=(0.0, 1.0))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_bootstrap_interval_of_a_mean_matches_the_normal_one(seed):
    # 400 draws of N(2, 1): the 95 % interval of the mean is 2 +- 1.96 / 20 = +-0.098
    x = np.random.default_rng(100 + seed).normal(2.0, 1.0, 400)
    est = estimate(Evidence.of("k", x), seed)
    half = 1.96 * x.std(ddof=1) / math.sqrt(x.size)
    assert est.value == pytest.approx(x.mean())
    assert est.low == pytest.approx(x.mean() - half, abs=0.15 * half)
    assert est.high == pytest.approx(x.mean() + half, abs=0.15 * half)
    assert estimate(Evidence.of("k", x), seed) == est  # one seed, one result


def test_a_share_takes_wilsons_interval_and_few_values_none():
    est = estimate(Evidence.share("k", 9, 10), 0)
    assert (est.low, est.high) == wilson_interval(9, 10) and est.value == 0.9
    few = estimate(Evidence.of("k", [1.0, 2.0, 3.0, 4.0]), 0)  # below MIN_TRIALS
    assert math.isnan(few.low) and decide(AT_LEAST, few) == "inconclusive"


@pytest.mark.parametrize(
    ("low", "high", "at_least", "in_band"),
    [
        (0.6, 0.9, "holds", "inconclusive"),
        (0.1, 0.4, "fails", "fails"),
        (0.4, 0.6, "inconclusive", "inconclusive"),
        (0.5, 0.7, "holds", "holds"),
        (0.85, 0.95, "holds", "fails"),
    ],
)
def test_the_verdict_is_where_the_interval_lies(low, high, at_least, in_band):
    est = Estimate((low + high) / 2, low, high, 20)
    assert decide(AT_LEAST, est) == at_least
    within = Criterion("0.65", "within", 0.65, "a test's band", 0.15, (0.0, 1.0))  # 0.5-0.8
    assert decide(within, est) == in_band


def test_trials_to_decide_scale_the_half_width_as_one_over_sqrt_n():
    # value 0.55, interval +-0.1 at 20 trials: the interval must shrink to 0.05, a quarter of
    # the variance: 80 trials
    assert trials_to_decide(AT_LEAST, Estimate(0.55, 0.45, 0.65, 20)) == 80
    assert trials_to_decide(AT_LEAST, Estimate(0.5, 0.4, 0.6, 20)) is None  # on the threshold
    # brute force for a share, whose Wilson interval is searched: 12 of 20 (0.6) decides >= 0.5
    # at the count given, not one below; all of 10 decides >= 0.95 at 73 (n / (n + 1.96^2))
    need = trials_to_decide(AT_LEAST, estimate(Evidence.share("k", 12, 20), 0))
    for m, verdict in ((need, "holds"), (need - 1, "inconclusive")):
        share = Evidence.share("k", round(0.6 * m), m)
        assert decide(AT_LEAST, estimate(share, 0)) == verdict, (m, need)
    target = Criterion("0.95", ">=", 0.95, "the issue's target", bounds=(0.0, 1.0))
    assert trials_to_decide(target, estimate(Evidence.share("k", 10, 10), 0)) == 73


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_trials_to_decide_from_the_values_follow_the_normal_scaling(seed):
    # 20 values at the quantiles of N(0.55, 0.2) against >= 0.5 (an interval of about +-0.09):
    # the bootstrap search and the 1/sqrt(n) scaling of the interval's arm estimate the same
    # count, about 20 (0.09 / 0.05)^2 = 65
    x = [NormalDist(0.55, 0.2).inv_cdf((i + 0.5) / 20) for i in range(20)]
    evidence = Evidence.of("k", x)
    est = estimate(evidence, seed)
    assert decide(AT_LEAST, est) == "inconclusive"
    scaled = trials_to_decide(AT_LEAST, est)
    searched = trials_to_decide(AT_LEAST, est, evidence, seed)
    assert searched == pytest.approx(scaled, rel=0.3)
    assert trials_to_decide(AT_LEAST, est, evidence, seed) == searched  # one seed, one result


def test_trials_to_decide_a_mean_with_a_rare_large_value():
    # five tracked seeds and one lost (7.6 m) against <= 0.05: the interval's low end stays
    # near the tracked seeds' mean while a resample without the lost seed is more likely than
    # 2.5 %: (5/6)^m < 0.025 from m = 21 on; the 1/sqrt(n) scaling of the arm asks for 7
    values = [0.002, 7.59, 0.0017, 0.0022, 0.0027, 0.0015]
    within = Criterion("0", "<=", 0.05, "a test's tolerance")
    evidence = Evidence.of("k", values)
    est = estimate(evidence, 0)
    assert decide(within, est) == "inconclusive"
    closed_form = next(m for m in range(6, 100) if (5 / 6) ** m < 0.025)
    assert closed_form == 21
    assert trials_to_decide(within, est) < 10
    assert abs(trials_to_decide(within, est, evidence, 0) - closed_form) <= 3
    # a value on the edge: no count decides it
    on_edge = Evidence.of("k", [0.04, 0.06] * 5)
    assert trials_to_decide(within, estimate(on_edge, 0), on_edge, 0) is None


def _experiment(claims=()) -> base.Experiment:
    return base.Experiment(
        "t", "p", "a", "d", dict, lambda *a: None, lambda *a: None, claims=claims
    )


def test_reports_count_old_point_verdicts_as_undecided_and_price_the_undecided():
    spec = ClaimSpec("k", "a share", "share", AT_LEAST, Control("c", ("x=1",), 5))
    analysis = base.Analysis(
        evidence=[Evidence.share("k", 11, 20)],  # 0.55, Wilson 0.34-0.74: inconclusive
    )
    claims = claims_frame(_experiment((spec,)), analysis, 0)
    # a results folder written before claims had intervals: a point verdict, never decided
    old = _old_claims(pd.DataFrame([{"claim": "old", "measured_value": "1", "holds": True}]))
    both = pd.concat([claims, old], ignore_index=True)
    assert both["verdict"].tolist() == ["inconclusive", UNMIGRATED]
    assert old["note"].item() == "point verdict without an interval: holds"
    counts = tally(both)
    assert (counts["decided"], counts["inconclusive"], counts["not_migrated"]) == (0, 1, 1)
    need = int(claims["trials_to_decide"].iloc[0])
    assert need == trials_to_decide(AT_LEAST, estimate(Evidence.share("k", 11, 20), 0))
    # 20 trials of the run, 2 s each: the claim's `need` trials take 2 * need s
    lines = _undecided(claims, 20, pd.DataFrame({"trial_seconds": [1.0, 3.0]}))
    row = next(line for line in lines if line.startswith("| a share |"))
    wall = 2 * need
    shown = f"{wall / 3600:.2f} h" if wall > 3600 else f"{wall:.0f} s"
    assert row == f"| a share | 20 | {need} | {need} | {shown} |"
    # an experiment whose trials are its config's settings (leave-one-out cases, repeats)
    # cannot run more than it has by --runs: the price says so (it priced a run the runner
    # refuses without a word); within them it is priced as before
    beyond = _undecided(claims, 20, pd.DataFrame({"trial_seconds": [1.0, 3.0]}), settings=need - 1)
    row = next(line for line in beyond if line.startswith("| a share |"))
    said = (
        f"{need} (more than the {need - 1} settings of this config, one trial each: a config "
        "with more repeats or cases)"
    )
    assert row == f"| a share | 20 | {need} | {said} | {shown} |"
    within = _undecided(claims, 20, pd.DataFrame({"trial_seconds": [1.0, 3.0]}), settings=need)
    kept = next(line for line in within if line.startswith("| a share |"))
    assert kept == f"| a share | 20 | {need} | {need} | {shown} |"


def test_the_report_reads_the_settings_of_the_run_it_reports(tmp_path):
    """write_reproduction bounds the undecided claims by the trial count of the config saved
    with each run (gp-aalto-defaults: its 10 leave-one-run-out cases)."""
    experiment = get_experiment("gp-aalto-defaults")
    run = tmp_path / "run"
    run.mkdir()
    config = {"experiment": experiment.name, "runs": 10, "seed": 0, "config": {"runs": [1, 2, 3]}}
    (run / "config.yaml").write_text(yaml.safe_dump(config))
    assert _saved_settings(experiment, run) == 2 * 3  # two sensors x three held-out runs
    (run / "config.yaml").write_text("config: {runs: [1, 2, 3], unknown_key: 1}\n")
    assert _saved_settings(experiment, run) is None  # unreadable: priced without the bound
    assert _saved_settings(get_experiment("mcl-kld"), run) is None  # trials are seeds


def test_evidence_for_an_undeclared_claim_is_refused():
    analysis = base.Analysis(evidence=[Evidence.share("other", 1, 2)])
    with pytest.raises(ValueError, match="which no claim declares"):
        claims_frame(_experiment(), analysis, 0)
