# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetometer calibration from readings taken while the sensor is turned in place.

A sensor turned in a constant field reads points on a sphere centred on its hard-iron offset
(thesis Fig. 6.2); soft iron and unequal axis gains stretch the sphere into an ellipsoid.

* :func:`fit_sphere`: least-squares sphere, centre ``m_ref`` and radius ``r_ref`` of eq. 6.16. An
  algebraic fit (linear in the centre and r^2 - |c|^2) started, then refined by Gauss-Newton on
  the geometric residuals |m - m_ref| - r_ref.
* :func:`fit_ellipsoid`: algebraic least-squares quadric (the general ellipsoid fit of Li and
  Griffiths, IEEE GMP 2004, with the norm of the coefficients fixed instead of their ellipsoid
  constraint), giving the hard-iron offset and a symmetric correction matrix that maps the readings
  onto a sphere.
* :func:`calibrated_magnitude`: the field strength of eq. 6.16,
  m = sqrt(sum_k (m_k - m_k^ref)^2) - (r^base - r^ref).

Readings are (n, 3) arrays in any one unit; the results are in the same unit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from kiseki._support.real_numbers import check_number
from kiseki._support.schema import MAGNITUDE_LIMIT

__all__ = [
    "EllipsoidCalibration",
    "SphereCalibration",
    "calibrated_magnitude",
    "fit_ellipsoid",
    "fit_sphere",
]

# Readings whose thinnest extent is below this share of their widest lie on a plane (or a line,
# or a point): no sphere or ellipsoid is determined by them.
_FLAT = 1e-6
# Readings (and offsets, radii) beyond MAGNITUDE_LIMIT, kiseki's bound for every number of its
# files, are refused in any unit (1e9 nT is 1 T, beyond any magnetometer's range): their squares
# overflowed with numpy warnings and the fits then said no sphere fitted them.
# Readings that spread less than _MIN_SPREAD about their mean (in any unit: a femtotesla in
# tesla, below any magnetometer's noise), or less than _SPREAD_SHARE of their largest magnitude
# (their differences then keep fewer than 7 of a double's 16 digits), determine no sphere: at
# 1e-300 their squares were 0, LAPACK printed an error line and the fit failed or gave garbage.
_MIN_SPREAD = 1e-15
_SPREAD_SHARE = 1e-9


@dataclass(frozen=True, eq=False)
class SphereCalibration:
    """Hard-iron offset ``centre`` (m_ref of eq. 6.16) and field strength ``radius`` (r_ref);
    ``rms_residual`` is the RMS of |m - m_ref| - r_ref over the ``count`` readings fitted."""

    centre: np.ndarray  # (3,)
    radius: float
    rms_residual: float
    count: int

    def apply(self, readings: np.ndarray) -> np.ndarray:
        """Readings with the hard-iron offset removed: m - m_ref."""
        return _as_readings(readings, 1, "readings") - self.centre

    def magnitude(self, readings: np.ndarray, r_base: float | None = None) -> np.ndarray:
        """Eq. 6.16 with this calibration; ``r_base`` defaults to this sensor's own radius,
        which gives |m - m_ref|."""
        base = self.radius if r_base is None else r_base
        return calibrated_magnitude(readings, self.centre, self.radius, base)


@dataclass(frozen=True, eq=False)
class EllipsoidCalibration:
    """Readings m = offset + soft_iron @ u, with u on a sphere of ``radius``.

    ``offset`` (3,) is the hard-iron offset (the ellipsoid's centre); ``soft_iron`` (3, 3) the
    symmetric positive-definite distortion; ``correction`` its inverse, so that
    ``correction @ (m - offset)`` lies on the sphere. ``rms_residual`` is the RMS of
    |apply(m)| - radius over the ``count`` readings fitted. A rotation of the corrected readings
    is not observable from the readings alone; the symmetric matrix is the one without rotation.
    """

    offset: np.ndarray  # (3,)
    soft_iron: np.ndarray  # (3, 3)
    correction: np.ndarray  # (3, 3)
    radius: float
    rms_residual: float
    count: int

    @property
    def semi_axes(self) -> np.ndarray:
        """(3,) the fitted ellipsoid's semi-axes, ascending."""
        return np.sort(self.radius * np.linalg.eigvalsh(self.soft_iron))

    def apply(self, readings: np.ndarray) -> np.ndarray:
        """Corrected readings: correction @ (m - offset), on the sphere of ``radius``."""
        return (_as_readings(readings, 1, "readings") - self.offset) @ self.correction.T


