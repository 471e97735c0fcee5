# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Cooperative positioning: triangulation against the paper's closed forms (eqs. 1-4), against
Monte Carlo on random geometry, in 3-D against 2-D, and its refusals of bad geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.coop import paper_error, paper_position, triangulate

SIGMA = math.radians(0.1)  # the paper's bearing noise


@pytest.mark.parametrize("theta1", [0.35, 0.785, 1.1])
@pytest.mark.parametrize("theta2", [0.5, 0.785, 1.3])
def test_symmetric_case_matches_equations_1_to_4(theta1: float, theta2: float) -> None:
    d = 1.5
    standing = [[-d, 0.0], [d, 0.0]]
    bearings = [theta1, math.pi - theta2]  # robot 1 sees theta1 from +x, robot 2 from -x
    position, covariance = triangulate(standing, bearings, bearing_sigma=SIGMA)
    np.testing.assert_allclose(position, paper_position(d, theta1, theta2), atol=1e-12)
    jac = np.column_stack(
        [paper_error(d, theta1, theta2, 1.0, 0.0), paper_error(d, theta1, theta2, 0.0, 1.0)]
    )
    np.testing.assert_allclose(covariance, SIGMA**2 * jac @ jac.T, rtol=1e-9, atol=1e-18)


def test_equation_3_as_printed_contradicts_equation_1() -> None:
    d, t1, t2, h = 1.0, 0.6, 1.0, 1e-7
    numeric = (paper_position(d, t1 + h, t2) - paper_position(d, t1 - h, t2)) / (2 * h)
    np.testing.assert_allclose(paper_error(d, t1, t2, 1.0, 0.0), numeric, rtol=1e-6)
    s2 = math.sin(t1 + t2) ** 2
    printed_dx = d * math.sin(2 * t2) / s2  # eq. 3 as printed, dth1 = 1, dth2 = 0
    assert printed_dx == pytest.approx(-numeric[0], rel=1e-6)  # the sign is the misprint
    # sec. 3.2: opposite errors make the cross-track error (x), equal ones none on the centre line
    assert abs(paper_error(d, 0.8, 0.8, 1.0, -1.0)[0]) > 1.0
    assert paper_error(d, 0.8, 0.8, 1.0, 1.0)[0] == pytest.approx(0.0, abs=1e-12)


def _bearings(standing: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = target - standing
    return np.arctan2(d[:, 1], d[:, 0]), np.arctan2(d[:, 2], np.hypot(d[:, 0], d[:, 1]))


def test_covariance_matches_monte_carlo_in_3d() -> None:
    rng = np.random.default_rng(5)
    standing = np.array([[0.0, 0.0, 0.0], [4.0, 0.5, 0.4], [1.0, 5.0, -0.3]])
    target = np.array([2.5, 2.0, 1.0])
    bearings, elevations = _bearings(standing, target)
    sigma = math.radians(0.5)
    position, covariance = triangulate(
        standing, bearings, elevations, bearing_sigma=sigma, elevation_sigma=2 * sigma
    )
    np.testing.assert_allclose(position, target, atol=1e-9)
    samples = np.array(
        [
            triangulate(
                standing,
                bearings + rng.normal(0, sigma, 3),
                elevations + rng.normal(0, 2 * sigma, 3),
                bearing_sigma=sigma,
                elevation_sigma=2 * sigma,
            )[0]
            for _ in range(4000)
        ]
    )
    sample_cov = np.cov(samples.T)
    assert np.linalg.norm(sample_cov - covariance) < 0.08 * np.linalg.norm(covariance)


def test_three_d_on_a_plane_is_two_d() -> None:
    standing = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]])
    target = np.array([1.0, 1.5])
    b = np.arctan2(target[1] - standing[:, 1], target[0] - standing[:, 0])
    p2, c2 = triangulate(standing, b + [0.001, -0.002, 0.0015], bearing_sigma=SIGMA)
    flat = np.column_stack([standing, np.zeros(3)])
    p3, c3 = triangulate(flat, b + [0.001, -0.002, 0.0015], np.zeros(3), bearing_sigma=SIGMA)
    np.testing.assert_allclose(p3[:2], p2, atol=1e-12)
    np.testing.assert_allclose(c3[:2, :2], c2, rtol=1e-9)
    assert p3[2] == pytest.approx(0.0, abs=1e-12)
    assert triangulate(standing, b).shape == (2,)


