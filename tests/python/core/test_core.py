# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Poses, angles and the seeded generator, checked against numpy references."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

import kiseki
from kiseki import Pose2, Pose3, Random


def homogeneous(p: Pose2) -> np.ndarray:
    c, s = np.cos(p.theta), np.sin(p.theta)
    return np.array([[c, -s, p.x], [s, c, p.y], [0, 0, 1]])


def test_pose2_compose_matches_matrix_product():
    rng = np.random.default_rng(1)
    for _ in range(50):
        a, b = (Pose2(*rng.uniform(-5, 5, 3)) for _ in range(2))
        m = homogeneous(a) @ homogeneous(b)
        c = a * b
        np.testing.assert_allclose([c.x, c.y], m[:2, 2], atol=1e-12)
        assert np.isclose(np.cos(c.theta), m[0, 0]) and np.isclose(np.sin(c.theta), m[1, 0])
        d = a.between(c)
        np.testing.assert_allclose(d.to_array(), b.to_array(), atol=1e-9)
    p = Pose2(1.0, 2.0, 0.5)
    assert pickle.loads(pickle.dumps(p)).to_array().tolist() == p.to_array().tolist()


def test_pose2_rejects_nan():
    with pytest.raises(ValueError, match="finite"):
        Pose2(float("nan"), 0.0, 0.0)


def test_normalize_angle_vectorised_matches_arctan2():
    a = np.linspace(-30, 30, 1001)
    n = kiseki.normalize_angle(a)
    np.testing.assert_allclose(n, np.arctan2(np.sin(a), np.cos(a)), atol=1e-12)
    assert (n >= -np.pi).all() and (n < np.pi).all()


def test_pose3_against_matrices():
    a = Pose3.from_rpy(1, 2, 3, 0.1, 0.2, 0.3)
    b = Pose3.from_rpy(-1, 0, 2, -0.3, 0.1, 1.3)
    np.testing.assert_allclose((a * b).matrix(), a.matrix() @ b.matrix(), atol=1e-12)
    np.testing.assert_allclose((a * a.inverse()).matrix(), np.eye(4), atol=1e-12)
    assert a.to_pose2().x == pytest.approx(1.0)
    with pytest.raises(ValueError):
        Pose3([0, 0, np.nan], [1, 0, 0, 0])


def test_random_is_reproducible_and_seed_sensitive():
    a, b, c = Random(5).normal(size=1000), Random(5).normal(size=1000), Random(6).normal(size=1000)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    assert abs(a.mean()) < 4 / np.sqrt(1000)
    assert abs(a.std() - 1) < 0.1
    u = Random(1).uniform(2.0, 3.0, 10000)
    assert u.min() >= 2.0 and u.max() < 3.0 and abs(u.mean() - 2.5) < 0.01
    assert kiseki.derive_seed(1, 2) == kiseki.derive_seed(1, 2) != kiseki.derive_seed(1, 3)
    with pytest.raises(ValueError):
        Random(1).normal(0.0, -1.0, 3)
    with pytest.raises(ValueError):
        Random(1).uniform(size=-1)


@pytest.mark.parametrize(
    ("draw", "match"),
    [
        (lambda r: r.uniform(math.nan, 1.0, 3), "uniform: low and high must be finite"),
        (lambda r: r.uniform(0.0, math.inf, 3), "uniform: low and high must be finite"),
        (lambda r: r.uniform(-1e308, 1e308, 3), "less than 1e308 apart"),
        (lambda r: r.normal(math.nan, 1.0, 3), "normal: mean and stddev must be finite"),
        (lambda r: r.normal(0.0, math.inf, 3), "normal: mean and stddev must be finite"),
    ],
)
def test_random_refuses_parameters_that_give_nan_or_infinite_draws(draw, match):
    """Each of these returned NaN or infinite numbers without a word."""
    with pytest.raises(ValueError, match=match):
        draw(Random(1))


def test_version_and_linked_libraries():
    versions = kiseki.library_versions()
    assert versions["kiseki"] == kiseki.__version__
    assert versions["octomap"].count(".") == 2  # probed by building an OcTree
    assert versions["pcl"].startswith("1.") and versions["opencv"].startswith("4.")
