# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the magnetometer calibration: sphere and ellipsoid fits recover a known sphere or
ellipsoid (exactly without noise, within the noise's reach with it), degenerate readings are
refused, and eq. 6.16 gives hand-computed values."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.magnetic import (
    EllipsoidCalibration,
    SphereCalibration,
    calibrated_magnitude,
    fit_ellipsoid,
    fit_sphere,
)

CENTRE = np.array([12.0, -30.0, 5.0])  # hard-iron offset, uT
RADIUS = 48.0  # field strength, uT
# the rule of a radius: positive, up to kiseki's bound on every number of its files
POSITIVE = r"a finite number in \(0, 1e\+09\]"
# Symmetric positive-definite soft-iron distortion with off-diagonal terms (a tilted ellipsoid).
SOFT_IRON = np.array([[1.10, 0.05, -0.02], [0.05, 0.90, 0.03], [-0.02, 0.03, 1.00]])


def directions(n: int, seed: int, cap_deg: float = 180.0) -> np.ndarray:
    """n seeded unit vectors, uniform on the sphere or on a cap around +z of half-angle cap."""
    rng = np.random.default_rng(seed)
    cos_min = np.cos(np.radians(cap_deg))
    z = rng.uniform(cos_min, 1.0, n)
    phi = rng.uniform(0.0, 2 * np.pi, n)
    rho = np.sqrt(1 - z * z)
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


@pytest.mark.parametrize("cap_deg", [180.0, 60.0])
def test_sphere_exact_without_noise(cap_deg: float) -> None:
    readings = CENTRE + RADIUS * directions(50, seed=1, cap_deg=cap_deg)
    fit = fit_sphere(readings)
    assert isinstance(fit, SphereCalibration)
    np.testing.assert_allclose(fit.centre, CENTRE, atol=1e-9)
    assert fit.radius == pytest.approx(RADIUS, abs=1e-9)
    assert fit.rms_residual < 1e-9
    assert fit.count == 50
    np.testing.assert_allclose(np.linalg.norm(fit.apply(readings), axis=1), RADIUS, atol=1e-9)


def test_sphere_exact_from_four_points() -> None:
    # Four non-coplanar points determine one sphere: (x-1)^2 + y^2 + z^2 = 4.
    readings = np.array([[3.0, 0, 0], [-1.0, 0, 0], [1.0, 2, 0], [1.0, 0, 2]])
    fit = fit_sphere(readings)
    np.testing.assert_allclose(fit.centre, [1.0, 0.0, 0.0], atol=1e-12)
    assert fit.radius == pytest.approx(2.0, abs=1e-12)


def test_sphere_with_noise_recovered_within_tolerance() -> None:
    rng = np.random.default_rng(7)
    sigma, n = 0.5, 600
    readings = CENTRE + RADIUS * directions(n, seed=2) + rng.normal(0.0, sigma, (n, 3))
    fit = fit_sphere(readings)
    # Standard error of each centre component about sigma * sqrt(3 / n) = 0.035 uT.
    np.testing.assert_allclose(fit.centre, CENTRE, atol=0.15)
    assert fit.radius == pytest.approx(RADIUS, abs=0.1)
    # Radial residual of isotropic noise: SD sigma.
    assert fit.rms_residual == pytest.approx(sigma, rel=0.1)


def test_sphere_geometric_fit_beats_algebraic_on_a_noisy_cap() -> None:
    """On a 50-degree cap the algebraic (Kasa) fit, computed here independently, is biased
    (radius too small); the refined fit has a smaller geometric RMS and a centre several times
    closer to the truth (0.4 against 1.5 uT with these seeds)."""
    rng = np.random.default_rng(3)
    readings = CENTRE + RADIUS * directions(300, seed=4, cap_deg=50.0)
    readings = readings + rng.normal(0.0, 1.0, readings.shape)
    design = np.column_stack([2 * readings, np.ones(len(readings))])
    solution = np.linalg.lstsq(design, np.sum(readings**2, axis=1), rcond=None)[0]
    kasa_centre = solution[:3]
    kasa_radius = np.sqrt(solution[3] + kasa_centre @ kasa_centre)
    kasa_rms = np.sqrt(np.mean((np.linalg.norm(readings - kasa_centre, axis=1) - kasa_radius) ** 2))
    fit = fit_sphere(readings)
    assert fit.rms_residual <= kasa_rms + 1e-12
    kasa_error = np.linalg.norm(kasa_centre - CENTRE)
    assert kasa_error > 1.0
    assert np.linalg.norm(fit.centre - CENTRE) < kasa_error / 2
    assert abs(fit.radius - RADIUS) < abs(kasa_radius - RADIUS) / 2


