# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Magnetic MCL with two magnetometers on their own maps: the summed likelihood against the two
single-sensor models, the drift check dropping a sensor whose z drifts (and saying when), and
keeping both when neither drifts."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.gp import SquaredExponential
from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.magnetic.localization import MagneticMclConfig, localize_on_magnetic_map
from kiseki.magnetic.multi_sensor import DriftCheck, localize_with_magnetometers

RES = 0.1


def bumpy_field(x: np.ndarray, y: np.ndarray, bias=(0.0, 0.0, 0.0)) -> np.ndarray:
    """G, world frame: disturbances every 1-2 m; ``bias`` a sensor's own calibration offset."""
    bx = 0.05 * np.sin(2.1 * x) * np.cos(1.7 * y) + 0.2
    by = 0.04 * np.cos(1.3 * x + 0.5) * np.sin(2.3 * y) - 0.05
    bz = 0.06 * np.sin(1.1 * x + 1.9 * y) + 0.4
    return np.stack([bx + bias[0], by + bias[1], bz + bias[2]], axis=-1)


def field_map(bias) -> MagneticFieldMap:
    xs, ys = (np.arange(120) + 0.5) * RES, (np.arange(80) + 0.5) * RES
    gx, gy = np.meshgrid(xs, ys)
    mean = bumpy_field(gx, gy, bias)
    return MagneticFieldMap(
        origin=np.zeros(2),
        resolution=RES,
        mean=mean,
        variance=np.full_like(mean, 1e-5),
        prior_mean=np.array([0.2, -0.05, 0.4]) + bias,
        prior_variance=np.full(3, 0.01),
        kernel=SquaredExponential(0.1, 0.5, 0.005),
        units="G",
    )


BIASES = ((0.0, 0.0, 0.0), (0.01, -0.02, 0.015))  # two devices, two calibrations


def loop(drift_from: int | None, drift: float = 0.05, seed: int = 3):
    """A loop of 400 readings every ~0.06 m; sensor 1's z drifts by ``drift`` G from reading
    ``drift_from`` on (a step, as a hard-iron change)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2 * np.pi, 400)
    truth = np.c_[6.0 + 3.5 * np.cos(t), 4.0 + 2.5 * np.sin(t), t + np.pi / 2]
    z = np.stack(
        [bumpy_field(truth[:, 0], truth[:, 1], b) + rng.normal(0, 0.005, (400, 3)) for b in BIASES],
        axis=1,
    )
    if drift_from is not None:
        z[drift_from:, 1, 2] += drift
    odo = truth.copy()
    odo[:, :2] += np.cumsum(rng.normal(0, 0.01, (400, 2)), axis=0)  # wandering odometry
    return truth, odo, z


@pytest.fixture(scope="module")
def maps():
    return [field_map(np.asarray(b)) for b in BIASES]


def test_two_sensors_on_one_map_run_as_the_single_model_of_eq_6_18(maps):
    """Both sensors read against the same map: the per-sensor sum must give the run of the
    C++ model that sums the sensors itself (eq. 6.18)."""
    truth, odo, z = loop(None)
    z[:, 1] = z[:, 0] + np.random.default_rng(9).normal(0, 0.005, (400, 3))
    offsets = [[0.0, 0.1], [0.0, -0.1]]
    config = MagneticMclConfig(particles=300, noise_sd=0.005, initial_sd=(0.1, 0.1, 0.05))
    kw = dict(initial_pose=truth[0], config=config, seed=5, frame="world")
    ours = localize_with_magnetometers([maps[0], maps[0]], odo, z, offsets, drift=None, **kw)
    single = localize_on_magnetic_map(maps[0], odo, z, offsets, **kw)
    np.testing.assert_allclose(ours.estimates, single.estimates, atol=1e-9)
    assert ours.resamplings == single.resamplings


@pytest.mark.parametrize("seed", [1, 2])
def test_a_drifting_sensor_is_dropped_and_the_other_keeps_the_estimate(maps, seed):
    truth, odo, z = loop(drift_from=150, seed=seed)
    config = MagneticMclConfig(particles=500, noise_sd=0.005, initial_sd=(0.1, 0.1, 0.05))
    kw = dict(initial_pose=truth[0], config=config, seed=seed)
    offsets = [[0.0, 0.0], [0.0, 0.0]]
    checked = localize_with_magnetometers(maps, odo, z, offsets, **kw)
    trusting = localize_with_magnetometers(maps, odo, z, offsets, drift=None, **kw)
    alone = localize_with_magnetometers(maps[:1], odo, z[:, :1], offsets[:1], **kw)
    (drop,) = checked.extra["dropped"]
    # dropped: sensor 1, on z, within the window's length after the drift began
    assert (drop.sensor, drop.axis) == (1, 2) and 150 <= drop.update < 150 + 2 * 20
    assert drop.mean > 3.0
    assert checked.extra["trusted"][drop.update + 1 :, 1].sum() == 0
    err = {
        name: np.hypot(*(r.estimates[:, :2] - truth[:, :2]).T)[200:].mean()
        for name, r in (("checked", checked), ("trusting", trusting), ("alone", alone))
    }
    # trusting the drifted sensor pulls the estimate off; dropping it gives the good sensor's
    assert err["trusting"] > 2 * err["checked"]
    assert err["checked"] < 1.5 * err["alone"] + 0.02


def test_no_sensor_is_dropped_when_none_drifts(maps):
    truth, odo, z = loop(None, seed=4)
    config = MagneticMclConfig(particles=500, noise_sd=0.005, initial_sd=(0.1, 0.1, 0.05))
    run = localize_with_magnetometers(
        maps, odo, z, [[0.0, 0.0]] * 2, initial_pose=truth[0], config=config, seed=4
    )
    assert run.extra["dropped"] == []
    assert run.extra["trusted"].all()


def test_bad_inputs(maps):
    truth, odo, z = loop(None)
    kw = dict(initial_pose=truth[0])
    with pytest.raises(ValueError, match="2 field map"):
        localize_with_magnetometers(maps, odo, z, [[0.0, 0.0]] * 3, **kw)
    with pytest.raises(ValueError, match="readings: expected shape"):
        localize_with_magnetometers(maps, odo, z[:, :1], [[0.0, 0.0]] * 2, **kw)
    with pytest.raises(ValueError, match="window must be an integer >= 2"):
        DriftCheck(window=1)
    for limit, shown in ((0.0, "0.0"), (float("inf"), "inf"), (True, "True")):
        with pytest.raises(
            ValueError, match=rf"^drift check: limit must be a finite number > 0, got {shown}$"
        ):
            DriftCheck(limit=limit)


def test_a_drift_limit_and_window_are_held_as_python_numbers():
    """A numpy limit was held as given (a float32 in the config), and so was a numpy window
    (np.int64, which json refuses)."""
    check = DriftCheck(window=np.int64(12), limit=np.float32(2.5))
    assert type(check.limit) is float and check.limit == 2.5
    assert type(check.window) is int and check.window == 12