@pytest.mark.parametrize(
    ("standing", "bearings", "message"),
    [
        ([[0.0, 0.0]], [0.3], "at least two standing robots"),
        ([[1.0, 2.0], [1.0, 2.0]], [0.3, 1.2], "coincide"),
        ([[0.0, 0.0], [1.0, 0.0]], [0.3, float("nan")], "bearing 1 is not finite"),
        ([[0.0, 0.0], [1.0, 0.0]], [0.3], "2 standing robots but 1 bearings"),
        ([[-1.0, 0.0], [1.0, 0.0]], [math.pi / 2, math.pi / 2 + 0.005], "nearly parallel"),
        ([[-1.0, 0.0], [1.0, 0.0]], [0.0, math.pi], "nearly parallel"),  # on the baseline
        ([[1.0, 0.0], [-1.0, 0.0]], [-math.pi / 4, -3 * math.pi / 4], "points away"),
        ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [0.3, 1.0], "shape (n, 2)"),
        ([["a", "b"], ["c", "d"]], [0.3, 1.0], "standing"),
    ],
)
def test_bad_geometry_and_input_are_named(standing, bearings, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        triangulate(standing, bearings)


def test_bad_sigma_and_paper_angles() -> None:
    with pytest.raises(ValueError, match="bearing_sigma"):
        triangulate([[-1.0, 0.0], [1.0, 0.0]], [0.8, 2.3], bearing_sigma=-1.0)
    # an SD of 1e300 rad gave a NaN and infinite covariance
    with pytest.raises(
        ValueError,
        match=r"bearing_sigma must be a finite number in \[0, pi\] rad, got 1e\+300",
    ):
        triangulate([[-1.0, 0.0], [1.0, 0.0]], [0.8, 2.3], bearing_sigma=1e300)
    with pytest.raises(ValueError, match=r"elevation_sigma must be a finite number in \[0, pi\]"):
        triangulate([[-1.0, 0.0], [1.0, 0.0]], [0.8, 2.3], bearing_sigma=0.01, elevation_sigma=9)
    # True was an SD of 1 rad
    with pytest.raises(ValueError, match=r"bearing_sigma must be a finite number .* got True$"):
        triangulate([[-1.0, 0.0], [1.0, 0.0]], [0.8, 2.3], bearing_sigma=True)
    with pytest.raises(ValueError, match="elevation 0"):
        triangulate([[0.0, 0, 0], [1.0, 0, 0]], [0.5, 2.0], [math.pi / 2, 0.0])
    with pytest.raises(ValueError, match="interior angles"):
        paper_position(1.0, 2.0, 1.5)
    with pytest.raises(ValueError, match="nearly parallel"):
        paper_position(1.0, 1e-4, 1e-4)


@pytest.mark.parametrize("d", [math.nan, math.inf, -1.0, 0.0, "1.0", True])
def test_paper_forms_refuse_a_half_baseline_d_that_is_not_a_positive_distance(d) -> None:
    """paper_position(nan, ...) gave (nan, nan); d = -1 was taken (robots 1 and 2 swapped)."""
    message = f"d (robots 1 and 2 at -d and d) must be a finite number > 0 m, got {d!r}"
    with pytest.raises(ValueError) as caught:
        paper_position(d, 0.5, 0.6)
    assert str(caught.value) == message
    with pytest.raises(ValueError) as caught:
        paper_error(d, 0.5, 0.6, 0.001, 0.0)
    assert str(caught.value) == message


@pytest.mark.parametrize(("dtheta1", "dtheta2"), [(math.nan, 0.0), (0.0, -math.inf), ("0", 0)])
def test_paper_error_refuses_angle_errors_that_are_not_finite(dtheta1, dtheta2) -> None:
    """paper_error(1, 0.5, 0.6, nan, 0) gave (nan, nan)."""
    with pytest.raises(ValueError) as caught:
        paper_error(1.0, 0.5, 0.6, dtheta1, dtheta2)
    name, bad = ("dtheta2", dtheta2) if dtheta1 == 0.0 else ("dtheta1", dtheta1)
    assert str(caught.value) == f"{name} must be a finite number (rad), got {bad!r}"
    # zero and negative errors, and any d > 0, stay: eq. 4's dy is linear in both
    dy = paper_error(1e-3, 0.5, 0.6, -0.002, 0.0)[1]
    assert dy == pytest.approx(2e-3 * math.sin(0.6) ** 2 * -0.002 / math.sin(1.1) ** 2, rel=1e-12)
    assert paper_error(1.0, 0.5, 0.6, 0, 0).tolist() == [0.0, 0.0]


def test_an_elevation_sigma_without_a_bearing_sigma_is_refused() -> None:
    """It was ignored without a word: the position came back, without a covariance."""
    standing, bearings, elevations = [[0.0, 0, 0], [1.0, 0, 0]], [1.0, 2.0], [0.1, 0.1]
    with pytest.raises(ValueError) as caught:
        triangulate(standing, bearings, elevations, None, 0.1)
    assert str(caught.value) == (
        "elevation_sigma (0.1) needs bearing_sigma, which is None: the covariance is returned "
        "only with bearing_sigma"
    )
    # with bearing_sigma it gives the covariance too; without either sigma the position alone
    standing = np.array(standing)
    bearings, elevations = _bearings(standing, np.array([0.5, 1.0, 0.2]))
    position, covariance = triangulate(standing, bearings, elevations, 0.01, 0.1)
    assert covariance.shape == (3, 3) and np.all(np.linalg.eigvalsh(covariance) > 0)
    np.testing.assert_allclose(position, [0.5, 1.0, 0.2], atol=1e-12)
    np.testing.assert_allclose(triangulate(standing, bearings, elevations), position, atol=1e-12)


@pytest.mark.parametrize("far", [1e9, -1e11])
def test_robots_far_from_the_origin_do_not_coincide_by_the_tolerance(far) -> None:
    """Robots 1 m apart 1e9 m from the origin "coincided": the solver's tolerance for that,
    1e-9 (1 + |position|), grew with the coordinates; it now works relative to robot 0."""
    near = triangulate([[0.0, 0.0], [1.0, 0.0]], [1.0, 2.0])
    found = triangulate([[far, far], [far + 1, far]], [1.0, 2.0])
    np.testing.assert_allclose(found - far, near, atol=1e-4)  # a float holds 1e11 to 1.5e-5
    near = triangulate([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [1.0, 2.0], [0.1, 0.1])
    found = triangulate([[far, far, 5.0], [far + 1, far, 5.0]], [1.0, 2.0], [0.1, 0.1])
    np.testing.assert_allclose(found - [far, far, 5.0], near, atol=1e-4)
    with pytest.raises(ValueError, match="standing robots 0 and 1 coincide"):
        triangulate([[far, far], [far, far]], [1.0, 2.0])  # one spot still is one


@pytest.mark.parametrize(
    ("theta1", "theta2", "name"), [(True, 0.6, "theta1"), (0.5, math.nan, "theta2")]
)
def test_paper_forms_refuse_angles_that_are_no_finite_number(theta1, theta2, name) -> None:
    """True was an angle of 1 rad."""
    bad = theta1 if name == "theta1" else theta2
    with pytest.raises(ValueError) as caught:
        paper_position(1.0, theta1, theta2)
    assert str(caught.value) == f"{name} must be a finite number (rad), got {bad!r}"