def test_ellipsoid_exact_without_noise() -> None:
    unit = directions(40, seed=5)
    readings = CENTRE + (RADIUS * unit) @ SOFT_IRON.T
    fit = fit_ellipsoid(readings, radius=RADIUS)
    assert isinstance(fit, EllipsoidCalibration)
    np.testing.assert_allclose(fit.offset, CENTRE, atol=1e-9)
    np.testing.assert_allclose(fit.soft_iron, SOFT_IRON, atol=1e-9)
    np.testing.assert_allclose(fit.correction @ SOFT_IRON, np.eye(3), atol=1e-9)
    np.testing.assert_allclose(fit.apply(readings), RADIUS * unit, atol=1e-9)
    assert fit.rms_residual < 1e-9
    np.testing.assert_allclose(fit.semi_axes, RADIUS * np.linalg.eigvalsh(SOFT_IRON), atol=1e-9)


def test_ellipsoid_default_radius_keeps_the_volume() -> None:
    readings = CENTRE + (RADIUS * directions(40, seed=6)) @ SOFT_IRON.T
    fit = fit_ellipsoid(readings)
    expected = RADIUS * np.linalg.det(SOFT_IRON) ** (1 / 3)
    assert fit.radius == pytest.approx(expected, abs=1e-9)
    np.testing.assert_allclose(np.linalg.norm(fit.apply(readings), axis=1), expected, atol=1e-9)


def test_ellipsoid_with_noise_recovered_within_tolerance() -> None:
    rng = np.random.default_rng(11)
    n, sigma = 800, 0.5
    readings = CENTRE + (RADIUS * directions(n, seed=8)) @ SOFT_IRON.T
    readings = readings + rng.normal(0.0, sigma, (n, 3))
    fit = fit_ellipsoid(readings, radius=RADIUS)
    np.testing.assert_allclose(fit.offset, CENTRE, atol=0.2)
    np.testing.assert_allclose(fit.soft_iron, SOFT_IRON, atol=0.01)
    assert fit.rms_residual == pytest.approx(sigma, rel=0.15)
    # The sphere fit of the same readings is worse: it cannot take out the soft iron.
    assert fit_sphere(readings).rms_residual > 3 * fit.rms_residual


def test_ellipsoid_on_a_sphere_gives_identity() -> None:
    readings = CENTRE + RADIUS * directions(30, seed=9)
    fit = fit_ellipsoid(readings)
    np.testing.assert_allclose(fit.soft_iron, np.eye(3), atol=1e-9)
    assert fit.radius == pytest.approx(RADIUS, abs=1e-9)


def circle(n: int = 40) -> np.ndarray:
    """Readings of a sensor turned about z only: a circle in a plane."""
    angle = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return CENTRE + np.column_stack([RADIUS * np.cos(angle), RADIUS * np.sin(angle), 0 * angle])


