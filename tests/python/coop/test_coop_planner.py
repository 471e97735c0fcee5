# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Cooperative positioning's first-order prediction against Monte Carlo, and the move
planner against every swept setting."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.coop import GOAL, START, plan, simulate
from kiseki.coop.planner import plan_moves, predict, predicted_goal_rms


@pytest.mark.parametrize(("form", "moves"), [(1, 5), (1, 15), (2, 7), (2, 20)])
def test_predicted_covariance_matches_monte_carlo(form: int, moves: int) -> None:
    p = plan(form, moves)
    tiny = math.radians(1e-3)  # first order holds
    run = simulate(p, 3000, tiny, seed=11)
    for k in (len(p.steps) // 2, len(p.steps)):
        err = (run.estimates[:, k] - run.truth[k]).reshape(len(run.estimates), 6)
        sample = np.cov(err.T)
        cov = predict(p, tiny)[k]
        assert np.linalg.norm(sample - cov) < 0.08 * np.linalg.norm(cov), (form, moves, k)
    # and at the paper's noise the RMS at the goal
    full = simulate(p, 3000, seed=12)
    d = full.estimates[:, -1, p.steps[-1].robot] - p.steps[-1].target
    assert predicted_goal_rms(p) == pytest.approx(np.sqrt((d**2).sum(1).mean()), rel=0.05)


def test_prediction_stays_positive_semidefinite_on_long_chains() -> None:
    p = plan(1, 71, None, START, (0.0, 21.5))
    for cov in predict(p):
        assert np.linalg.eigvalsh(cov).min() >= -1e-12 * max(1.0, np.trace(cov))


def test_planner_beats_every_swept_setting() -> None:
    chosen = plan_moves()
    assert np.allclose(chosen.steps[-1].target, GOAL)
    for m in chosen.steps:
        assert m.robot not in m.standing and len(set(m.standing)) == 2
        assert np.abs(m.target[0] - GOAL[0]) <= 2.0 + 1e-9  # within its region
    swept = [plan(1, n) for n in range(1, 40, 2)] + [plan(2, n) for n in range(1, 31)]
    best = min(swept, key=predicted_goal_rms)
    assert predicted_goal_rms(chosen) < 0.9 * predicted_goal_rms(best)
    ours = simulate(chosen, 3000, seed=21).goal_errors.mean()
    theirs = simulate(best, 3000, seed=21).goal_errors.mean()
    assert ours < theirs
    with pytest.raises(ValueError, match="spacing"):
        plan_moves(spacing=0.0)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"spacing": 0.0}, "spacing must be a finite number > 0 m, got 0.0"),
        ({"spacing": True}, "spacing must be a finite number > 0 m, got True"),  # was 1 m
        ({"reach": 0.2}, "reach (more than the spacing) must be a finite number > 0.25 m, got 0.2"),
        (
            {"reach": math.inf},
            "reach (more than the spacing) must be a finite number > 0.25 m, got inf",
        ),
        (
            {"spacing": 0.5, "reach": 0.4},
            "reach (more than the spacing) must be a finite number > 0.5 m, got 0.4",
        ),
        ({"half_width": math.nan}, "half_width must be a finite number > 0 m, got nan"),
        ({"max_moves": 2.5}, "max_moves must be an integer in 1..1,000, got 2.5"),
        ({"max_moves": True}, "max_moves must be an integer in 1..1,000, got True"),
    ],
)
def test_the_planner_names_a_bad_setting(kwargs, message):
    with pytest.raises(ValueError) as caught:
        plan_moves(**kwargs)
    assert str(caught.value) == message
