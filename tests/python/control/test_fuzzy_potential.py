# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The Fuzzy Potential Method against hand-computed headings and a brute-force loop version."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.control import FuzzyPotentialConfig, FuzzyPotentialMethod

MAX_RANGE = 4.0
ANGLES = np.linspace(-math.radians(120), math.radians(120), 683)  # the paper's laser
R = 0.35 + 0.10  # robot half-width + margin (the defaults)


def scan(segments, angles=ANGLES):
    """Ranges from the origin to the nearest of the segments ((x0, y0), (x1, y1)), a loop."""
    ranges = np.full(angles.shape, MAX_RANGE)
    for k, a in enumerate(angles):
        dx, dy = math.cos(a), math.sin(a)
        for (x0, y0), (x1, y1) in segments:
            ex, ey = x1 - x0, y1 - y0
            den = dx * (-ey) - dy * (-ex)
            if abs(den) < 1e-15:
                continue
            t = (x0 * (-ey) - y0 * (-ex)) / den
            u = (dx * y0 - dy * x0) / den
            if t > 0 and 0 <= u <= 1:
                ranges[k] = min(ranges[k], t)
    return ranges


def brute_force(goal, angles, ranges, max_range, c=None):
    """The module docstring's definitions, one direction and one beam at a time."""
    c = c if c is not None else FuzzyPotentialConfig()
    n = int(round(2 * math.pi / c.step))
    psis = [-math.pi + k * 2 * math.pi / n for k in range(n)]
    psi_g = math.atan2(goal[1], goal[0])

    def wrap(a):
        return (a + math.pi) % (2 * math.pi) - math.pi

    mu = []
    for psi in psis:
        mu_g = max(0.0, 1 - abs(wrap(psi - psi_g)) / c.goal_half_width)
        mu_o = 0.0
        for a, d in zip(angles, ranges, strict=True):
            if not (d < max_range) or d >= c.influence_distance:
                continue
            depth = min(1.0, (c.influence_distance - d) / (c.influence_distance - c.stop_distance))
            half = math.asin(min(1.0, (c.robot_radius + c.margin) / d))
            if abs(wrap(psi - a)) <= half:
                mu_o = max(mu_o, depth)
        mu.append(min(mu_g, 1 - mu_o))
    best = max(mu)
    top = [m >= best - 1e-9 for m in mu]
    if all(top):
        return min(psis, key=lambda p: abs(wrap(p - psi_g))), best * c.v_max
    runs = []  # (width, start index) of circular runs of maximal directions
    start = next(k for k in range(n) if not top[k]) + 1
    k = 0
    while k < n:
        i = (start + k) % n
        if top[i]:
            width = 0
            while k < n and top[(start + k) % n]:
                width, k = width + 1, k + 1
            runs.append((width, i))
        else:
            k += 1
    widest = max(w for w, _ in runs)
    centres = [wrap(psis[i] + (w - 1) / 2 * 2 * math.pi / n) for w, i in runs if w == widest]
    closest = min(abs(wrap(ct - psi_g)) for ct in centres)
    return min(ct for ct in centres if abs(wrap(ct - psi_g)) <= closest + 1e-9), best * c.v_max


def test_open_field_heads_at_the_goal_at_full_speed():
    heading, speed = FuzzyPotentialMethod().direction((3.0, 3.0), ANGLES, scan([]), MAX_RANGE)
    assert heading == pytest.approx(math.radians(45), abs=1e-12)
    assert speed == pytest.approx(0.5)


def edge_beam(limit_rad):
    """The last beam angle at or below limit_rad: the wall's last hit."""
    return float(ANGLES[limit_rad >= ANGLES].max())


def test_wall_ahead_turns_towards_the_gap_by_the_hand_computed_angle():
    # wall across the goal direction 1 m ahead, from y = -2 to 0.3; the gap is on the left
    ranges = scan([((1.0, -2.0), (1.0, 0.3))])
    a_e = edge_beam(math.atan2(0.3, 1.0))
    d_e = 1.0 / math.cos(a_e)
    # the wall's last point bounds the blocked directions: phi + asin(R / d) grows towards the
    # edge (its derivative 1 - R sin(phi) / sqrt(1 - (R cos(phi))^2) > 0 for R = 0.45, h = 1)
    boundary = math.degrees(a_e + math.asin(R / d_e))  # 42.2 deg
    expected = math.ceil(boundary)  # first free 1-degree direction
    assert expected == 43
    heading, speed = FuzzyPotentialMethod().direction((3.0, 0.0), ANGLES, ranges, MAX_RANGE)
    assert heading == pytest.approx(math.radians(expected), abs=1e-9)
    assert speed == pytest.approx(0.5 * (1 - expected / 180), abs=1e-9)
    assert (heading, speed) == pytest.approx(brute_force((3.0, 0.0), ANGLES, ranges, MAX_RANGE))


@pytest.mark.parametrize("left", [0.75, 0.6, 0.9])
def test_corridor_keeps_the_heading_parallel_to_the_walls(left):
    # 1.5 m corridor along x, centred or off-centre; both walls stay > R = 0.45 m to the side
    ranges = scan([((-1.0, left), (10.0, left)), ((-1.0, left - 1.5), (10.0, left - 1.5))])
    heading, speed = FuzzyPotentialMethod().direction((5.0, 0.0), ANGLES, ranges, MAX_RANGE)
    assert heading == 0.0
    assert speed == pytest.approx(0.5)


