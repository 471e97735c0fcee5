# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The time budget (kiseki.filters.budget): the choice of counts against hand-computed cases
and its rule over many cost models, the cost model's file, and that one seed and one cost
model give one trajectory for any thread count, with and without the budget."""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
from pathlib import Path

import numpy as np
import pytest

from kiseki.datasets import read_carmen_log
from kiseki.filters import CostModel, LocalizeConfig, choose_counts, localize
from kiseki.filters.budget import COST_MODEL_LIMIT
from kiseki.mapping import build_map

# Binary fractions, so that the hand computations below are exact.
COST = CostModel(fixed_ms=2.0, per_particle_ms=2.0**-10, per_beam_ms=2.0**-12)


def test_rule_1_keeps_the_beams_and_takes_the_most_particles_that_fit():
    # T = 0.5 x 32 = 16 ms; per particle 2^-10 + 360 x 2^-12 = 0.0888671875 ms;
    # (16 - 2) / 0.0888671875 = 157.54 -> 157
    choice = choose_counts(32.0, COST, 100, 1000, 360, 30, 0.5)
    assert (choice.particles, choice.beams, choice.fits) == (157, 360, True)
    assert choice.predicted_ms == 2.0 + 157 * 0.0888671875
    capped = choose_counts(32.0, COST, 100, 150, 360, 30, 0.5)  # the maximum is the cap
    assert (capped.particles, capped.beams) == (150, 360)


def test_rule_2_cuts_the_beams_at_the_minimum_particle_count():
    # 157 < 200: at N = 200, room = 14 / 200 - 2^-10 = 0.0690234375 ms -> 282.7 beams -> 282
    choice = choose_counts(32.0, COST, 200, 1000, 360, 30, 0.5)
    assert (choice.particles, choice.beams, choice.fits) == (200, 282, True)
    assert choice.predicted_ms == 2.0 + 200 * (2.0**-10 + 282 * 2.0**-12) == 15.96484375


def test_rule_3_runs_at_the_floor_and_says_the_budget_is_not_kept():
    # the floor of 300 beams at N = 200: 2 + 200 (2^-10 + 300 x 2^-12) = 16.84375 > 16
    choice = choose_counts(32.0, COST, 200, 1000, 360, 300, 0.5)
    assert (choice.particles, choice.beams, choice.fits) == (200, 300, False)
    assert choice.predicted_ms == 16.84375
    # a floor above the beams asked for is the beams asked for
    few = choose_counts(2.1, COST, 200, 1000, 20, 30, 1.0)
    assert (few.particles, few.beams, few.fits) == (200, 20, False)
    assert "cannot keep" in few.describe()


def test_the_choice_fills_the_budget_as_the_rule_says_over_many_cost_models():
    rng = np.random.default_rng(7)
    for _ in range(2000):
        cost = CostModel(*rng.uniform(0, 1, 3) * (5.0, 1e-3, 1e-5))
        budget, share = float(rng.uniform(1, 100)), float(rng.uniform(0.5, 1))
        low = int(rng.integers(1, 2000))
        high, beams = low + int(rng.integers(0, 100_000)), int(rng.integers(1, 1000))
        floor = int(rng.integers(1, 100))
        c = choose_counts(budget, cost, low, high, beams, floor, share)
        target = share * budget
        assert low <= c.particles <= high and min(floor, beams) <= c.beams <= beams
        assert c.predicted_ms == cost.predict_ms(c.particles, c.beams)
        assert c.fits == (c.predicted_ms <= target)
        if c.beams == beams and c.particles > low:  # rule 1: the most particles that fit
            assert c.fits
            assert c.particles == high or cost.predict_ms(c.particles + 1, beams) > target
        elif c.fits:  # rule 2: the minimum, and the most beams that fit
            assert c.particles == low or c.particles == high
            assert c.beams == beams or cost.predict_ms(low, c.beams + 1) > target
        else:  # rule 3: nothing fits, even the minimum with the floor
            assert c.particles == low and c.beams == min(floor, beams)


def test_choice_refuses_a_budget_that_is_not_positive():
    for budget in (0.0, -1.0, math.nan, math.inf, True):  # True was taken as 1 ms
        with pytest.raises(ValueError, match="^the budget must be a finite number > 0 ms, got "):
            choose_counts(budget, COST, 100, 1000, 360, 30, 0.8)
    with pytest.raises(ValueError, match="min_particles"):
        choose_counts(20.0, COST, 1000, 100, 360, 30, 0.8)


def test_cost_model_file_round_trip_and_bad_files(tmp_path):
    model = dataclasses.replace(COST, calibration={"particles": [1, 2]})
    path = model.save(tmp_path / "cost.json")
    assert CostModel.load(path) == model
    assert json.loads(path.read_text())["kind"] == "kiseki update cost model"
    cases = {
        "missing.json": None,
        "text.json": "not json",
        "other.json": json.dumps({"kind": "something else"}),
        "short.json": json.dumps({"kind": "kiseki update cost model", "fixed_ms": 1.0}),
        "negative.json": json.dumps({**model.to_dict(), "per_beam_ms": -1.0}),
        # a fixed time of 1e300 ms was taken, and a prediction of 300 digits printed
        "huge.json": json.dumps({**model.to_dict(), "fixed_ms": 1e300}),
        "bool.json": json.dumps({**model.to_dict(), "per_particle_ms": True}),
    }
    problems = {
        "missing.json": "cannot read",
        "text.json": "not JSON",
        "other.json": "not a cost model",
        "short.json": "no per_particle_ms, per_beam_ms",
        "negative.json": "per_beam_ms must be a finite number in [0, 1e+09] ms, got -1.0",
        "huge.json": "fixed_ms must be a finite number in [0, 1e+09] ms, got 1e+300",
        "bool.json": "per_particle_ms must be a finite number in [0, 1e+09] ms, got True",
    }
    for name, text in cases.items():
        if text is not None:
            (tmp_path / name).write_text(text)
        with pytest.raises(ValueError) as err:
            CostModel.load(tmp_path / name)
        message = str(err.value)
        assert message.startswith(str(tmp_path / name)) and problems[name] in message
        assert "\n" not in message
    # a FIFO is refused unread (opening it would wait for a writer for ever) and so is a file
    # larger than a cost model can be; /dev/zero would otherwise be read until memory ran out
    os.mkfifo(tmp_path / "fifo.json")
    big = tmp_path / "big.json"
    big.write_bytes(b" " * (COST_MODEL_LIMIT + 1))
    for path, problem in (
        (tmp_path / "fifo.json", "a FIFO (named pipe), not a regular file"),
        (Path("/dev/zero"), "a character device, not a regular file"),
        (big, "larger than 1 MiB (kiseki's limit for cost models)"),
    ):
        with pytest.raises(ValueError, match=re.escape(f"{path}: {problem}")):
            CostModel.load(path)


def test_config_refuses_a_bad_budget():
    for budget in (0.0, -5.0, math.inf):
        with pytest.raises(
            ValueError,
            match=r"^budget_ms must be a finite number > 0 ms \(or None: no budget\), got ",
        ):
            LocalizeConfig(budget_ms=budget)
    with pytest.raises(ValueError, match="a time budget applies"):
        LocalizeConfig(method="space-observation", budget_ms=20.0)


@pytest.fixture(scope="module")
def intel(shared_data):
    scans = read_carmen_log(shared_data / "carmen" / "intel-corrected.log.gz").scans
    grid = build_map(scans.poses, scans.ranges, scans.angles, scans.max_range)
    return scans.first(150), grid


@pytest.mark.parametrize("beam_skip", [False, True])
def test_one_seed_and_one_cost_model_give_one_trajectory_for_any_thread_count(intel, beam_skip):
    scans, grid = intel
    # 0.4 ms + 2e-6 ms per particle + 2e-7 ms per beam evaluation: a 2 ms budget x 0.8 fits
    # (1.6 - 0.4) / (2e-6 + 90 x 2e-7) = 60,000 particles, above the maximum of 3,000; a
    # 0.5 ms budget fits (0.4 - 0.4) / ... = 0 < the minimum 500: at 500, no beam fits, so the
    # floor of 30 beams (rule 3)
    cost = CostModel(0.4, 2e-6, 2e-7)
    runs = {}
    for budget in (None, 2.0, 0.5):
        for threads in (1, 2):
            config = LocalizeConfig(
                seed=3,
                particles=3000,
                min_particles=500,
                kld=True,
                odometry_noise=0.1,
                beam_skip=beam_skip,
                budget_ms=budget,
                threads=threads,
            )
            runs[budget, threads] = localize(scans, grid, config, cost_model=cost)
    for budget in (None, 2.0, 0.5):
        one, two = runs[budget, 1], runs[budget, 2]
        assert np.array_equal(one.estimates, two.estimates)
        assert np.array_equal(one.particle_counts, two.particle_counts)
    assert runs[None, 1].budget is None and runs[None, 1].cost_model is None
    assert np.array_equal(runs[None, 1].estimates, runs[2.0, 1].estimates)  # the cap: 3,000
    low = runs[0.5, 1]
    assert (low.budget.particles, low.budget.beams, low.budget.fits) == (500, 30, False)
    assert low.cost_model == cost and low.particle_counts.max() <= 500
    assert not np.array_equal(low.estimates, runs[None, 1].estimates)


def test_a_calibrated_cost_model_given_back_gives_the_same_trajectory(intel):
    scans, grid = intel
    config = LocalizeConfig(particles=4000, beams=60, budget_ms=1.0, seed=5)
    first = localize(scans, grid, config)  # calibrates on this log
    cost = first.cost_model
    assert cost is not None and len(cost.calibration["quantile_ms"]) == 9
    assert first.budget == choose_counts(1.0, cost, 100, 4000, 60, 30, 0.8)
    again = localize(scans, grid, config, cost_model=cost)
    assert again.budget == first.budget
    assert np.array_equal(again.estimates, first.estimates)
    assert (first.particle_counts[first.updated] == first.budget.particles).all()
