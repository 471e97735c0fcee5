# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Cooperative positioning's movement forms: form 1 and form 2 against the paper's geometry
(sight angles, widths, moves per unit), the seeded positioning loop and its errors along
the chain, and the refusals of bad plans."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.coop import GOAL, START, paper_angle, plan, simulate


def _angle_at(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    u, v = a - p, b - p
    return math.acos(np.clip(u @ v / np.linalg.norm(u) / np.linalg.norm(v), -1, 1))


def test_form_1_measures_the_scout_symmetrically_and_takes_two_moves_per_unit() -> None:
    angle = math.radians(55)
    p = plan(1, 15, angle)
    assert len(p.steps) == 15 and np.allclose(p.steps[-1].target, GOAL)
    at = p.nominal_positions()
    levels = []
    for k, move in enumerate(p.steps[:-1]):
        i, j = move.standing
        before = at[k]
        if k % 2 == 0:  # the scout: both standing robots see it at the angle (theta1 = theta2)
            assert before[i, 1] == pytest.approx(before[j, 1])  # a lateral pair
            assert _angle_at(before[i], before[j], move.target) == pytest.approx(angle)
            assert _angle_at(before[j], before[i], move.target) == pytest.approx(angle)
        else:  # the joiner lands level with the scout: the next pair
            assert move.target[1] == pytest.approx(at[k + 1][p.steps[k - 1].robot][1])
            levels.append(move.target[1])
    rise = np.diff([0.0, *levels])  # the first over the start's baseline: w = 1 m
    assert rise[0] == pytest.approx(math.tan(angle))
    np.testing.assert_allclose(rise[1:], rise[1])  # then 2 moves per unit of forward travel
    assert levels[-1] + rise[1] == pytest.approx(GOAL[1])


def test_form_2_leapfrogs_one_unit_per_move_on_isosceles_triangles() -> None:
    angle = math.radians(50)
    p = plan(2, 9, angle)
    at = p.nominal_positions()
    ys = [m.target[1] for m in p.steps]
    np.testing.assert_allclose(np.diff(ys), GOAL[1] / 9)  # 1 move per unit
    for k, move in enumerate(p.steps[2:-1], start=2):
        before = at[k]
        assert move.robot == int(np.argmin(before[:, 1]))  # the rearmost jumps
        far = max(move.standing, key=lambda r: np.hypot(*(before[r] - move.target)))
        near = move.standing[0] if far == move.standing[1] else move.standing[1]
        assert _angle_at(before[far], before[near], move.target) == pytest.approx(angle)


def test_paper_angle_keeps_the_start_width() -> None:
    for form, n in ((1, 9), (2, 7)):
        p = plan(form, n)
        assert p.angle == pytest.approx(paper_angle(form, n))
        xs = np.abs(p.nominal_positions()[:, :, 0])
        assert xs.max() == pytest.approx(2.0 if form == 1 else 1.0)  # widths follow the start's


def test_simulation_is_seeded_and_its_error_scales_with_the_noise() -> None:
    p = plan(2, 7)
    a, b = simulate(p, 200, seed=4), simulate(p, 200, seed=4)
    np.testing.assert_array_equal(a.goal_errors, b.goal_errors)
    assert not np.array_equal(a.goal_errors, simulate(p, 200, seed=5).goal_errors)
    assert simulate(p, 10, angle_sigma=0.0).goal_errors.max() < 1e-9  # exact without noise
    # first order: ten times the noise, ten times the error (same draws)
    small = simulate(p, 500, angle_sigma=math.radians(0.01), seed=9).goal_errors
    large = simulate(p, 500, angle_sigma=math.radians(0.1), seed=9).goal_errors
    assert large.mean() / small.mean() == pytest.approx(10.0, rel=0.01)


def test_errors_accumulate_along_the_chain() -> None:
    run = simulate(plan(2, 12), 400, seed=2)
    spread = [
        np.sqrt(np.trace(np.cov(run.estimates[:, k + 1, m.robot].T)))
        for k, m in enumerate(run.plan.steps)
    ]
    assert spread[-1] > 2 * spread[0]
    assert np.allclose(run.estimates[:, 0], START)  # the start is measured beforehand


def test_bad_plans_are_refused() -> None:
    with pytest.raises(ValueError, match="form must be 1 or 2"):
        plan(3, 5, 0.9)
    with pytest.raises(ValueError, match="odd number of moves"):
        plan(1, 4, 0.9)
    with pytest.raises(ValueError, match="5..85 deg"):
        plan(2, 5, math.radians(89))
    with pytest.raises(ValueError, match="ahead"):
        plan(2, 5, 0.9, goal=(0.0, -5.0))
    with pytest.raises(ValueError, match="start: expected 3"):
        plan(2, 5, start=[[0.0, 0.0]])
    with pytest.raises(ValueError, match="numbers"):
        plan(2, 5, goal=("a", 1))
    with pytest.raises(ValueError, match="runs"):
        simulate(plan(2, 5), 0)
    with pytest.raises(ValueError, match="seed"):
        simulate(plan(2, 5), 5, seed=-1)


@pytest.mark.parametrize("deg", [40.0, 55.0, 70.0])
def test_form1_readings_meet_at_their_closed_form_sight_angles(deg) -> None:
    """Past the first unit (which keeps the start's width), pair and scout sees its joiner
    along lines meeting at atan(tan(theta) / 3), crossing at theta itself; the scouts' apexes
    at pi - 2 theta in both; both readings reach the goal in the same moves."""
    theta = math.radians(deg)
    scout_pair, crossing = (plan(1, 15, theta, reading=r) for r in ("pair-scout", "crossing"))
    for p, joiner in ((scout_pair, math.atan(math.tan(theta) / 3)), (crossing, theta)):
        a = p.sight_angles()
        np.testing.assert_allclose(a[3:13:2], joiner, atol=1e-9)  # the joiners of units 2-7
        np.testing.assert_allclose(a[2:13:2], min(math.pi - 2 * theta, 2 * theta), atol=1e-9)
        np.testing.assert_allclose(p.steps[-1].target, GOAL)
    with pytest.raises(ValueError, match="reading must be one of"):
        plan(1, 15, theta, reading="diagonal")


def test_an_angle_that_follows_from_the_goal_names_the_goal_and_the_moves() -> None:
    """Without an angle, it follows from the goal's distance and the moves (paper_angle); out
    of range it read 'the representative angle must lie in 5..85 deg, got 0.00716...', as if
    the user had given it, and the command line's --goal was never named."""
    angle = math.degrees(paper_angle(1, 15, START, (0.0, 0.001)))
    with pytest.raises(ValueError) as caught:
        plan(1, 15, None, START, (0.0, 0.001))
    assert str(caught.value) == (
        f"form 1 keeping the start's width to the goal (0, 0.001) in 15 moves stands at "
        f"{angle:.3g} deg, out of the representative angle's 5..85 deg: move the goal, change "
        "the moves or give the angle"
    )
    with pytest.raises(ValueError, match=r"to the goal \(0, 900\) in 1 move stands at 89.9 deg"):
        plan(1, 1, None, START, (0.0, 900.0))
    assert 5 < math.degrees(plan(1, 15, None, START, (0.0, 20.0)).angle) < 85  # in range: taken
    with pytest.raises(ValueError, match="^form 1 takes an odd number of moves"):  # said first
        plan(1, 14, None, START, (0.0, 0.001))