def test_symmetric_obstacle_ties_break_to_the_right_every_time():
    ranges = scan([((1.0, -0.5), (1.0, 0.5))])
    a_e = edge_beam(math.atan2(0.5, 1.0))
    expected = math.ceil(math.degrees(a_e + math.asin(R * math.cos(a_e))))  # d = 1 / cos a
    assert expected == 51
    fpm = FuzzyPotentialMethod()
    mu_g, mu_o, mu, _ = fpm.memberships((3.0, 0.0), ANGLES, ranges, MAX_RANGE)
    k_left = int(np.argmin(np.abs(fpm.directions - math.radians(expected))))
    k_right = int(np.argmin(np.abs(fpm.directions + math.radians(expected))))
    assert mu[k_left] == pytest.approx(mu[k_right], abs=1e-12) == pytest.approx(mu.max())
    answers = {fpm.direction((3.0, 0.0), ANGLES, ranges, MAX_RANGE) for _ in range(3)}
    mirrored = fpm.direction((3.0, 0.0), -ANGLES[::-1], ranges[::-1], MAX_RANGE)
    assert len(answers) == 1 and mirrored == pytest.approx(answers.pop())
    assert mirrored[0] == pytest.approx(-math.radians(expected), abs=1e-9)


def test_a_plateau_gives_its_centre_half_a_step_off_the_grid():
    # a ring of returns at 1 m covers every direction within +-146.7 deg with depth 2/3, so
    # mu = min(mu_g, 1/3): maximal wherever mu_g >= 1/3, i.e. within 120 deg of the goal
    ranges = np.full(ANGLES.shape, 1.0)
    psi_g = math.degrees(math.atan2(0.5, 3.0))  # 9.46 deg
    lo, hi = math.ceil(psi_g - 120), math.floor(psi_g + 120)  # -110 .. 129
    heading, speed = FuzzyPotentialMethod().direction((3.0, 0.5), ANGLES, ranges, MAX_RANGE)
    assert heading == pytest.approx(math.radians((lo + hi) / 2), abs=1e-9)  # 9.5 deg
    assert speed == pytest.approx(0.5 / 3)


@pytest.mark.parametrize("seed", range(6))
def test_random_scenes_match_the_brute_force_loop(seed):
    rng = np.random.default_rng(seed)
    angles = np.linspace(-math.radians(120), math.radians(120), 61)
    ranges = rng.uniform(0.2, 5.0, angles.size)
    ranges[rng.random(angles.size) < 0.1] = np.nan
    goal = rng.uniform(-3, 3, 2)
    config = FuzzyPotentialConfig(step=math.radians(rng.choice([1.0, 2.0, 5.0])))
    got = FuzzyPotentialMethod(config).direction(goal, angles, ranges, MAX_RANGE)
    assert got == pytest.approx(brute_force(goal, angles, ranges, MAX_RANGE, config), abs=1e-12)


@pytest.mark.parametrize(
    ("goal", "angles", "ranges", "match"),
    [
        ((1.0, 0.0), [], [], "empty"),
        ((1.0, 0.0), [0.0, 0.1], [1.0], "2 angles but 1 ranges"),
        ((math.nan, 0.0), [0.0], [1.0], "goal"),
        ((0.0, 0.0), [0.0], [1.0], "coincides"),
    ],
)
def test_bad_input_is_refused(goal, angles, ranges, match):
    with pytest.raises(ValueError, match=match):
        FuzzyPotentialMethod().direction(goal, angles, ranges, MAX_RANGE)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("v_max", 0.0),
        ("robot_radius", -1.0),
        ("margin", math.nan),
        ("stop_distance", 3.0),
        ("step", 1e-9),  # asked for 46.8 GiB of candidate directions
        ("step", math.radians(46.0)),
    ],
)
def test_bad_config_names_the_field(field, value):
    with pytest.raises(
        ValueError, match="influence_distance" if field == "stop_distance" else field
    ):
        FuzzyPotentialConfig(**{field: value})


def test_negative_and_zero_readings_are_invalid_as_nan():
    """kiseki's rule (kiseki.scans): a reading <= 0 says nothing; it counted as an obstacle at
    the robot, which blocks about half the directions."""
    angles = np.linspace(-math.pi, math.pi, 73)[:-1]
    free = np.full(72, MAX_RANGE)
    want = FuzzyPotentialMethod().direction((5.0, 0.0), angles, free, MAX_RANGE)
    for bad in (-1.0, 0.0, np.nan):
        ranges = free.copy()
        ranges[[10, 40]] = bad
        assert FuzzyPotentialMethod().direction((5.0, 0.0), angles, ranges, MAX_RANGE) == want


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("v_max", 0.0, "FuzzyPotentialConfig.v_max must be a finite number > 0 m/s, got 0.0"),
        (
            "robot_radius",
            -1.0,
            "FuzzyPotentialConfig.robot_radius must be a finite number > 0 m, got -1.0",
        ),
        ("margin", math.nan, "FuzzyPotentialConfig.margin must be a finite number >= 0 m, got nan"),
        ("step", -0.1, "FuzzyPotentialConfig.step must be a finite number > 0 rad, got -0.1"),
    ],
)
def test_a_bad_config_number_is_worded_as_one_rule(field, value, message):
    with pytest.raises(ValueError) as e:
        FuzzyPotentialConfig(**{field: value})
    assert str(e.value) == message


@pytest.mark.parametrize("bad", [0.0, math.inf, True])  # True was a range of 1 m
def test_a_bad_max_range_is_refused(bad):
    with pytest.raises(ValueError) as e:
        FuzzyPotentialMethod().direction((1.0, 0.0), [0.0], [1.0], bad)
    assert str(e.value) == f"max_range must be a finite number > 0 m, got {bad!r}"
