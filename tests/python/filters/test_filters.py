# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The Monte Carlo engine through its Python API: invariants under property tests (hypothesis),
the same trajectory for any thread count, the motion model's spread against its closed form,
resampling against the weights, Python-written models plugged in, and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kiseki import _core
from kiseki.core import Pose2
from kiseki.filters import MclConfig, MonteCarloLocalizer, scan_model
from kiseki.grid import OccupancyGrid


def room() -> OccupancyGrid:
    """An 8 m x 5 m room at 0.05 m with a block in one corner: no symmetry."""
    cells = np.zeros((100, 160), np.int8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 100
    cells[60:80, 110:140] = 100
    return OccupancyGrid(cells, 0.05, Pose2(-1.0, -1.0, 0.0))


ANGLES = np.linspace(-np.pi / 2, np.pi / 2, 61)


def scan_at(grid: OccupancyGrid, pose) -> np.ndarray:
    return np.array(
        [grid.cast_ray(pose[0], pose[1], pose[2] + a, max_range=8.0)[0] for a in ANGLES],
        dtype=np.float32,
    )


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**64 - 1),
    kld=st.booleans(),
    particles=st.integers(50, 3000),
    resampling=st.sampled_from(["multinomial", "systematic", "stratified", "residual"]),
    recovery=st.sampled_from(["none", "augmented", "resetting"]),
    steps=st.integers(1, 6),
)
def test_engine_invariants_hold(seed, kld, particles, resampling, recovery, steps) -> None:
    """Weights normalised, no NaN, the count within the KLD bounds, for any settings."""
    grid = room()
    config = MclConfig(
        particles=particles,
        kld=kld,
        min_particles=min(30, particles),
        resampling=resampling,
        recovery=recovery,
        resample_threshold=1.0,
        sensor_reset_candidates=500,
        threads=1,
    )
    loc = MonteCarloLocalizer(config, seed % 2**63, grid)
    loc.initialize((2.0, 2.0, 0.0), (0.3, 0.3, 0.2))
    model = scan_model("likelihood-field", grid)
    truth = np.array([2.0, 2.0, 0.0])
    for k in range(steps):
        truth = truth + [0.1, 0.0, 0.02]
        model.set_scan(ANGLES, scan_at(grid, truth), 8.0)
        loc.step(truth, lambda: model)
        w = loc.weights
        assert np.isfinite(loc.poses).all() and np.isfinite(w).all()
        assert w.sum() == pytest.approx(1.0, abs=1e-9) and (w >= 0).all()
        low = config.min_particles if kld else particles
        assert low <= loc.size <= particles, k
        assert 0.0 <= loc.reliability <= 1.0


def run(threads: int, seed: int = 5) -> np.ndarray:
    grid = room()
    loc = MonteCarloLocalizer(MclConfig(particles=4000, threads=threads), seed, grid)
    loc.initialize((1.0, 1.0, 0.3), (0.2, 0.2, 0.1))
    model = scan_model("likelihood-field", grid)
    out = []
    pose = np.array([1.0, 1.0, 0.3])
    for _ in range(15):
        pose = pose + [0.08, 0.05, 0.01]
        model.set_scan(ANGLES, scan_at(grid, pose), 8.0)
        loc.step(pose, lambda: model)
        out.append(np.concatenate([loc.estimate, loc.poses[::97].ravel()]))
    return np.array(out)


def test_same_seed_same_trajectory_for_one_and_two_threads() -> None:
    one, two = run(1), run(2)
    np.testing.assert_array_equal(one, two)
    assert not np.array_equal(one, run(1, seed=6))