def fit_sphere(readings: np.ndarray) -> SphereCalibration:
    """Least-squares sphere through readings taken while turning the sensor (at least 4, not
    all in one plane)."""
    m = _as_readings(readings, 4, "sphere fit")
    _check_spread(m, "sphere fit")
    mean = m.mean(axis=0)
    scale = np.sqrt(np.mean(np.sum((m - mean) ** 2, axis=1)))
    u = (m - mean) / scale
    # Algebraic start: |u|^2 = 2 c.u + (r^2 - |c|^2), linear in c and d = r^2 - |c|^2.
    design = np.column_stack([2.0 * u, np.ones(len(u))])
    solution, *_ = np.linalg.lstsq(design, np.sum(u * u, axis=1), rcond=None)
    centre, d = solution[:3], solution[3]
    radius_sq = d + centre @ centre
    if not radius_sq > 0:
        raise ValueError("sphere fit: the readings do not determine a sphere (r^2 <= 0)")
    start = np.append(centre, np.sqrt(radius_sq))

    def residuals(p: np.ndarray) -> np.ndarray:
        return np.linalg.norm(u - p[:3], axis=1) - p[3]

    def jacobian(p: np.ndarray) -> np.ndarray:
        diff = u - p[:3]
        dist = np.maximum(np.linalg.norm(diff, axis=1), 1e-300)
        return np.column_stack([-diff / dist[:, None], -np.ones(len(u))])

    refined = least_squares(residuals, start, jac=jacobian, method="lm", xtol=1e-15, ftol=1e-15)
    p = refined.x if refined.success and np.all(np.isfinite(refined.x)) else start
    centre_m = mean + scale * p[:3]
    radius = float(abs(p[3]) * scale)
    rms = float(np.sqrt(np.mean((np.linalg.norm(m - centre_m, axis=1) - radius) ** 2)))
    return SphereCalibration(_frozen(centre_m), radius, rms, len(m))


def fit_ellipsoid(readings: np.ndarray, radius: float | None = None) -> EllipsoidCalibration:
    """Least-squares ellipsoid through readings taken while turning the sensor (at least 9, not
    all in one plane). ``radius``: the field strength the corrected readings get; by default the
    geometric mean of the semi-axes (the ellipsoid's volume is kept)."""
    m = _as_readings(readings, 9, "ellipsoid fit")
    _check_spread(m, "ellipsoid fit")
    if radius is not None:
        check_number(radius, "ellipsoid fit: radius", 0.0, MAGNITUDE_LIMIT, low_open=True)
    mean = m.mean(axis=0)
    scale = np.sqrt(np.mean(np.sum((m - mean) ** 2, axis=1)))
    x, y, z = ((m - mean) / scale).T
    # Quadric a x^2 + b y^2 + c z^2 + 2 d xy + 2 e xz + 2 f yz + 2 g x + 2 h y + 2 i z + j = 0,
    # the coefficient vector of unit norm minimising the algebraic residuals.
    design = np.column_stack(
        [x * x, y * y, z * z, 2 * x * y, 2 * x * z, 2 * y * z, 2 * x, 2 * y, 2 * z, np.ones_like(x)]
    )
    _, singular, vt = np.linalg.svd(design, full_matrices=False)
    if singular[-2] <= 1e-9 * singular[0]:
        raise ValueError(
            "ellipsoid fit: the readings do not determine an ellipsoid (several quadrics fit "
            "them): turn the sensor through more orientations"
        )
    a, b, c, d, e, f, g, h, i, j = vt[-1]
    quadratic = np.array([[a, d, e], [d, b, f], [e, f, c]])
    try:
        centre_u = -np.linalg.solve(quadratic, np.array([g, h, i]))
    except np.linalg.LinAlgError:
        raise ValueError("ellipsoid fit: the fitted quadric has no centre (a cylinder)") from None
    level = centre_u @ quadratic @ centre_u - j
    shape = quadratic / level if level != 0 else quadratic * np.inf
    eigenvalues, vectors = np.linalg.eigh(shape)
    if not np.all(np.isfinite(eigenvalues)) or eigenvalues[0] <= 0:
        raise ValueError(
            "ellipsoid fit: the readings do not lie on an ellipsoid (the fitted quadric is a "
            "hyperboloid): turn the sensor through more orientations"
        )
    semi_axes = scale / np.sqrt(eigenvalues)  # in the readings' units
    target = float(np.prod(semi_axes) ** (1.0 / 3.0)) if radius is None else float(radius)
    correction = vectors @ np.diag(target / semi_axes) @ vectors.T
    soft_iron = vectors @ np.diag(semi_axes / target) @ vectors.T
    offset = mean + scale * centre_u
    corrected = (m - offset) @ correction.T
    rms = float(np.sqrt(np.mean((np.linalg.norm(corrected, axis=1) - target) ** 2)))
    return EllipsoidCalibration(
        _frozen(offset), _frozen(soft_iron), _frozen(correction), target, rms, len(m)
    )


