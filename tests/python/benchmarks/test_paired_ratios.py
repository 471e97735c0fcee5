# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The threads benchmark's verdict on "two threads never slower than one": the geometric mean
of paired time ratios, its bootstrap interval, and the rule that reads them."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

BENCHMARKS = Path(__file__).resolve().parents[3] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

from bench_threads_under_load import BAND, ratio_interval, verdict  # noqa: E402


def test_the_geometric_mean_and_its_interval_match_the_closed_form():
    rng = np.random.default_rng(7)
    ratios = np.exp(rng.normal(np.log(0.8), 0.2, 400))
    g, lo, hi = ratio_interval(ratios)
    assert g == np.exp(np.log(ratios).mean())
    assert lo < g < hi
    # the bootstrap's 95 % interval of a mean of logs: about +-1.96 standard errors
    half = 1.96 * np.log(ratios).std() / np.sqrt(len(ratios))
    np.testing.assert_allclose([np.log(lo), np.log(hi)], np.log(g) + np.array([-half, half]),
                               atol=0.15 * half)  # fmt: skip
    np.testing.assert_allclose(ratio_interval(np.full(50, 1.2)), 1.2)  # no spread, no width


def test_the_rule_holds_fails_or_leaves_undecided():
    assert verdict(0.7, 0.95) == "holds"
    assert verdict(0.9, BAND) == "holds"  # the band's edge is within it
    assert verdict(BAND + 1e-9, 2.0) == "fails"
    assert verdict(0.98, 1.2) == "undecided"
    # the control the benchmark prints: two threads ten times slower than one fail the rule
    rng = np.random.default_rng(1)
    _, lo, hi = ratio_interval(np.exp(rng.normal(np.log(10.0), 0.5, 190)))
    assert verdict(lo, hi) == "fails"
