# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the Kok-Solin walk reader: walks written here with known values, bad files named in
the error, and the recorded walks (their quaternion convention checked against scipy's
rotations)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import scipy.io
from scipy.spatial.transform import Rotation

from kiseki.datasets.kok import SENSOR_TO_BODY, read_kok_walk
from kiseki.datasets.magnetic import read_magnetic_data
from kiseki.errors import LogFormatError

# ---------------------------------------------------------------- walks written here


def reference_world_field(quat_wxyz: np.ndarray, m: np.ndarray) -> np.ndarray:
    """scipy's rotations: body-to-world of (w, x, y, z) quaternions after the +90 deg mount."""
    mount = Rotation.from_euler("z", 90.0, degrees=True)
    return Rotation.from_quat(quat_wxyz[:, [1, 2, 3, 0]]).apply(mount.apply(m))


def write_walk(path: Path, n: int = 5, **overrides) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(0)
    quat = rng.normal(size=(n, 4))
    data = {
        "t": 0.1 * np.arange(n)[:, None],
        "dPos": rng.normal(size=(n - 1, 3)),
        "quat": quat / np.linalg.norm(quat, axis=1, keepdims=True),
        "m": rng.normal(0.0, 30.0, (n, 3)),
        "LL": np.ones((1, 3)),
    }
    data.update(overrides)
    scipy.io.savemat(path, data)
    return data


def test_kok_walk_known_values(tmp_path: Path) -> None:
    data = write_walk(tmp_path / "w.mat")
    for s in (read_kok_walk(tmp_path / "w.mat"), read_magnetic_data(tmp_path / "w.mat")):
        assert len(s) == 5 and s.units == "uT" and s.dimension == 3
        np.testing.assert_allclose(s.positions[0], 0.0)
        np.testing.assert_allclose(s.positions[1:], np.cumsum(data["dPos"], axis=0), atol=1e-15)
        np.testing.assert_allclose(s.field, reference_world_field(data["quat"], data["m"]), 1e-12)
        np.testing.assert_allclose(s.times, data["t"].ravel())
    # A quarter turn about z (w = cos 45, z = sin 45) maps the sensor's x to world -x after the
    # mount (sensor x -> body y -> world -x).
    quarter = np.tile([np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5)], (2, 1))
    write_walk(tmp_path / "q.mat", 2, quat=quarter, m=np.array([[1.0, 0, 0], [0, 0, 1.0]]))
    np.testing.assert_allclose(
        read_kok_walk(tmp_path / "q.mat").field, [[-1, 0, 0], [0, 0, 1]], atol=1e-15
    )
    np.testing.assert_array_equal(SENSOR_TO_BODY @ [1, 0, 0], [0, 1, 0])


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"dPos": np.zeros((5, 3))}, r"dPos must be 4 x 3 .* got \(5, 3\)"),
        ({"quat": np.ones((5, 3))}, "quat must be 5 x 4 like m"),
        ({"m": np.ones((5, 2))}, r"m must be N x 3 with N >= 2, got \(5, 2\)"),
        ({"t": np.zeros((3, 1))}, "t must hold 5 times like m"),
        ({"quat": np.tile([1.0, 0.0, 0.0, 0.1], (5, 1))}, "quat row 1 is not a unit quaternion"),
        ({"m": np.full((5, 3), "a")}, "m is not a numeric array"),
        # taken with a numpy warning (the imaginary part dropped)
        ({"m": np.ones((5, 3)) + 1j}, "m is a complex128 array, not real numbers"),
        # a huge or NaN increment: the path it gives is refused (1e300 made an infinite walk)
        (
            {"dPos": np.array([[0.1, 0, 0], [1e300, 0, 0], [0.1, 0, 0], [0.1, 0, 0]])},
            r"dPos takes the walk to \[1e\+300, 0.0, 0.0\] m at sample 3: not finite within",
        ),
        (
            {"dPos": np.full((4, 3), np.nan)},
            r"dPos takes the walk to \[nan, nan, nan\] m at sample 2",
        ),
        # times going back, standing still or of 1e300 s were written to the trajectory as read
        (
            {"t": np.array([[0.4], [0.3], [0.2], [0.1], [0.0]])},
            r"t must increase .*sample 2 is 0.3 after 0.4",
        ),
        (
            {"t": np.zeros((5, 1))},
            r"t must increase from sample to sample.*; sample 2 is 0.0 after 0.0",
        ),
        (
            {"t": np.array([[0.0], [0.1], [1e300], [0.3], [0.4]])},
            r"t must increase.*sample 3 is 1e\+300 after 0.1",
        ),
        (
            {"t": np.array([[0.0], [0.1], [0.2], [0.3], [1e300]])},
            r"t must .* within \+-1e\+10 s; sample 5 is 1e\+300",
        ),
        (
            {"t": np.array([[np.nan], [0.1], [0.2], [0.3], [0.4]])},
            r"t must increase.*sample 1 is nan$",
        ),
    ],
)
def test_bad_kok_walk_named(tmp_path: Path, overrides, message: str) -> None:
    path = tmp_path / "w.mat"
    write_walk(path, **overrides)
    with pytest.raises(LogFormatError, match=f"^{re.escape(str(path))}: {message}"):
        read_kok_walk(path)


