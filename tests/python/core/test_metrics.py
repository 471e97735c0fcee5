# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""APE, RPE and alignment agree with evo (the reference implementation of the definitions)."""

from __future__ import annotations

import numpy as np
import pytest
from evo.core import metrics as evo_metrics
from evo.core.trajectory import PoseTrajectory3D

from kiseki.metrics import align_trajectory, ape, as_se3, rpe, stop_error, umeyama_alignment

EVO_RELATION = {
    "translation": evo_metrics.PoseRelation.translation_part,
    "rotation_deg": evo_metrics.PoseRelation.rotation_angle_deg,
    "full": evo_metrics.PoseRelation.full_transformation,
}


def trajectories(seed: int, n: int = 200):
    """A wandering planar reference and an estimate with drift, noise and a frame offset."""
    rng = np.random.default_rng(seed)
    theta = np.cumsum(rng.normal(0, 0.05, n))
    step = rng.uniform(0.05, 0.15, n)
    ref = np.column_stack([np.cumsum(step * np.cos(theta)), np.cumsum(step * np.sin(theta)), theta])
    est = (
        ref
        + rng.normal(0, [0.05, 0.05, 0.02], (n, 3))
        + np.linspace(0, 1, n)[:, None]
        * [
            0.3,
            -0.2,
            0.05,
        ]
    )
    c, s = np.cos(0.4), np.sin(0.4)
    moved = est.copy()
    moved[:, 0], moved[:, 1] = c * est[:, 0] - s * est[:, 1] + 2.0, s * est[:, 0] + c * est[:, 1]
    moved[:, 2] += 0.4
    return moved, ref


def evo_traj(poses: np.ndarray) -> PoseTrajectory3D:
    return PoseTrajectory3D(poses_se3=list(as_se3(poses)), timestamps=np.arange(len(poses)) * 0.1)