def test_motion_noise_has_the_closed_form_spread() -> None:
    """Straight 1 m: translation SD sqrt(alpha3) m; a turn on the spot of 0.05 rad with 0.1 mm of
    slip: heading SD sqrt(alpha1) x 0.05 (the slip's direction is not turned there and back);
    straight back 0.1 m has the noise of straight ahead."""
    alphas = (0.002, 0.002, 0.0005, 0.0005)
    for odom, sd_x, sd_theta in (
        ((-1e-4, -1e-5, 0.05), None, math.sqrt(0.002) * 0.05),
        ((0.1, 0.0, 0.0), math.sqrt(0.0005) * 0.1, math.sqrt(2 * 0.002) * 0.1),
        ((-0.1, 0.0, 0.0), math.sqrt(0.0005) * 0.1, math.sqrt(2 * 0.002) * 0.1),
    ):
        loc = MonteCarloLocalizer(MclConfig(particles=8000, alphas=alphas), 3)
        loc.initialize((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        loc.engine.predict(Pose2(0, 0, 0), Pose2(*odom))
        p = loc.poses
        assert p[:, 2].std() == pytest.approx(sd_theta, rel=0.08)
        assert abs(p[:, 2].mean() - odom[2]) < 1e-3
        if sd_x is not None:
            assert p[:, 0].std() == pytest.approx(sd_x, rel=0.08)
            assert abs(p[:, 0].mean() - odom[0]) < 1e-3


def test_resampling_follows_the_weights() -> None:
    w = np.array([0.5, 0.0, 0.3, 0.2])
    for method in ("multinomial", "systematic", "stratified", "residual"):
        counts = np.zeros(4)
        for seed in range(200):
            counts += np.bincount(_core.resample_indices(w, 100, method, seed), minlength=4)
        np.testing.assert_allclose(counts / counts.sum(), w, atol=0.01)
        assert counts[1] == 0
    with pytest.raises(ValueError, match="unknown method"):
        _core.resample_indices(w, 10, "lucky", 0)
    assert _core.effective_sample_size(np.full(10, 0.1)) == pytest.approx(10)


def test_weights_and_particles_can_be_set_without_losing_weights() -> None:
    loc = MonteCarloLocalizer(MclConfig(particles=3), 1)
    poses = np.array([[0.0, 1.0, 0.1], [2.0, 3.0, -0.2], [4.0, 5.0, 3.0]])
    loc.engine.set_particles(poses, np.array([1.0, 1.0, 2.0]))
    np.testing.assert_allclose(loc.weights, [0.25, 0.25, 0.5])
    turned = loc.poses.copy()
    turned[:, 2] = 0.5  # a per-particle heading reset (the magnetic thesis, ch. 5)
    loc.engine.set_particles(turned, loc.weights)
    np.testing.assert_allclose(loc.weights, [0.25, 0.25, 0.5])
    loc.engine.set_weights([3.0, 1.0, 0.0])
    assert loc.engine.estimate().x == pytest.approx(0.5)
    with pytest.raises(ValueError, match="poses"):
        loc.engine.set_particles(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="finite"):
        loc.engine.set_particles(np.array([[0.0, np.nan, 0.0]]))
    with pytest.raises(ValueError, match="sum to 0"):
        loc.engine.set_weights([0.0, 0.0, 0.0])


def test_a_model_written_in_python_plugs_in() -> None:
    """A 1-D Gaussian 'beacon' model in numpy: the cloud moves onto x = 2.5."""
    loc = MonteCarloLocalizer(MclConfig(particles=2000), 2)
    loc.initialize((2.0, 0.0, 0.0), (0.5, 0.05, 0.01))
    report = loc.step_log_likelihoods(
        (2.0, 0.0, 0.0), lambda poses: -0.5 * ((poses[:, 0] - 2.5) / 0.05) ** 2
    )
    assert report.informative and abs(loc.estimate[0] - 2.5) < 0.02
    with pytest.raises(ValueError, match="NaN"):
        loc.step_log_likelihoods((2.0, 0.0, 0.0), lambda poses: np.full(len(poses), np.nan))


def test_update_gate_and_bad_input() -> None:
    grid = room()
    loc = MonteCarloLocalizer(MclConfig(particles=100, update_min_d=0.2, update_min_a=0.5), 0)
    loc.initialize((1.0, 1.0, 0.0), (0.01, 0.01, 0.01))
    model = scan_model("likelihood-field", grid)
    model.set_scan(ANGLES, scan_at(grid, (1.0, 1.0, 0.0)), 8.0)
    assert loc.step((1.0, 1.0, 0.0), lambda: model) is not None  # the first scan is used
    assert loc.step((1.1, 1.0, 0.0), lambda: model) is None  # 0.1 m: no update
    assert loc.estimate[0] == pytest.approx(1.1, abs=0.02)  # follows the odometry
    assert loc.step((1.25, 1.0, 0.0), lambda: model) is not None
    with pytest.raises(ValueError, match="jumps"):
        loc.step((101.0, 1.0, 0.0), lambda: model)  # 100 m between two scans
    with pytest.raises(ValueError, match="particles"):
        MclConfig(particles=0)
    with pytest.raises(ValueError, match="recovery"):
        MclConfig(recovery="hope")
    with pytest.raises(ValueError, match="threads"):
        MclConfig(threads=-1)
    with pytest.raises(ValueError, match="reset_evidence"):
        MclConfig(reset_evidence=float("nan"))
    with pytest.raises(ValueError, match="reset_likelihood_drop"):
        MclConfig(reset_likelihood_drop=1.0)
    with pytest.raises(ValueError, match="free cell"):
        MonteCarloLocalizer(MclConfig(), 0, OccupancyGrid(np.full((4, 4), -1, np.int8), 0.1))
    with pytest.raises(ValueError, match="differ in length"):
        model.set_scan(ANGLES, np.ones(5, np.float32), 8.0)
    with pytest.raises(ValueError, match="max_range"):
        model.set_scan(ANGLES, scan_at(grid, (1.0, 1.0, 0.0)), 0.0)


def test_invalid_readings_are_skipped_and_no_returns_scored_as_nav2() -> None:
    """NaN, zero and negative ranges count as no reading; +inf and readings at max range are
    no-returns: the likelihood field skips them, the beam model scores them with z_max."""
    grid = room()
    pose = np.array([[2.0, 2.0, 0.0]])
    ranges = scan_at(grid, pose[0])
    lf = scan_model("likelihood-field", grid)
    beam = scan_model("beam", grid)
    lf.set_scan(ANGLES, ranges, 8.0)
    beam.set_scan(ANGLES, ranges, 8.0)
    clean_lf, clean_beam = lf.log_likelihoods(pose)[0], beam.log_likelihoods(pose)[0]
    bad = ranges.copy()
    bad[:3] = [np.nan, 0.0, -1.0]
    lf.set_scan(ANGLES, bad, 8.0)
    assert lf.readings == 58
    without = lf.log_likelihoods(pose)[0]
    only = ranges.copy()
    only[3:] = np.nan
    lf.set_scan(ANGLES, only, 8.0)
    assert without == pytest.approx(clean_lf - lf.log_likelihoods(pose)[0], abs=1e-9)
    none = ranges.copy()
    none[5] = np.inf
    beam.set_scan(ANGLES, none, 8.0)
    assert beam.readings == 61
    assert (
        np.isfinite(beam.log_likelihoods(pose)[0]) and beam.log_likelihoods(pose)[0] != clean_beam
    )
    lf.set_scan(ANGLES, none, 8.0)
    assert lf.readings == 60
