# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Relocalization from one scan against a brute-force numpy reference (_helpers.
relocalization_reference): every lattice pose of a small random map scored with the likelihood
field written out, then the greedy selection of distinct poses, and the best pose on either side
of a disc."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _helpers.relocalization_reference import (
    MAX_RANGE,
    brute_force,
    lattice_positions,
    random_case,
)
from kiseki.errors import RelocalizationError
from kiseki.filters import RelocalizeConfig, Relocalizer, SearchDisc, relocalize


@pytest.mark.parametrize("seed", range(4))
def test_hypotheses_are_the_brute_force_selection(seed):
    grid, angles, ranges = random_case(seed)
    config = RelocalizeConfig(
        beams=(0, 15)[seed % 2],
        depth=seed % 4,
        angular_step=0.2,
        hypotheses=3,
        min_distance=0.4,
        min_angle=0.8,
        free_only=seed != 1,
        threads=1,
    )
    matcher = Relocalizer(grid, MAX_RANGE, config)
    headings = matcher.headings(angles, ranges)
    assert headings == math.ceil(2 * math.pi / 0.2 - 1e-9)
    got = matcher.match(angles, ranges)
    scores, want = brute_force(grid, angles, ranges, config, headings)
    assert len(got) == len(want) == config.hypotheses
    # the same scores as the brute force's selection, and each one is the pose's own score
    np.testing.assert_allclose([g.score for g in got], [t[0] for t in want], rtol=0, atol=1e-6)
    for g in got:
        assert scores[g.heading, g.cell[1], g.cell[0]] == pytest.approx(g.score, abs=1e-6)
    assert got[0].score == pytest.approx(scores.max(), abs=1e-6)
    # scores() of the hypotheses' poses, the likelihood field read pose by pose, agrees
    poses = np.array([[g.x, g.y, g.theta] for g in got])
    np.testing.assert_allclose(
        matcher.scores(angles, ranges, poses), [g.score for g in got], rtol=0, atol=1e-4
    )
    two = relocalize(
        grid, angles, ranges, MAX_RANGE, RelocalizeConfig(**{**config.__dict__, "threads": 2})
    )
    assert two == got


@pytest.mark.parametrize("seed", range(4))
def test_the_best_pose_on_each_side_of_a_disc_is_the_brute_force_maximum(seed):
    grid, angles, ranges = random_case(10 + seed)
    sensor = ((0.0, 0.0, 0.0), (0.3, -0.1, 0.4))[seed % 2]
    config = RelocalizeConfig(
        beams=15, depth=1 + seed % 3, angular_step=0.3, hypotheses=1, threads=1 + seed % 2
    )
    matcher = Relocalizer(grid, MAX_RANGE, config, sensor)
    headings = matcher.headings(angles, ranges)
    scores, _ = brute_force(grid, angles, ranges, config, headings)
    positions = lattice_positions(grid, headings, sensor)
    rng = np.random.default_rng(seed)
    h, w = scores.shape[1:]
    for _ in range(4):
        centre = grid.origin.x + rng.uniform(0, w * 0.1), grid.origin.y + rng.uniform(0, h * 0.1)
        radius = float(rng.uniform(0.05, 0.8))
        distance = np.hypot(positions[..., 0] - centre[0], positions[..., 1] - centre[1])
        for inside in (True, False):
            side = distance <= radius if inside else distance > radius
            want = np.where(side, scores, -np.inf).max()
            got = matcher.match(angles, ranges, SearchDisc(*centre, radius, inside))
            if not np.isfinite(want):
                assert got == []
                continue
            assert got[0].score == pytest.approx(want, abs=1e-6)
            assert side[got[0].heading, got[0].cell[1], got[0].cell[0]]