@pytest.mark.parametrize("relation", ["translation", "rotation_deg", "full"])
@pytest.mark.parametrize("alignment", ["none", "se3", "sim3", "origin"])
def test_ape_matches_evo(relation, alignment):
    est, ref = trajectories(1)
    e, r = evo_traj(est), evo_traj(ref)
    if alignment in ("se3", "sim3"):
        e.align(r, correct_scale=alignment == "sim3")
    elif alignment == "origin":
        e.align_origin(r)
    metric = evo_metrics.APE(EVO_RELATION[relation])
    metric.process_data((r, e))
    ours = ape(est, ref, relation, alignment)
    np.testing.assert_allclose(ours.errors, metric.error, rtol=1e-9, atol=1e-9)
    stats = metric.get_all_statistics()
    for key in ("rmse", "mean", "median", "std", "min", "max", "sse"):
        assert getattr(ours, key) == pytest.approx(stats[key], rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("relation", ["translation", "rotation_deg"])
@pytest.mark.parametrize(("delta", "all_pairs"), [(1, False), (7, False), (7, True)])
def test_rpe_matches_evo(relation, delta, all_pairs):
    est, ref = trajectories(2)
    metric = evo_metrics.RPE(
        EVO_RELATION[relation],
        delta=delta,
        delta_unit=evo_metrics.Unit.frames,
        all_pairs=all_pairs,
    )
    metric.process_data((evo_traj(ref), evo_traj(est)))
    ours = rpe(est, ref, delta, relation, all_pairs)
    np.testing.assert_allclose(ours.errors, metric.error, rtol=1e-9, atol=1e-9)


def test_alignment_recovers_a_known_similarity():
    rng = np.random.default_rng(3)
    src = rng.normal(size=(50, 3))
    angle = 0.7
    c, s = np.cos(angle), np.sin(angle)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    dst = 2.5 * src @ rot.T + [1.0, -2.0, 0.5]
    r, t, s = umeyama_alignment(src, dst, with_scale=True)
    np.testing.assert_allclose(r, rot, atol=1e-12)
    np.testing.assert_allclose(t, [1.0, -2.0, 0.5], atol=1e-12)
    assert s == pytest.approx(2.5)
    # without noise, a rigidly moved reference is moved back exactly (closed form)
    _, ref = trajectories(4)
    c, s = np.cos(0.4), np.sin(0.4)
    moved = np.column_stack(
        [c * ref[:, 0] - s * ref[:, 1] + 2.0, s * ref[:, 0] + c * ref[:, 1] - 1.0, ref[:, 2] + 0.4]
    )
    np.testing.assert_allclose(align_trajectory(moved, ref, "se3"), as_se3(ref), atol=1e-9)
    # with noise and drift, every alignment gives evo's aligned poses
    est, ref = trajectories(4)
    for alignment in ("se3", "sim3", "scale", "origin"):
        e = evo_traj(est)
        if alignment == "origin":
            e.align_origin(evo_traj(ref))
        else:
            e.align(evo_traj(ref), alignment == "sim3", alignment == "scale")
        ours = align_trajectory(est, ref, alignment)
        np.testing.assert_allclose(ours, np.stack(e.poses_se3), atol=1e-9, err_msg=alignment)
    # a heading off by 0.1 rad everywhere is a 5.73 deg rotation error at every pose
    turned = ref + [0.0, 0.0, 0.1]
    np.testing.assert_allclose(ape(turned, ref, "rotation_deg").errors, np.degrees(0.1))


def test_stop_error_in_goal_frame():
    err = stop_error([13.05, 0.02, 0.01], [13.0, 0.0, 0.0])
    assert (err.along, err.across) == pytest.approx((0.05, 0.02))
    assert err.within(0.1) and not err.within(0.05)
    err = stop_error([0.0, 1.1, 0.0], [0.0, 1.0, np.pi / 2])  # goal facing +y: 0.1 m overshoot
    assert err.along == pytest.approx(0.1) and err.across == pytest.approx(0.0, abs=1e-12)
    assert err.heading_deg == pytest.approx(-90.0)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: ape(np.zeros((3, 3)), np.zeros((4, 3))), "associate"),
        (lambda: ape(np.zeros((3, 2)), np.zeros((3, 2))), "shape"),
        (lambda: ape(np.full((3, 3), np.nan), np.zeros((3, 3))), "NaN"),
        (lambda: ape(np.zeros((3, 3)), np.zeros((3, 3)), "speed"), "relation"),
        (lambda: ape(np.zeros((3, 3)), np.zeros((3, 3)), alignment="affine"), "alignment"),
        (lambda: rpe(np.zeros((3, 3)), np.zeros((3, 3)), delta=0), "delta"),
        (lambda: rpe(np.zeros((3, 3)), np.zeros((3, 3)), delta=5), "no pose pairs"),
        (lambda: stop_error([0, 0], [0, 0, 0]), "triples"),
        # each found by an audit: a number where there was none, or an internal error
        (lambda: ape(np.ones((3, 4, 4)), np.ones((3, 4, 4)), "rotation_deg"), "not a rigid"),
        (lambda: rpe(np.zeros((3, 3)), np.zeros((3, 3)), delta=1.5), "delta must be an integer"),
        (lambda: umeyama_alignment([[0, 0], [1, 1]], [[0, 0]]), "same shape"),
        (lambda: umeyama_alignment([[0, 0], [np.nan, 1]], [[0, 0], [1, 1]]), "finite"),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_wilson_interval_against_its_closed_form_values():
    from kiseki.metrics import wilson_interval

    # Wilson (1927) at z = 1.96: 5 of 20 -> (0.1119, 0.4687); 0 of 20 -> (0, 0.1611)
    lo, hi = wilson_interval(5, 20)
    assert lo == pytest.approx(0.11186, abs=1e-5) and hi == pytest.approx(0.46871, abs=1e-5)
    lo, hi = wilson_interval(0, 20)
    assert lo == 0.0 and hi == pytest.approx(0.16113, abs=1e-5)
    assert all(np.isnan(v) for v in wilson_interval(0, 0))
    # 5 of 3 was "math domain error"; n = -3 gave (7.0, -0.06)
    for k, n in ((5, 3), (1, -3), (True, 3), (1.5, 3)):
        with pytest.raises(ValueError, match="wilson_interval"):
            wilson_interval(k, n)
    for z in (0.0, np.nan, np.inf, True):  # True was taken as z = 1
        with pytest.raises(
            ValueError, match="^wilson_interval: z must be a finite number > 0, got "
        ):
            wilson_interval(5, 20, z)


def test_poses_written_with_four_decimals_are_rigid_enough():
    """The rigid-motion check takes rotations rounded to 4 decimals (or chained in float32)."""
    c, s = np.cos(0.3), np.sin(0.3)
    poses = np.tile(np.eye(4), (5, 1, 1))
    poses[:, :2, :2] = [[c, -s], [s, c]]
    poses[:, 0, 3] = np.arange(5.0)
    rounded = np.round(poses, 4)
    assert ape(rounded, rounded, "rotation_deg").max == 0.0
    assert ape(rounded, poses).max < 1e-4


def test_area_under_roc_against_counting_and_its_labels_checked():
    from kiseki.metrics import area_under_roc

    score, positive = np.array([0.1, 0.4, 0.35, 0.8]), np.array([False, False, True, True])
    pairs = [(p, q) for p in score[positive] for q in score[~positive]]
    want = np.mean([1.0 if p > q else 0.5 if p == q else 0.0 for p, q in pairs])
    assert area_under_roc(score, positive) == want == 0.75
    assert area_under_roc(score, positive.astype(int)) == want
    with pytest.raises(ValueError, match="labels must be booleans"):  # both read as True
        area_under_roc([0.1, 0.9], ["no", "yes"])


