# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki magnetic fit``'s default model, the curl-free GP, and the predictor its map folder
keeps: on a field that is the gradient of a known potential, against the library's GP fitted
directly (the reference) and the closed form, in 2-D and 3-D, exact and reduced-rank."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg
import yaml

from kiseki.gp import CurlFreeGP, CurlFreeKernel, ReducedRankCurlFreeGP
from kiseki.magnetic.binning import bin_readings
from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.magnetic.map_gp import CURL_FREE_BASIS

EARTH = np.array([20.0, -5.0, -40.0])  # uT, the constant part


def run(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "magnetic", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
    )


def gradient_field(p: np.ndarray) -> np.ndarray:
    """f = EARTH - grad(phi), phi = 3 sin(1.3 x) cos(y) + 2 z cos(0.8 x) (uT m), in closed
    form; 2-D positions are read at z = 0."""
    x, y = p[:, 0], p[:, 1]
    z = p[:, 2] if p.shape[1] == 3 else np.zeros(len(p))
    dphi = np.column_stack(
        [
            3.9 * np.cos(1.3 * x) * np.cos(y) - 1.6 * z * np.sin(0.8 * x),
            -3.0 * np.sin(1.3 * x) * np.sin(y),
            2.0 * np.cos(0.8 * x),
        ]
    )
    return EARTH - dphi


def write_csv(path, columns: str, table: np.ndarray) -> None:
    np.savetxt(path, table, delimiter=",", header=columns, comments="", fmt="%.12g")


def read_csv(path) -> np.ndarray:
    return np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


@pytest.fixture(scope="module", params=[(2, "exact"), (3, "exact"), (2, "hilbert")])
def fitted(request, tmp_path_factory):
    """300 readings (noise 0.05 uT) over 4 x 4 m (x 1 m in 3-D), fitted with the defaults
    (the reduced-rank GP with --method hilbert)."""
    d, method = request.param
    folder = tmp_path_factory.mktemp(f"curl-free-{d}d-{method}")
    rng = np.random.default_rng(5)
    p = rng.uniform(0.0, [4.0, 4.0, 1.0][:d], (300, d))
    y = gradient_field(p) + rng.normal(0.0, 0.05, (300, 3))
    axes = "x,y,z"[: 2 * d - 1]
    write_csv(folder / "floor.csv", f"{axes},mx,my,mz", np.column_stack([p, y]))
    args = ["fit", "floor.csv", "-o", "map", "--resolution", 0.25]
    done = run(*args, *(["--method", method] if method == "hilbert" else []), cwd=folder)
    assert done.returncode == 0, done.stderr
    at = rng.uniform(0.5, [3.5, 3.5, 0.8][:d], (80, d))
    write_csv(folder / "at.csv", axes, at)
    done_predict = run("predict", "map", "--at", "at.csv", "-o", "out.csv", cwd=folder)
    assert done_predict.returncode == 0, done_predict.stderr
    return folder, d, method, p, y, at, done.stdout + done_predict.stdout


def test_the_default_is_the_curl_free_gp_on_readings_binned_per_tenth_of_a_metre(fitted):
    folder, d, method, p, y, _, stdout = fitted
    doc = yaml.safe_load((folder / "map" / "magnetic_map.yaml").read_text())
    assert doc["kernel"]["model"] == "curl-free" and "sigma_lin" in doc["kernel"]
    assert doc["provenance"]["data"]["bin"] == 0.1
    cells = len(bin_readings(p, y, 0.1)[0])
    assert cells < 300 and doc["training"]["points"] == cells  # binned, every cell kept
    assert doc["files"]["predictor"] == "predictor.npz"
    described = "exact curl-free GP" if method == "exact" else "reduced-rank curl-free GP"
    assert f"from {cells} of 300 measurements ({described})" in stdout
    assert "re-evaluated exactly (its stored factor)" in stdout


def test_predictions_equal_the_library_gp_with_the_maps_hyperparameters(fitted):
    """The reference: the GP fitted in this process on the same binned readings with the
    hyperparameters the YAML states (no search)."""
    folder, d, method, p, y, at, _ = fitted
    k = yaml.safe_load((folder / "map" / "magnetic_map.yaml").read_text())["kernel"]
    kernel = CurlFreeKernel(k["sigma_f"], k["length_scale"], k["sigma_lin"], k["sigma_n"])
    xb, yb, _ = bin_readings(p, y, 0.1)
    if method == "exact":
        reference = CurlFreeGP.fit(xb, yb, kernel)
    else:
        reference = ReducedRankCurlFreeGP.fit(xb, yb, kernel, basis=CURL_FREE_BASIS)
    mean, variance = reference.predict(at)
    out = read_csv(folder / "out.csv")
    np.testing.assert_allclose(out[:, d : d + 3], mean, rtol=0, atol=1e-6)
    np.testing.assert_allclose(out[:, d + 3 :], variance, rtol=1e-5, atol=1e-9)


def test_the_map_recovers_the_field_and_its_uncertainty(fitted):
    folder, d, method, _, _, at, _ = fitted
    out = read_csv(folder / "out.csv")
    error = out[:, d : d + 3] - gradient_field(at)
    rmse = np.sqrt(np.mean(error**2, axis=0))
    # measured: 0.01-0.03 uT exact, a little more with 1,024 functions; the noise is 0.05
    assert np.all(rmse < (0.05 if method == "exact" else 0.1)), rmse
    sd = np.sqrt(out[:, d + 3 :])
    assert np.mean(np.abs(error) < 3 * sd + 1e-3) > 0.9  # the variance is calibrated
    # outside the map: the constant field's posterior, close to the true constant
    fmap = MagneticFieldMap.load(folder / "map")
    assert np.all(np.abs(fmap.prior_mean - EARTH) < 1.5)


def test_predicting_needs_no_factorisation(fitted, monkeypatch):
    """The map keeps its GP's factor: loading and predicting factorise nothing."""
    folder, d, method, *_, at, _ = fitted

    def refuse(*args, **kwargs):
        raise AssertionError("a factorisation while predicting from a stored map")

    monkeypatch.setattr(scipy.linalg, "cho_factor", refuse)
    fmap = MagneticFieldMap.load(folder / "map")
    mean, _ = fmap.predict(at)
    np.testing.assert_allclose(mean, read_csv(folder / "out.csv")[:, d : d + 3], atol=1e-9)


def test_a_damaged_predictor_is_refused_in_one_line_naming_it(fitted, tmp_path):
    folder, *_ = fitted
    copy = tmp_path / "map"
    copy.mkdir()
    for f in (folder / "map").iterdir():
        copy.joinpath(f.name).write_bytes(f.read_bytes())
    with np.load(copy / "predictor.npz") as npz:
        arrays = dict(npz)
    arrays["factor_lower"] = arrays["factor_lower"] * 1.01  # not this data's factor any more
    np.savez(copy / "predictor.npz", **arrays)
    done = run("predict", copy, "--at", folder / "at.csv", "-o", tmp_path / "o.csv")
    assert done.returncode == 1 and len(done.stderr.splitlines()) == 1, done.stderr
    assert "predictor.npz" in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "o.csv").exists()
