# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The reliability estimate fitted on recorded logs (``learned-real``): the model fitted without
the Intel log, scored on kidnapping trials spliced into the Intel log (trial seeds 201-204; the
fits used 101-130), says "localised" (> 0.9) on at least 95 % of the localised updates and
"lost" (< 0.5) on at least 90 % of the lost ones, and ranks them; the simulator's coefficients,
on the same updates, are the control: they call too many localised updates doubtful."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from kiseki.filters import LEARNED_RELIABILITY, REAL_LOG_RELIABILITY, LocalizeConfig, localize
from kiseki.filters.reliability import learned_model
from kiseki.metrics import area_under_roc
from kiseki_experiments.harness.paths import CARMEN_LOGS
from kiseki_experiments.mcl.mcl_reliability import FIT_SEEDS, carmen_labelled_updates
from kiseki_experiments.mcl.mcl_reliability_folds import REAL_LOG_FOLDS

HELD_OUT_SEEDS = (201, 202, 203, 204)
LOG = "intel-corrected"


@pytest.fixture(scope="module")
def intel(shared_data: Path):
    assert not set(HELD_OUT_SEEDS) & set(FIT_SEEDS)
    parts = [carmen_labelled_updates(LOG, s, data_dir=str(shared_data / "carmen")) for s in
             HELD_OUT_SEEDS]  # fmt: skip
    features = np.concatenate([p.features for p in parts])
    labels = np.concatenate([p.localised for p in parts])
    assert 0.3 < labels.mean() < 0.9  # both kinds of update are there
    return features, labels


def _shares(probability: np.ndarray, labels: np.ndarray) -> tuple[float, float]:
    """(localised updates read above 0.9, lost updates read below 0.5)."""
    return float(np.mean(probability[labels] > 0.9)), float(np.mean(probability[~labels] < 0.5))


def test_the_model_that_never_saw_the_log_reads_it_right(intel) -> None:
    features, labels = intel
    p = REAL_LOG_FOLDS[LOG].probability(features)
    high, low = _shares(p, labels)
    assert high >= 0.95 and low >= 0.90, (high, low)
    assert area_under_roc(p, labels) >= 0.98


def test_the_simulators_coefficients_call_localised_updates_doubtful_there(intel) -> None:
    features, labels = intel
    high, _ = _shares(LEARNED_RELIABILITY.probability(features), labels)
    assert high < 0.95


def test_each_fold_leaves_its_own_log_out_and_the_users_model_has_them_all() -> None:
    assert set(REAL_LOG_FOLDS) == set(CARMEN_LOGS)
    for log, model in REAL_LOG_FOLDS.items():
        others = [x for x in CARMEN_LOGS if x != log]
        assert log not in model.provenance and all(x in model.provenance for x in others)
    assert all(x in REAL_LOG_RELIABILITY.provenance for x in CARMEN_LOGS)
    assert learned_model("learned-real") is REAL_LOG_RELIABILITY
    assert learned_model("learned") is LEARNED_RELIABILITY and learned_model("agreement") is None
    assert LocalizeConfig(reliability="learned-real").reliability == "learned-real"
    with pytest.raises(ValueError, match="reliability must be one of agreement, learned, learned-"):
        learned_model("real")


def test_localize_reports_the_named_estimate(shared_data: Path) -> None:
    """``LocalizeConfig(reliability="learned-real")`` reports (1) with the recorded logs'
    coefficients at every update, and differs from the simulator's on the same updates."""
    from kiseki.datasets import read_carmen_log
    from kiseki.mapping import MapBuildConfig, map_of_log

    scans = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz").scans.first(150)
    grid = map_of_log(scans, MapBuildConfig(resolution=0.05))
    runs = {
        name: localize(scans, grid, LocalizeConfig(particles=300, reliability=name, threads=1))
        for name in ("learned-real", "learned")
    }
    real, sim = runs["learned-real"], runs["learned"]
    rows = real.updated & np.isfinite(real.reliability_features).all(axis=1)
    assert rows.sum() > 100
    expected = REAL_LOG_RELIABILITY.probability(real.reliability_features[rows])
    np.testing.assert_allclose(real.reliability[rows], expected, rtol=1e-12)
    np.testing.assert_array_equal(real.estimates, sim.estimates)  # the estimate reads, not steers
    assert np.abs(real.reliability[rows] - sim.reliability[rows]).max() > 0.01