def calibrated_magnitude(
    readings: np.ndarray, m_ref: np.ndarray, r_ref: float, r_base: float
) -> np.ndarray:
    """Field strength of eq. 6.16, as printed: m = |m - m_ref| - (r_base - r_ref).

    ``m_ref`` (3,) and ``r_ref``: this sensor's sphere fit; ``r_base``: the radius of the sensor
    taken as the reference. Returns (n,) for (n, 3) readings, a float for one (3,) reading.

    Note on the sign: with the formula as printed, a reading on this sensor's own calibration
    sphere (|m - m_ref| = r_ref) gives 2 r_ref - r_base, moving it away from the reference
    sensor's r_base; bringing every sensor onto the reference's scale would take
    + (r_base - r_ref). Both agree when r_base = r_ref (a sensor used alone).
    """
    single = np.ndim(readings) == 1
    m = _as_readings(np.atleast_2d(readings) if single else readings, 1, "eq. 6.16 readings")
    centre = np.asarray(m_ref, dtype=np.float64)
    if centre.shape != (3,) or not np.all(np.abs(centre) <= MAGNITUDE_LIMIT):
        raise ValueError(
            f"eq. 6.16: m_ref must be 3 finite numbers within +-{MAGNITUDE_LIMIT:g}, got {m_ref!r}"
        )
    for name, value in (("r_ref", r_ref), ("r_base", r_base)):
        check_number(value, f"eq. 6.16: {name}", 0.0, MAGNITUDE_LIMIT, low_open=True)
    magnitude = np.linalg.norm(m - centre, axis=1) - (r_base - r_ref)
    return float(magnitude[0]) if single else magnitude


def _as_readings(readings: np.ndarray, minimum: int, what: str) -> np.ndarray:
    try:
        m = np.asarray(readings, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what}: readings are not numbers ({exc})") from exc
    if m.ndim != 2 or m.shape[1] != 3:
        raise ValueError(f"{what}: readings must be (n, 3), got shape {m.shape}")
    if len(m) < minimum:
        raise ValueError(f"{what}: needs at least {minimum} readings, got {len(m)}")
    bad = ~np.isfinite(m).all(axis=1)
    if bad.any():
        row = int(np.argmax(bad))
        raise ValueError(
            f"{what}: {int(bad.sum())} of {len(m)} readings NaN or infinite, the first in row "
            f"{row} (counting from 0): {m[row].tolist()}"
        )
    beyond = (np.abs(m) > MAGNITUDE_LIMIT).any(axis=1)
    if beyond.any():
        row = int(np.argmax(beyond))
        raise ValueError(
            f"{what}: {int(beyond.sum())} of {len(m)} readings beyond +-{MAGNITUDE_LIMIT:g} (in "
            f"any unit), the first in row {row} (counting from 0): {m[row].tolist()}"
        )
    return m


def _check_spread(m: np.ndarray, what: str) -> None:
    """Readings that determine a sphere or an ellipsoid, checked before any solver sees them:
    not identical, spread enough (see _MIN_SPREAD), not on a line or in a plane."""
    deviations = m - m.mean(axis=0)
    spread, largest = float(np.abs(deviations).max()), float(np.abs(m).max())
    if spread == 0:
        raise ValueError(f"{what}: all {len(m)} readings are identical")
    if spread < max(_MIN_SPREAD, _SPREAD_SHARE * largest):
        raise ValueError(
            f"{what}: the readings lie within {spread:.3g} of their mean (the largest is "
            f"{largest:.3g}): too close together to fit; in any unit they must spread at least "
            f"{_MIN_SPREAD:g} and {_SPREAD_SHARE:g} of the largest reading"
        )
    singular = np.linalg.svd(deviations, compute_uv=False)
    if singular[-1] <= _FLAT * singular[0]:
        shape = "on one line" if singular[1] <= _FLAT * singular[0] else "in one plane"
        raise ValueError(
            f"{what}: the readings lie {shape}: no sphere or ellipsoid is determined; turn the "
            "sensor about more than one axis"
        )


def _frozen(array: np.ndarray) -> np.ndarray:
    array = np.array(array, dtype=np.float64)
    array.setflags(write=False)
    return array
