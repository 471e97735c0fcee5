# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The learned reliability estimate (kiseki.filters.reliability): its logistic fit against
scikit-learn's unpenalised one, and its calibration on simulated updates it was not fitted on
(trial seeds 201-204; the fit used 101-130), with controls that are miscalibrated on purpose
and must fail the same check."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from kiseki.filters import LEARNED_RELIABILITY, LocalizeConfig, ReliabilityModel
from kiseki.filters.reliability import fit_logistic
from kiseki.metrics import area_under_roc
from kiseki_experiments.mcl.mcl_reliability import FIT_SEEDS, pooled

HELD_OUT_SEEDS = (201, 202, 203, 204)
BINS = 10
# Consecutive updates of one trial share their label and nearly their features: taken as
# independent, a bin's n would overstate the evidence. Blocks of this many updates count as
# one independent draw (a lost spell after a jump lasts tens of updates, a recovery a few).
DESIGN_EFFECT = 10
MARGIN = 0.05  # "reads as a probability": within 5 points, beyond the sampling noise


def calibration_problems(predicted: np.ndarray, localised: np.ndarray) -> list[str]:
    """Reliability-diagram bins (width 1/BINS) holding >= 50 updates whose observed share of
    localised updates differs from their mean prediction by more than MARGIN + 3 standard
    errors (binomial at the bin's mean prediction, n = count / DESIGN_EFFECT)."""
    index = np.minimum((predicted * BINS).astype(int), BINS - 1)
    problems = []
    for b in range(BINS):
        inside = index == b
        n = int(inside.sum())
        if n < 50:
            continue
        p, observed = float(predicted[inside].mean()), float(localised[inside].mean())
        tolerance = MARGIN + 3.0 * np.sqrt(max(p * (1 - p), 1e-4) * DESIGN_EFFECT / n)
        if abs(observed - p) > tolerance:
            problems.append(f"bin {b}: {n} updates, predicted {p:.3f}, observed {observed:.3f}")
    return problems


@pytest.fixture(scope="module")
def held_out():
    assert not set(HELD_OUT_SEEDS) & set(FIT_SEEDS)
    return pooled(HELD_OUT_SEEDS)


def test_the_learned_estimate_is_calibrated_on_held_out_simulated_updates(held_out) -> None:
    predicted = LEARNED_RELIABILITY.probability(held_out.features)
    labels = held_out.localised
    assert 0.3 < labels.mean() < 0.9  # both kinds of update are there
    index = np.minimum((predicted * BINS).astype(int), BINS - 1)
    checked = np.isin(index, [b for b in range(BINS) if (index == b).sum() >= 50]).mean()
    assert checked >= 0.9  # the bins checked hold nearly every update
    assert calibration_problems(predicted, labels) == []


@pytest.mark.parametrize("control", ["agreement", "underconfident"])
def test_a_miscalibrated_estimate_fails_the_same_check(held_out, control) -> None:
    b = np.asarray(LEARNED_RELIABILITY.coefficients)
    if control == "agreement":  # the engine's estimate read as a probability
        predicted = held_out.agreement_reliability
    else:  # the intercept moved down by 1.5 (the odds divided by 4.5)
        predicted = ReliabilityModel((b[0] - 1.5, *b[1:])).probability(held_out.features)
    assert calibration_problems(predicted, held_out.localised) != []


def test_the_learned_estimate_tells_lost_from_localised(held_out) -> None:
    """Calibration alone is met by a constant (the share localised); the estimate must also
    rank the updates: area under the ROC curve >= 0.95, where the constant has 0.5."""
    labels = held_out.localised
    assert area_under_roc(LEARNED_RELIABILITY.probability(held_out.features), labels) >= 0.95
    constant = np.full(len(labels), labels.mean())
    assert calibration_problems(constant, labels) == []  # calibrated, and useless:
    assert area_under_roc(constant, labels) == 0.5


def test_the_logistic_fit_and_the_roc_area_match_scikit_learn() -> None:
    from sklearn.linear_model import LogisticRegression  # only here: a slow import
    from sklearn.metrics import roc_auc_score

    rng = np.random.default_rng(5)
    x = rng.normal(size=(2000, 2))
    y = rng.uniform(size=2000) < 1 / (1 + np.exp(-(0.5 + x @ [2.0, -1.0])))
    ours = fit_logistic(x, y)
    theirs = LogisticRegression(C=np.inf, tol=1e-10, max_iter=1000).fit(x, y)
    np.testing.assert_allclose(ours, [*theirs.intercept_, *theirs.coef_[0]], atol=1e-4)
    score = np.round(x[:, 0], 1)  # with ties
    assert area_under_roc(score, y) == pytest.approx(roc_auc_score(y, score), abs=1e-12)


def test_the_default_reliability_is_still_the_engines_and_bad_names_are_refused() -> None:
    assert LocalizeConfig().reliability == "agreement"
    with pytest.raises(ValueError, match="reliability must be one of agreement, learned"):
        LocalizeConfig(reliability="confidence")
    with pytest.raises(ValueError, match="need 3 finite coefficients"):
        ReliabilityModel((1.0, 2.0))
    for bad in (np.nan, True):  # True was taken as the coefficient 1
        with pytest.raises(
            ValueError, match="^reliability model: b_agreement must be a finite number, got "
        ):
            ReliabilityModel((1.0, bad, 2.0))
    assert "seeds 101-130" in LEARNED_RELIABILITY.provenance
    assert dataclasses.is_dataclass(LEARNED_RELIABILITY)