def test_kok_random_bytes_and_missing_variables(tmp_path: Path) -> None:
    path = tmp_path / "r.mat"
    path.write_bytes(np.random.default_rng(1).bytes(4000))
    with pytest.raises(LogFormatError, match=f"^{re.escape(str(path))}: not a MATLAB v5 .mat file"):
        read_kok_walk(path)
    scipy.io.savemat(tmp_path / "other.mat", {"a": np.ones(3)})
    with pytest.raises(LogFormatError, match="lacks t, dPos, quat, m .variables found: a."):
        read_kok_walk(tmp_path / "other.mat")
    with pytest.raises(LogFormatError, match="a directory"):
        read_kok_walk(tmp_path)


# ---------------------------------------------------------------- recorded walks

KOK_SIZES = {"eight": 466, "square": 747}


def spread(field: np.ndarray) -> float:
    """Norm of the per-component SD over a walk."""
    return float(np.linalg.norm(field.std(axis=0)))


@pytest.mark.parametrize("walk", sorted(KOK_SIZES))
def test_kok_walk_geometry_and_rotation(shared_data: Path, walk: str) -> None:
    path = shared_data / "magnetic" / "kok_1d" / f"{walk}.mat"
    raw = scipy.io.loadmat(path)
    s = read_kok_walk(path)
    assert len(s) == KOK_SIZES[walk] and s.units == "uT"
    np.testing.assert_allclose(s.positions[0], 0.0)
    # z is vertical: a hand-held walk spans metres in x and y, a few decimetres in z.
    extent = np.ptp(s.positions, axis=0)
    assert extent[2] < 0.5 and min(extent[:2]) > 2.0
    assert np.median(np.diff(s.times)) == pytest.approx(0.1, abs=1e-3)
    # The rotation keeps the magnitude and matches scipy's.
    np.testing.assert_allclose(s.magnitude, np.linalg.norm(raw["m"], axis=1), rtol=1e-12)
    np.testing.assert_allclose(s.field, reference_world_field(raw["quat"], raw["m"]), atol=1e-9)


@pytest.mark.parametrize("walk", sorted(KOK_SIZES))
def test_kok_quaternion_convention_from_the_data(shared_data: Path, walk: str) -> None:
    """The Earth field is constant in the world frame: of the 16 conventions (quaternion order
    w-first or w-last, rotation body-to-world or its inverse, magnetometer mount turned 0, 90, 180
    or 270 deg about z), the reader's gives the least spread of the world field (13.0 uT on eight,
    14.4 on square, the next 18.4 and 16.5), its vertical component varies far less than the raw
    readings, and its mean points down with a northern-European inclination."""
    raw = scipy.io.loadmat(shared_data / "magnetic" / "kok_1d" / f"{walk}.mat")
    quat, m = raw["quat"], raw["m"]
    spreads = {}
    for order, columns in (("wxyz", [1, 2, 3, 0]), ("xyzw", [0, 1, 2, 3])):
        rotation = Rotation.from_quat(quat[:, columns])
        for direction, r in (("body-to-world", rotation), ("world-to-body", rotation.inv())):
            for mount in (0, 90, 180, 270):
                turned = Rotation.from_euler("z", mount, degrees=True).apply(m)
                spreads[order, direction, mount] = spread(r.apply(turned))
    ranked = sorted(spreads, key=spreads.get)
    assert ranked[0] == ("wxyz", "body-to-world", 90)
    assert spreads[ranked[1]] > 1.1 * spreads[ranked[0]]
    world = read_kok_walk(shared_data / "magnetic" / "kok_1d" / f"{walk}.mat").field
    assert spread(world) == pytest.approx(spreads[ranked[0]], rel=1e-9)
    assert world[:, 2].std() < 0.5 * m.std(axis=0).max()
    mean = world.mean(axis=0)
    inclination = np.degrees(np.arctan2(-mean[2], np.linalg.norm(mean[:2])))
    assert 65.0 < inclination < 80.0
    assert 40.0 < np.linalg.norm(mean) < 60.0
