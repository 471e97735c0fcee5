# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""mcl-relocalization's per-scan judgement against a brute-force numpy reference on small random
maps: every lattice pose scored (_helpers.relocalization_reference), the best score within and
beyond the radius of the truth taken from that array, the truth's own off-lattice score read
from the likelihood field written out, and the rank of the first hit in the brute force's
selection; and the scan draw's spread."""

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
from kiseki.filters import RelocalizeConfig, Relocalizer
from kiseki_experiments.mcl.mcl_relocalization import (
    RelocalizationConfig,
    ScanOutcome,
    draw_scans,
    judge_scan,
)


def field_score(grid, angles, ranges, config: RelocalizeConfig, pose) -> float:
    """The likelihood field's log-likelihood of the scan at any pose (the laser at the robot,
    each end read in the cell that holds it; the beams by nav2's rule)."""
    cells = np.asarray(grid.cells)
    h, w = cells.shape
    res = grid.resolution
    oy, ox = np.nonzero(cells >= 65)
    step = max(1, (len(angles) - 1) // (config.beams - 1)) if config.beams > 1 else 1
    a, r = angles[::step], ranges[::step].astype(np.float64)
    keep = (r > 0) & (r < MAX_RANGE)
    a, r = a[keep], r[keep]
    x, y, th = pose
    ex = np.floor((x + r * np.cos(th + a) - grid.origin.x) / res).astype(int)
    ey = np.floor((y + r * np.sin(th + a) - grid.origin.y) / res).astype(int)
    s = config.sigma_hit
    total = 0.0
    for cx, cy in zip(ex, ey, strict=True):
        d = config.max_distance
        if 0 <= cx < w and 0 <= cy < h:
            d = min(d, float(np.sqrt((ox - cx) ** 2 + (oy - cy) ** 2).min() * res))
        g = math.exp(-(d**2) / (2 * s * s)) / (math.sqrt(2 * math.pi) * s)
        total += math.log(config.z_hit * g + config.z_rand / MAX_RANGE)
    return total


@pytest.mark.parametrize("seed", range(3))
def test_a_scans_judgement_is_the_brute_force_one(seed):
    grid, angles, ranges = random_case(20 + seed)
    rc = RelocalizeConfig(beams=15, depth=2, angular_step=0.2, hypotheses=3, threads=1)
    matcher = Relocalizer(grid, MAX_RANGE, rc)
    near_matcher = Relocalizer(
        grid, MAX_RANGE, RelocalizeConfig(**{**rc.__dict__, "hypotheses": 1})
    )
    headings = matcher.headings(angles, ranges)
    scores, taken = brute_force(grid, angles, ranges, rc, headings)
    positions = lattice_positions(grid, headings)
    config = RelocalizationConfig(near_radius=0.5, hit_distance=0.3, hit_angle_deg=15.0, top=3)
    # the truth a little off the first or the second hypothesis (off the lattice): hits of rank
    # 1 and 2
    rng = np.random.default_rng(seed)
    _, px, py, th, _ = taken[seed % 2]
    truth = np.array([px + rng.uniform(-0.1, 0.1), py + rng.uniform(-0.1, 0.1), th + 0.05])
    got = judge_scan(matcher, near_matcher, angles, ranges, truth, config)

    distance = np.hypot(positions[..., 0] - truth[0], positions[..., 1] - truth[1])
    near = np.where(distance <= config.near_radius, scores, -np.inf).max()
    far = np.where(distance > config.near_radius, scores, -np.inf).max()
    assert got.near == pytest.approx(near, abs=1e-6)
    assert got.far == pytest.approx(far, abs=1e-6)
    assert got.truth == pytest.approx(field_score(grid, angles, ranges, rc, truth), abs=1e-4)
    hits = [
        math.hypot(x - truth[0], y - truth[1]) <= config.hit_distance
        and abs(math.degrees(math.remainder(t - truth[2], math.tau))) <= config.hit_angle_deg
        for _, x, y, t, _ in taken
    ]
    assert got.rank == (hits.index(True) + 1 if any(hits) else 0)
    assert got.error_m == pytest.approx(math.hypot(taken[0][1] - truth[0], taken[0][2] - truth[1]))
    assert got.identifiable(0.05) == (far < near - 0.05 * abs(near))


@pytest.mark.parametrize(
    ("near", "far", "identifiable"),
    [
        (40.0, 38.5, False),  # within 2.0 (5 % of 40) of a positive score
        (40.0, 37.9, True),
        (-20.0, -20.9, False),  # within 1.0 of a negative one
        (-20.0, -21.1, True),
        (10.0, 12.0, False),  # a far pose scores better
        (-math.inf, -5.0, False),  # no lattice pose near the truth
    ],
)
def test_identifiable_reads_the_tolerance_on_the_scores_magnitude(near, far, identifiable):
    outcome = ScanOutcome(0.0, 0.0, 1, near, near, far, 0.0)
    assert outcome.identifiable(0.05) is identifiable


def test_scans_are_drawn_one_from_each_run_of_the_log():
    rng = np.random.default_rng(0)
    picks = draw_scans(1000, 200, rng)
    assert len(picks) == 200
    np.testing.assert_array_equal(picks // 5, np.arange(200))  # one in each run of 5 scans
    assert len(set((picks % 5).tolist())) > 1  # drawn, not the runs' first scans
    assert not np.array_equal(picks, draw_scans(1000, 200, np.random.default_rng(1)))
    np.testing.assert_array_equal(draw_scans(30, 200, rng), np.arange(30))