@pytest.mark.parametrize(
    "call",
    [
        lambda ref: ape(np.zeros((3, 3)), ref, alignment="sim3"),
        lambda ref: ape(np.zeros((3, 3)), ref, alignment="scale"),
        lambda ref: align_trajectory(np.zeros((3, 3)), ref, "scale"),
        lambda ref: umeyama_alignment(np.zeros((3, 2)), ref[:, :2], with_scale=True),
        # a spread of 1e-200 m squares to 0: the scale was inf
        lambda ref: umeyama_alignment([[0, 0], [1e-200, 0], [0, 0]], ref[:, :2], with_scale=True),
    ],
    ids=["ape-sim3", "ape-scale", "align-scale", "umeyama", "umeyama-underflow"],
)
def test_a_scale_from_an_estimate_standing_still_is_refused(call):
    """All statistics were NaN: the scale divided by the estimate's zero spread."""
    ref = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    with pytest.raises(ValueError) as caught:
        call(ref)
    assert str(caught.value) == (
        "the estimate's positions (src) are all the same: no scale can be estimated"
    )
    # without scale the same estimate aligns: onto the reference's centroid
    assert ape(np.zeros((3, 3)), ref, alignment="se3").max == pytest.approx(1.0)


def test_wilson_interval_refuses_counts_no_float_holds_exactly():
    """n = 10**400 raised OverflowError (z * z / (2 n)); 2**53 is the largest count taken."""
    from kiseki.metrics import wilson_interval

    for k, n in ((1, 10**400), (1, 2**53 + 1), (2**53 + 1, 2**53 + 1)):
        with pytest.raises(ValueError) as caught:
            wilson_interval(k, n)
        assert str(caught.value) == (
            f"wilson_interval: need counts 0 <= k <= n <= 2**53, got {k}, {n}"
        )
    lo, hi = wilson_interval(2**52, 2**53)  # a half: 0.5 +- 1.96 / (2 sqrt(n))
    assert (lo + hi) / 2 == pytest.approx(0.5, abs=1e-15)
    assert hi - lo == pytest.approx(1.96 / 2**26.5, rel=1e-6)


@pytest.mark.parametrize("big", [1e155, 1e200, 1e300])
def test_errors_whose_squares_overflow_stay_finite(big):
    """An estimate 1e200 m off gave an error of inf (np.linalg.norm squares it), an RMSE of
    inf and a NaN SD; the errors are finite and have finite statistics (closed forms below:
    errors big and 0, and big sqrt(2) for a diagonal offset). sse overflows, as documented."""
    est = np.array([[big, 0.0, 0.0], [0.0, 0.0, 0.0]])
    stats = ape(est, np.zeros((2, 3)))
    assert stats.max == big and stats.min == 0.0 and stats.mean == big / 2
    assert stats.rmse == pytest.approx(big / np.sqrt(2), rel=1e-15)
    assert stats.std == pytest.approx(big / 2, rel=1e-15)
    diagonal = ape(np.array([[big, big, 0.0]]), np.zeros((1, 3)))
    assert diagonal.max == pytest.approx(big * np.sqrt(2), rel=1e-15)
    assert ape(est, np.zeros((2, 3)), relation="full").max == pytest.approx(big, rel=1e-15)
    assert rpe(est, np.zeros((2, 3))).rmse == pytest.approx(big, rel=1e-15)
    if big > 1e160:
        assert stats.sse == np.inf


def test_ordinary_errors_are_the_plain_formulas_bit_for_bit():
    """The overflow path is taken only where the plain formulas overflow: the statistics of
    ordinary errors are numpy's own, so no reported RMSE moves in its last digit."""
    ref, est = trajectories(3)
    stats = ape(est, ref)
    e = np.linalg.norm(est[:, :2] - ref[:, :2], axis=1)
    assert np.array_equal(stats.errors, e)
    assert stats.rmse == float(np.sqrt(np.mean(e**2))) and stats.std == float(e.std())
    full = ape(est, ref, relation="full")
    rel = np.linalg.inv(as_se3(ref)) @ as_se3(est)
    np.testing.assert_allclose(full.errors, np.linalg.norm(rel - np.eye(4), axis=(1, 2)))
    step = rpe(est, ref)  # the plain path's own arrays, through the same code as before
    assert step.rmse == float(np.sqrt(np.mean(step.errors**2)))


def test_a_length_past_the_largest_double_is_inf_without_a_warning():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the rescaled path warned 'overflow in multiply'
        stats = ape(np.array([[1.5e308, 1.5e308, 0.0]]), np.zeros((1, 3)))  # 2.1e308
    assert stats.max == np.inf