@pytest.mark.parametrize("fit", [fit_sphere, fit_ellipsoid])
@pytest.mark.parametrize(
    ("readings", "message"),
    [
        (circle(), "in one plane"),
        (np.tile(CENTRE, (20, 1)), "identical"),
        (CENTRE + np.outer(np.arange(20.0), [1.0, 2.0, 3.0]), "on one line"),
        (np.zeros((20, 2)), r"\(n, 3\)"),
        ([["a", "b", "c"]] * 20, "not numbers"),
    ],
)
def test_degenerate_readings_refused(fit, readings, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        fit(readings)


def test_too_few_readings_refused() -> None:
    readings = CENTRE + RADIUS * directions(8, seed=1)
    with pytest.raises(ValueError, match="at least 4 readings, got 3"):
        fit_sphere(readings[:3])
    with pytest.raises(ValueError, match="at least 9 readings, got 8"):
        fit_ellipsoid(readings)


@pytest.mark.parametrize("fit", [fit_sphere, fit_ellipsoid])
def test_nan_reading_refused_naming_the_row(fit) -> None:
    readings = CENTRE + RADIUS * directions(30, seed=1)
    readings[17, 1] = np.nan
    with pytest.raises(ValueError, match="row 17"):
        fit(readings)


def test_hyperboloid_refused_by_the_ellipsoid_fit() -> None:
    # Points on x^2 + y^2 - z^2 = 1: a quadric, but not an ellipsoid.
    t = np.linspace(-1.0, 1.0, 7)
    angle = np.linspace(0.0, 2 * np.pi, 9, endpoint=False)
    tt, aa = np.meshgrid(t, angle)
    radius = np.sqrt(1 + tt**2)
    readings = np.column_stack(
        [(radius * np.cos(aa)).ravel(), (radius * np.sin(aa)).ravel(), tt.ravel()]
    )
    with pytest.raises(ValueError, match="not lie on an ellipsoid"):
        fit_ellipsoid(readings)


def test_bad_radius_refused() -> None:
    readings = CENTRE + RADIUS * directions(20, seed=1)
    for radius in (0.0, -1.0, np.nan):
        with pytest.raises(ValueError, match=r"^ellipsoid fit: radius must be " + POSITIVE):
            fit_ellipsoid(readings, radius=radius)


def test_eq_6_16_hand_computed() -> None:
    m_ref = np.array([1.0, 2.0, 3.0])
    # m - m_ref = (3, 4, 12): |.| = 13; r_ref 12, r_base 10: 13 - (10 - 12) = 15.
    assert calibrated_magnitude([4.0, 6.0, 15.0], m_ref, 12.0, 10.0) == pytest.approx(15.0)
    readings = np.array([[4.0, 6.0, 15.0], [1.0, 2.0, 8.0], [1.0, 2.0, 3.0]])
    # |m - m_ref| = 13, 5, 0; r_base - r_ref = 0.5 - 0.25 = 0.25.
    np.testing.assert_allclose(
        calibrated_magnitude(readings, m_ref, 0.25, 0.5), [12.75, 4.75, -0.25], atol=1e-15
    )


def test_eq_6_16_through_a_sphere_fit() -> None:
    readings = CENTRE + RADIUS * directions(20, seed=1)
    fit = fit_sphere(readings)
    # Own radius as the base: |m - m_ref| = r_ref on the calibration sphere.
    np.testing.assert_allclose(fit.magnitude(readings), RADIUS, atol=1e-9)
    # As printed, a base radius 2 uT below r_ref gives 2 r_ref - r_base.
    np.testing.assert_allclose(fit.magnitude(readings, r_base=RADIUS - 2), RADIUS + 2, atol=1e-9)


@pytest.mark.parametrize(
    ("m_ref", "r_ref", "r_base", "message"),
    [
        ([1.0, 2.0], 1.0, 1.0, "m_ref must be 3 finite numbers"),
        ([1.0, np.nan, 2.0], 1.0, 1.0, "m_ref must be 3 finite numbers"),
        ([0.0, 0.0, 0.0], 0.0, 1.0, r"^eq. 6.16: r_ref must be " + POSITIVE + ", got 0.0$"),
        ([0.0, 0.0, 0.0], 1.0, np.inf, r"^eq. 6.16: r_base must be " + POSITIVE + ", got inf$"),
    ],
)
def test_eq_6_16_bad_parameters_refused(m_ref, r_ref, r_base, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        calibrated_magnitude(np.ones((2, 3)), m_ref, r_ref, r_base)


def test_results_are_read_only() -> None:
    fit = fit_ellipsoid(CENTRE + RADIUS * directions(20, seed=1))
    with pytest.raises(ValueError, match="read-only"):
        fit.offset[0] = 0.0


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("fit", [fit_sphere, fit_ellipsoid])
@pytest.mark.parametrize("scale", [1e-300, 1e-160, 1e-20])
def test_readings_too_close_together_are_refused_before_the_solver(fit, scale, capfd) -> None:
    """Readings of magnitude 1e-300 had squares of 0: a divide-by-zero warning, LAPACK's
    'On entry to DLASCL parameter number 4 had an illegal value' on stderr, then a LinAlgError;
    at 1e-160 the ellipsoid fit returned a radius of 0 with NaN warnings."""
    with pytest.raises(ValueError, match=r"the readings lie within [0-9.e-]+ of their mean .* too"):
        fit(scale * (CENTRE + RADIUS * directions(30, seed=1)))
    assert capfd.readouterr().err == ""
    # the same sphere in a unit that keeps it apart fits: spread enough is unit-free
    same = fit(1e-6 * (CENTRE + RADIUS * directions(30, seed=1)))
    assert same.radius == pytest.approx(1e-6 * RADIUS, rel=1e-9)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("fit", [fit_sphere, fit_ellipsoid])
def test_readings_that_vary_in_their_last_digits_are_refused(fit) -> None:
    """A spread of 1e-9 on an offset of 1e6 keeps about one of a double's 16 digits: refused,
    with the shares it must reach."""
    readings = 1e6 + 1e-9 * directions(30, seed=1) / np.abs(directions(30, seed=1)).max()
    with pytest.raises(ValueError, match=r"at least 1e-15 and 1e-09 of the largest reading"):
        fit(readings)


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("fit", [fit_sphere, fit_ellipsoid])
def test_readings_beyond_a_billion_are_refused_naming_the_row(fit) -> None:
    """1e200 readings overflowed their squares (warnings) and were said to fit no sphere."""
    readings = CENTRE + RADIUS * directions(30, seed=1)
    readings[5] *= 1e200
    with pytest.raises(ValueError, match=r"1 of 30 readings beyond \+-1e\+09 .* in row 5 "):
        fit(readings)


def test_offsets_and_radii_that_are_no_numbers_are_refused() -> None:
    readings = CENTRE + RADIUS * directions(20, seed=1)
    for radius in ("48", True, 1e300):
        with pytest.raises(ValueError, match="radius must be " + POSITIVE):
            fit_ellipsoid(readings, radius=radius)
    with pytest.raises(ValueError, match=r"m_ref must be 3 finite numbers within \+-1e\+09"):
        calibrated_magnitude(readings, [1e300, 0.0, 0.0], 1.0, 1.0)
    for bad in ("1", True, 1e300):
        with pytest.raises(ValueError, match="r_base must be " + POSITIVE):
            calibrated_magnitude(readings, CENTRE, RADIUS, bad)
    assert calibrated_magnitude(readings[0], CENTRE, np.float32(RADIUS), 48) == pytest.approx(48)