def test_bad_input_is_one_line_naming_the_problem():
    grid, angles, ranges = random_case(0)
    with pytest.raises(RelocalizationError, match="hypotheses must be an integer"):
        RelocalizeConfig(hypotheses=0)
    with pytest.raises(
        RelocalizationError, match=r"^relocalize: sigma_hit must be a finite number > 0 m, got nan$"
    ):
        RelocalizeConfig(sigma_hit=float("nan"))
    with pytest.raises(
        RelocalizationError,
        match=r"^relocalize: max_range must be a finite number > 0 m, got 0\.0$",
    ):
        relocalize(grid, angles, ranges, 0.0)
    with pytest.raises(RelocalizationError, match="angles and ranges"):
        relocalize(grid, angles, ranges[:-1], MAX_RANGE)
    with pytest.raises(RelocalizationError, match="arrays of numbers"):
        relocalize(grid, angles, ["a"] * len(angles), MAX_RANGE)
    with pytest.raises(RelocalizationError, match="map must be an OccupancyGrid"):
        relocalize(np.zeros((5, 5)), angles, ranges, MAX_RANGE)
    assert relocalize(grid, angles, np.full(len(angles), np.inf, np.float32), MAX_RANGE) == []
    with pytest.raises(
        RelocalizationError,
        match=r"^relocalize: the search disc's radius must be a finite number >= 0 m, got -1\.0$",
    ):
        SearchDisc(0.0, 0.0, -1.0)
    with pytest.raises(RelocalizationError, match="disc must be a SearchDisc"):
        Relocalizer(grid, MAX_RANGE).match(angles, ranges, (0.0, 0.0, 1.0))


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"max_distance": -1.0}, "max_distance must be a finite number > 0 m, got -1.0"),
        ({"angular_step": -1.0}, "angular_step must be a finite number >= 0 rad, got -1.0"),
        ({"min_distance": -1.0}, "min_distance must be a finite number >= 0 m, got -1.0"),
        ({"min_angle": -1.0}, "min_angle must be a finite number >= 0 rad, got -1.0"),
    ],
)
def test_a_relocalize_setting_is_refused_in_its_unit(fields, message):
    """The lengths and angles read bare ('min_angle must be a finite number >= 0')."""
    with pytest.raises(RelocalizationError) as caught:
        RelocalizeConfig(**fields)
    assert str(caught.value) == f"relocalize: {message}"


def test_the_disc_and_the_sensor_are_refused_in_their_units():
    grid, _, _ = random_case(0)
    for axis, disc, bad in (("x", (math.nan, 0.0, 1.0), "nan"), ("y", (0.0, math.inf, 1.0), "inf")):
        with pytest.raises(RelocalizationError) as caught:
            SearchDisc(*disc)
        assert str(caught.value) == (
            f"relocalize: the search disc's {axis} must be a finite number (m), got {bad}"
        )
    for axis, sensor, unit in (
        ("x", (math.nan, 0.0, 0.0), "m"),
        ("y", (0.0, math.nan, 0.0), "m"),
        ("theta", (0.0, 0.0, math.nan), "rad"),
    ):
        with pytest.raises(RelocalizationError) as caught:
            Relocalizer(grid, MAX_RANGE, sensor=sensor)
        assert str(caught.value) == (
            f"relocalize: sensor {axis} must be a finite number ({unit}), got nan"
        )


def test_a_depth_past_the_map_finds_the_brute_force_selection():
    """Depth 16 (in its documented range) laid out 17 levels of (w + 65,535) x (h + 65,535)
    cells on a small map, 366 GB on 80 x 80: the levels stop at the first whose node covers the
    map, and the hypotheses are still the brute force's selection."""
    grid, angles, ranges = random_case(2)
    config = RelocalizeConfig(beams=15, depth=16, angular_step=0.3, hypotheses=3, threads=1)
    matcher = Relocalizer(grid, MAX_RANGE, config)
    got = matcher.match(angles, ranges)
    _, want = brute_force(grid, angles, ranges, config, matcher.headings(angles, ranges))
    assert len(got) == len(want) == 3
    np.testing.assert_allclose([g.score for g in got], [t[0] for t in want], rtol=0, atol=1e-6)
