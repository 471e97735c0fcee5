# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-aalto-defaults at a small size on the recorded Aalto runs, its numbers recomputed here
without the experiment's code: scikit-learn's baseline on the case's readings, the curl-free
GP's mean from its recorded hyperparameters by a dense solve of the kernel written out here,
the default from the per-case table by the stated rule, and each claim's value as the mean of
the paired differences."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from kiseki.datasets import read_aalto_run
from kiseki_experiments.gp.gp_aalto_defaults import GpAaltoDefaultsConfig, preflight
from kiseki_experiments.harness.runner import run_experiment

RUNS = (1, 2, 3)
SMALL = {
    "baseline_step": 200,
    "test_step": 20,
    "bin_size": 0.3,
    "hilbert_tolerances": "0.0001",
    "curl_free_basis": "128",
    "max_points": 200,
    "curl_free_max_points": 150,
    "restarts": 0,
}


@pytest.fixture(scope="module")
def small_run(shared_data, tmp_path_factory):
    overrides = [f"data_dir={shared_data / 'magnetic'}", "sensors=invensense", "runs=1,2,3"]
    overrides += [f"{k}={v}" for k, v in SMALL.items()]
    out = tmp_path_factory.mktemp("gp-aalto-defaults") / "run"
    run = run_experiment("gp-aalto-defaults", seed=0, overrides=overrides, out=out, progress=False)
    assert run.failed == 0
    return run.run_dir, shared_data / "magnetic" / "aalto" / "invensense"


def _case(folder, held_out: int):
    runs = {r: read_aalto_run(folder / str(r)) for r in RUNS}
    train = [r for r in RUNS if r != held_out]
    x = np.vstack([runs[r].positions for r in train])
    y = np.vstack([runs[r].field for r in train])
    test = runs[held_out]
    return x, y, test.positions[:: SMALL["test_step"]], test.field[:: SMALL["test_step"]]


def _row(run_dir, held_out: int, method: str) -> pd.Series:
    table = pd.read_csv(run_dir / "tables" / "per_case.csv")
    row = table[(table["held_out"] == held_out) & (table["method"] == method)]
    assert len(row) == 1
    return row.iloc[0]


def test_the_baseline_is_scikit_learns_gp_on_every_nth_reading(small_run) -> None:
    from sklearn.gaussian_process import GaussianProcessRegressor
    from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

    run_dir, folder = small_run
    x, y, points, truth = _case(folder, 2)
    step = SMALL["baseline_step"]
    row = _row(run_dir, 2, "sklearn")
    for c, name in enumerate("xyz"):
        target = y[::step, c]
        gpr = GaussianProcessRegressor(ConstantKernel() * RBF() + WhiteKernel())
        gpr.fit(x[::step], target - target.mean())
        error = truth[:, c] - gpr.predict(points) - target.mean()
        assert row[f"rmse_{name}"] == pytest.approx(np.sqrt(np.mean(error**2)), rel=1e-6)
        assert row[f"bias_{name}"] == pytest.approx(np.mean(error), rel=1e-6, abs=1e-9)


def test_the_curl_free_map_is_the_dense_posterior_of_its_recorded_kernel(small_run) -> None:
    run_dir, folder = small_run
    x, y, points, truth = _case(folder, 3)
    trials = pd.read_parquet(run_dir / "trials.parquet").set_index("held_out")
    k = {n: trials.loc[3, f"curl-free-exact-bin:{n}"] for n in ("sigma_f", "length_scale")}
    k |= {n: trials.loc[3, f"curl-free-exact-bin:{n}"] for n in ("sigma_lin", "sigma_n")}
    # the readings averaged per 0.3 m square, written out here (cell order does not matter)
    cells = np.floor(x / SMALL["bin_size"]).astype(np.int64)
    _, inverse = np.unique(cells, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    counts = np.bincount(inverse)
    xb = np.column_stack([np.bincount(inverse, x[:, c]) for c in range(2)]) / counts[:, None]
    yb = np.column_stack([np.bincount(inverse, y[:, c]) for c in range(3)]) / counts[:, None]

    def cov(a, b):  # d^2/dx dx'^T of sigma_f^2 exp(-|r|^2 / 2 l^2) + sigma_lin^2 x^T x', z = 0
        r = np.zeros((len(a), len(b), 3))
        r[:, :, :2] = a[:, None, :] - b[None, :, :]
        l2 = k["length_scale"] ** 2
        e = k["sigma_f"] ** 2 * np.exp(-0.5 * (r**2).sum(axis=2) / l2)
        block = e[:, :, None, None] * (np.eye(3) / l2 - r[..., :, None] * r[..., None, :] / l2**2)
        block += k["sigma_lin"] ** 2 * np.eye(3)
        return block.transpose(0, 2, 1, 3).reshape(3 * len(a), 3 * len(b))

    gram = cov(xb, xb) + k["sigma_n"] ** 2 * np.eye(3 * len(xb))
    mean = (cov(points, xb) @ np.linalg.solve(gram, yb.reshape(-1))).reshape(-1, 3)
    row = _row(run_dir, 3, "curl-free-exact-bin")
    rmse = np.sqrt(np.mean((truth - mean) ** 2, axis=0))
    np.testing.assert_allclose(row[["rmse_x", "rmse_y", "rmse_z"]].to_numpy(float), rmse, rtol=1e-6)
    # and it is a map: well under the held-out field's spread
    assert (rmse < 0.6 * truth.std(axis=0)).all()


def test_the_default_follows_the_rule_and_the_claims_are_the_paired_means(small_run) -> None:
    run_dir, _ = small_run
    table = pd.read_csv(run_dir / "tables" / "per_case.csv")
    rmse = ["rmse_x", "rmse_y", "rmse_z"]
    assert len(table) == 3 * 6  # 3 held-out runs, 6 methods (1 tolerance, 1 basis size)
    kiseki = table[table["method"] != "sklearn"]
    by_method = kiseki.groupby("method")[rmse].mean().mean(axis=1)
    default = by_method.idxmin()
    summary = pd.read_csv(run_dir / "tables" / "summary.csv")
    assert summary.loc[summary["default"], "method"].tolist() == [default]
    claims = pd.read_csv(run_dir / "claims.csv", keep_default_na=False)
    for comp in "xyz":
        for a, b, prefix in (
            (default, "sklearn", "kiseki's default map"),
            ("curl-free-exact-bin", "exact-bin-per-component", "the exact curl-free GP"),
        ):
            left = table[table["method"] == a].set_index("held_out")[f"rmse_{comp}"]
            right = table[table["method"] == b].set_index("held_out")[f"rmse_{comp}"]
            row = claims[
                claims["claim"].str.startswith(prefix) & claims["claim"].str.endswith(f"[{comp}]")
            ]
            assert len(row) == 1
            measured = float(str(row.iloc[0]["measured_value"]).split()[0])
            assert measured == pytest.approx((left - right).mean(), abs=1e-3)
            assert row.iloc[0]["verdict"] == "inconclusive"  # 3 cases: too few for an interval


def test_bad_configs_are_refused(tmp_path) -> None:
    with pytest.raises(FileNotFoundError, match="no magnetic data folder"):
        preflight(GpAaltoDefaultsConfig(data_dir=str(tmp_path / "none")))
    with pytest.raises(ValueError, match="sensors"):
        preflight(GpAaltoDefaultsConfig(data_dir=str(tmp_path), sensors=["compass"]))
    with pytest.raises(ValueError, match="distinct runs"):
        preflight(GpAaltoDefaultsConfig(data_dir=str(tmp_path), runs=[1, 1, 2]))
