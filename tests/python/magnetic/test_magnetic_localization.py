# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic-map MCL (thesis eqs. 6.17-6.18): the likelihood against its closed form, and the
filter against odometry on a field it knows."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kiseki.gp import SquaredExponential
from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.magnetic.localization import (
    MagneticMapModel,
    MagneticMclConfig,
    localize_on_magnetic_map,
)

RES = 0.1


def bumpy_field(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """A field (G) with disturbances every ~1-2 m, as steel in a floor makes."""
    bx = 0.05 * np.sin(2.1 * x) * np.cos(1.7 * y)
    by = 0.04 * np.cos(1.3 * x + 0.5) * np.sin(2.3 * y)
    bz = 0.06 * np.sin(1.1 * x + 1.9 * y) + 0.4
    return np.stack([bx + 0.2, by - 0.05, bz], axis=-1)


@pytest.fixture(scope="module")
def field_map() -> MagneticFieldMap:
    nx, ny = 120, 80
    xs = (np.arange(nx) + 0.5) * RES
    ys = (np.arange(ny) + 0.5) * RES
    gx, gy = np.meshgrid(xs, ys)
    mean = bumpy_field(gx, gy)
    return MagneticFieldMap(
        origin=np.zeros(2),
        resolution=RES,
        mean=mean,
        variance=np.full_like(mean, 1e-5),
        prior_mean=np.array([0.2, -0.05, 0.4]),
        prior_variance=np.full(3, 0.01),
        kernel=SquaredExponential(0.1, 0.5, 0.005),
        units="G",
    )


def body_readings(pose: np.ndarray, offsets: np.ndarray, noise: float, rng) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    world = np.c_[
        pose[0] + c * offsets[:, 0] - s * offsets[:, 1],
        pose[1] + s * offsets[:, 0] + c * offsets[:, 1],
    ]
    b = bumpy_field(world[:, 0], world[:, 1])
    body = np.c_[c * b[:, 0] + s * b[:, 1], -s * b[:, 0] + c * b[:, 1], b[:, 2]]
    return body + rng.normal(0.0, noise, body.shape)


def test_likelihood_is_the_closed_form(field_map):
    offsets = np.array([[0.0, 0.2], [0.0, 0.0], [0.0, -0.2]])
    model = MagneticMapModel(field_map, offsets, noise_sd=0.01)
    pose = np.array([5.0, 4.0, 0.3])
    z = body_readings(pose, offsets, 0.0, np.random.default_rng(0))
    got = model.log_likelihoods(pose[None, :], z)[0]
    # Eq. 6.17 per sensor with the interpolated map (bilinear of a smooth field: close to it),
    # summed over the three sensors (eq. 6.18).
    c, s = math.cos(pose[2]), math.sin(pose[2])
    expected = 0.0
    for o, zi in zip(offsets, z, strict=True):
        p = pose[:2] + [c * o[0] - s * o[1], s * o[0] + c * o[1]]
        mu, var = field_map.value_at(p[None, :])
        zw = np.array([c * zi[0] - s * zi[1], s * zi[0] + c * zi[1], zi[2]])
        sc = var[0] + 0.01**2
        expected += float(np.sum(-0.5 * (zw - mu[0]) ** 2 / sc - 0.5 * np.log(2 * np.pi * sc)))
    assert got == pytest.approx(expected, rel=1e-9)
    # The thesis' sensor frame (y right, z down) is the body frame with y and z negated.
    sensor = MagneticMapModel(field_map, offsets, 0.01, frame="sensor")
    flipped = z * [1.0, -1.0, -1.0]
    assert sensor.log_likelihoods(pose[None, :], flipped)[0] == pytest.approx(got, rel=1e-12)


def test_filter_beats_odometry_and_is_deterministic(field_map):
    rng = np.random.default_rng(3)
    offsets = np.array([[0.0, 0.25], [0.0, 0.0], [0.0, -0.25]])
    # A loop at 0.5 m/s, a reading every 0.1 m; odometry with a 2 % scale error and a heading bias.
    t = np.linspace(0.0, 2 * np.pi, 400)
    truth = np.c_[6.0 + 3.5 * np.cos(t), 4.0 + 2.5 * np.sin(t), t + np.pi / 2]
    step = np.diff(truth[:, :2], axis=0)
    odo = [truth[0].copy()]
    for k, d in enumerate(step):
        heading = odo[-1][2] + (truth[k + 1, 2] - truth[k, 2]) * 1.03
        dist = 1.02 * np.hypot(*d)
        odo.append(
            np.array(
                [
                    odo[-1][0] + dist * math.cos(heading),
                    odo[-1][1] + dist * math.sin(heading),
                    heading,
                ]
            )
        )
    odo = np.array(odo)
    z = np.array([body_readings(p, offsets, 0.005, rng) for p in truth])
    config = MagneticMclConfig(particles=500, noise_sd=0.005, initial_sd=(0.2, 0.2, 0.05))
    run = localize_on_magnetic_map(
        field_map, odo, z, offsets, initial_pose=truth[0], config=config, seed=1
    )
    err = np.hypot(*(run.estimates[:, :2] - truth[:, :2]).T)
    odo_err = np.hypot(*(odo[:, :2] - truth[:, :2]).T)
    assert odo_err[-100:].mean() > 0.5
    assert err.mean() < 0.5 * odo_err.mean()
    assert err.max() < 0.8  # the thesis' position accuracy
    heading_err = np.abs(np.angle(np.exp(1j * (run.estimates[:, 2] - truth[:, 2]))))
    assert heading_err[-100:].mean() < 0.14  # the thesis' heading accuracy
    assert run.resamplings < len(odo)  # ESS < n/2 gates the resampling
    again = localize_on_magnetic_map(
        field_map, odo, z, offsets, initial_pose=truth[0], config=config, seed=1
    )
    np.testing.assert_array_equal(again.estimates, run.estimates)


def test_bad_input_is_refused(field_map):
    offsets = np.array([[0.0, 0.0]])
    with pytest.raises(ValueError, match="frame must be one of"):
        MagneticMapModel(field_map, offsets, 0.01, frame="enu")
    for bad, shown in ((-0.01, "-0.01"), (np.nan, "nan"), (True, "True")):  # True was 1
        with pytest.raises(
            ValueError, match=rf"^noise_sd must be a finite number >= 0, got {shown}$"
        ):
            MagneticMapModel(field_map, offsets, bad)
        if bad is not True:  # the config's field types refuse a bool themselves
            with pytest.raises(
                ValueError,
                match=r"^MagneticMclConfig\.noise_sd must be a finite number >= 0 "
                rf"\(or None: the map's sigma_n\), got {shown}$",
            ):
                MagneticMclConfig(noise_sd=bad)
    model = MagneticMapModel(field_map, offsets, 0.01)
    with pytest.raises(ValueError, match=r"expected shape \(1, 3\)"):
        model.set_readings(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="NaN"):
        model.set_readings([[np.nan, 0, 0]])
    odo = np.zeros((5, 3))
    with pytest.raises(ValueError, match=r"readings: expected shape \(5, 1, 3\)"):
        localize_on_magnetic_map(
            field_map, odo, np.zeros((4, 1, 3)), offsets, initial_pose=[0, 0, 0]
        )
    z = np.zeros((5, 1, 3))
    z[2, 0, 1] = np.inf
    with pytest.raises(ValueError, match="step 2 has NaN"):
        localize_on_magnetic_map(field_map, odo, z, offsets, initial_pose=[0, 0, 0])
    with pytest.raises(ValueError, match="seed"):
        localize_on_magnetic_map(
            field_map, odo, np.zeros((5, 1, 3)), offsets, initial_pose=[0, 0, 0], seed=-1
        )
