# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-table-6-2: the thesis' Table 6.2 protocol (``002_74cea16d239c028f.txt``, sec. 6.3.2) on
the simulated elevator hall (data/worlds/magnetic_hall.yaml): the field read with the
sensor's 0.01 G noise at every point of the 0.2 m measurement grid (3.0 x 3.0 x 2.2 m, 2816
points), the GP trained on every 2nd, 3rd, 4th and 5th point along each axis (0.4, 0.6, 0.8
and 1.0 m) and asked for the rest.

The target is the field's magnitude m of eq. 6.16: the section states that "in this
measurement the field strength m is computed by eq. 6.16", and the error is taken as
|m_predicted - m_measured| at each held-out point, whose mean and SD are Table 6.2's columns
(a signed mean of an unbiased regressor would stay near 0, the thesis' grows with the
spacing). The simulated hand-held sensor has no offsets (m_ref = 0, r_base = r_ref: a
calibrated sensor), so m = |reading|. The held-out readings are the thesis' reference ("the
manually measured data taken as the true values"); the simulator also gives the noise-free
field, the error against which is reported beside it. Each trial is one seed of the noise;
hyperparameters are fitted on each training set (eq. 6.11, BFGS from the sensor's noise).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.core import Random
from kiseki.gp import ExactGP, SquaredExponential, fit_hyperparameters
from kiseki.plots import new_figure, save_figure
from kiseki.sim.scene import load_scene
from kiseki_experiments.gp.gp_common import HALL, SENSOR_NOISE, magnetic_world
from kiseki_experiments.gp.gp_floor_mapping_report import CALIBRATED
from kiseki_experiments.gp.gp_table_6_2_claims import CLAIMS, evidence
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import Count, NonNegativeReal, Real, Restarts
from kiseki_experiments.harness.records import pack, unpack

__all__ = ["EXPERIMENT", "THESIS_KERNEL", "THESIS_TABLE", "Table62Config"]

#: Table 6.2: spacing (m) -> (used data number, mean error G, SD of the error G).
THESIS_TABLE = {
    0.4: (384, 0.00648, 0.01205),
    0.6: (144, 0.00862, 0.01303),
    0.8: (48, 0.01192, 0.01838),
    1.0: (48, 0.01440, 0.02048),
}
#: Table 6.1, printed without units: sigma_f, l (m), sigma_n.
THESIS_KERNEL = (1.73808, 0.47496, 0.41968)
MODELS = ("gp", "constant")
UT = 0.01  # G per microtesla


@dataclass(frozen=True)
class Table62Config:
    scene: str = str(HALL)
    steps: list[Count] = field(default_factory=lambda: [2, 3, 4, 5])  # every k-th grid point
    noise_sd: NonNegativeReal = SENSOR_NOISE  # G, per axis (thesis sec. 6.3.2: "about 0.01 G")
    restarts: Restarts = 2  # random BFGS starts after the one at the sensor's noise
    # "<= 0.6 m suffices": SD(0.6) within this share of SD(0.4), and the wider spacings' SDs at
    # least this share above SD(0.6) (the thesis: 8 % and 41-57 %)
    suffices_margin: NonNegativeReal = 0.2
    slice_height: Real = 1.0  # m, the layer drawn (the west column's splice)
    # "gp": eq. 6.8's mean; "constant": the training points' mean magnitude everywhere (the
    # claims' control)
    model: str = "gp"


def preflight(config: Table62Config) -> None:
    if not Path(config.scene).is_file():
        raise FileNotFoundError(f"gp-table-6-2: {config.scene} not found")
    if load_scene(config.scene).measurement_grid is None:
        raise ValueError(f"gp-table-6-2: {config.scene} states no measurement_grid")
    if not config.steps or any(k < 2 for k in config.steps):
        raise ValueError(f"gp-table-6-2: steps must be integers >= 2, got {config.steps}")
    if config.model not in MODELS:
        raise ValueError(f"gp-table-6-2: model must be one of {MODELS}, got {config.model!r}")
    if not config.noise_sd > 0:
        raise ValueError(f"gp-table-6-2: noise_sd must be > 0, got {config.noise_sd}")


def _fit(x, y, noise_sd: float, restarts: int, seed: int) -> ExactGP:
    """The GP with eq. 6.11's hyperparameters, BFGS from (data spread, 0.5 m, sensor noise)."""
    spread = float(np.sqrt(np.mean(np.var(np.reshape(y, (len(y), -1)), axis=0))))
    start = SquaredExponential(max(spread, noise_sd), 0.5, noise_sd)
    fit = fit_hyperparameters(x, y, initial=start, restarts=restarts, seed=seed)
    return ExactGP.fit(x, y, fit.kernel)


def trial(config: Table62Config, index: int, seed: int) -> TrialOutput:
    scene = load_scene(config.scene)
    grid = scene.measurement_grid
    points = grid.points()
    truth = magnetic_world(scene).static_field_at(points)  # the hall has no time here
    noise = Random(seed).normal(0.0, config.noise_sd, truth.size).reshape(truth.shape)
    readings = truth + noise
    m_read, m_true = np.linalg.norm(readings, axis=1), np.linalg.norm(truth, axis=1)  # eq. 6.16
    thesis = SquaredExponential(THESIS_KERNEL[0] * UT, THESIS_KERNEL[1], THESIS_KERNEL[2] * UT)
    rows: dict[str, list] = {}
    for step in config.steps:
        train = grid.mask(step)
        test = ~train
        x = points[train]
        gp = _fit(x, m_read[train], config.noise_sd, config.restarts, seed)
        mean, var = gp.predict(points)
        mean, sd = mean[:, 0], np.sqrt(var[:, 0])
        if config.model == "constant":  # the control: one value for the whole hall
            mean = np.full(len(points), m_read[train].mean())
            sd = np.full(len(points), m_read[train].std())
        err_read = np.abs(mean - m_read)[test]
        err_true = np.abs(mean - m_true)[test]
        vec = _fit(x, readings[train], config.noise_sd, config.restarts, seed)
        vec_mean, _ = vec.predict(points[test])
        fixed_mean, fixed_var = ExactGP.fit(x, m_read[train], thesis).predict(points[test])
        fixed_err = np.abs(fixed_mean[:, 0] - m_true[test])
        fixed_sd = np.sqrt(fixed_var[:, 0])
        lo, hi = x.min(axis=0), x.max(axis=0)
        outside = np.any((points[test] < lo - 1e-9) | (points[test] > hi + 1e-9), axis=1)
        values = {
            "spacing_m": round(step * grid.spacing, 6),
            "train": int(train.sum()),
            "test": int(test.sum()),
            "outside_training_box": float(outside.mean()),
            "mean_err": float(err_read.mean()),
            "sd_err": float(err_read.std()),
            "signed_mean_err": float((mean - m_read)[test].mean()),
            "mean_err_true": float(err_true.mean()),
            "sd_err_true": float(err_true.std()),
            "within_2sd_true": float(np.mean(err_true <= 2 * sd[test])),
            "sigma_f": gp.kernel.sigma_f,
            "length_scale": gp.kernel.length_scale,
            "sigma_n": gp.kernel.sigma_n,
            "length_scale_xyz": vec.kernel.length_scale,
            "sigma_n_xyz": vec.kernel.sigma_n,
            "rmse_mx": 0.0,
            "rmse_my": 0.0,
            "rmse_mz": 0.0,
            "thesis_kernel_mean_err_true": float(fixed_err.mean()),
            "thesis_kernel_within_2sd_ut": float(np.mean(fixed_err <= 2 * fixed_sd)),
            "prediction": pack(mean),
        }
        rmse = np.sqrt(np.mean((vec_mean - truth[test]) ** 2, axis=0))
        values.update(rmse_mx=float(rmse[0]), rmse_my=float(rmse[1]), rmse_mz=float(rmse[2]))
        for key, value in values.items():
            rows.setdefault(key, []).append(value)
    rows["truth"] = [pack(m_true)]
    return TrialOutput(rows)


def _per_spacing(trials: pd.DataFrame) -> pd.DataFrame:
    """One row per (trial, spacing)."""
    keys = [c for c in trials.columns if c not in ("trial", "seed", "error", "truth")]
    frame = trials[["trial", *keys]].explode(keys, ignore_index=True)
    for key in keys:
        if key != "prediction":
            frame[key] = pd.to_numeric(frame[key])
    return frame


def analyze(config: Table62Config, trials, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    rows = _per_spacing(ok)
    means = rows.drop(columns=["prediction"]).groupby("spacing_m").mean().reset_index()
    spread = rows.groupby("spacing_m")[["mean_err", "sd_err"]].std().reset_index()
    table = pd.DataFrame(
        {
            "spacing_m": means["spacing_m"],
            "train": means["train"].astype(int),
            "thesis_train": [THESIS_TABLE.get(round(s, 1), (np.nan,))[0] for s in means.spacing_m],
            "mean_err_G": means["mean_err"],
            "thesis_mean_err_G": [_thesis(s, 1) for s in means.spacing_m],
            "sd_err_G": means["sd_err"],
            "thesis_sd_err_G": [_thesis(s, 2) for s in means.spacing_m],
            "seed_sd_of_mean_err": spread["mean_err"],
            "mean_err_vs_truth_G": means["mean_err_true"],
            "sd_err_vs_truth_G": means["sd_err_true"],
            "signed_mean_err_G": means["signed_mean_err"],
            "held_out_outside_training_box": means["outside_training_box"],
            "within_2sd_vs_truth": means["within_2sd_true"],
        }
    )
    hyper = means[["spacing_m", "sigma_f", "length_scale", "sigma_n"]].copy()
    hyper["length_scale_xyz"] = means["length_scale_xyz"]  # mx, my, mz with one kernel
    hyper["sigma_n_xyz"] = means["sigma_n_xyz"]
    hyper["sigma_f_uT"] = hyper["sigma_f"] / UT
    hyper["sigma_n_uT"] = hyper["sigma_n"] / UT
    components = means[
        ["spacing_m", "rmse_mx", "rmse_my", "rmse_mz", "thesis_kernel_mean_err_true"]
    ].copy()
    components["thesis_kernel_within_2sd_uT"] = means["thesis_kernel_within_2sd_ut"]
    figs = [_plot_errors(table, rows, figures)]
    if len(ok):
        figs.append(_plot_slice(config, ok.iloc[0], figures))
    return Analysis(
        {
            "table_6_2": table,
            "hyperparameters": hyper,
            "components_and_thesis_kernel": components,
            "calibrated": calibrated(table, hyper),
        },
        figs,
        notes=_notes(config, hyper),
        evidence=evidence(config, rows),
    )


def _thesis(spacing: float, column: int) -> float:
    return THESIS_TABLE.get(round(float(spacing), 1), (np.nan,) * 3)[column]


def calibrated(table: pd.DataFrame, hyper: pd.DataFrame) -> pd.DataFrame:
    """The numbers magnetic_hall.yaml was built to give (its ``calibrated`` marks): the grid of
    2816 points, whose subsamples are Table 6.2's training counts by arithmetic, and the
    sources' spatial scale, aimed at Table 6.1's length scale. Shown, not claimed."""
    rows = [
        {
            "quantity": f"training points at {s:g} m",
            "thesis": float(THESIS_TABLE[round(s, 1)][0]),
            "kiseki": float(n),
            "note": "16 x 16 x 11 grid points (fitted to 2816); subsamples by arithmetic",
        }
        for s, n in zip(table["spacing_m"], table["train"], strict=True)
        if round(s, 1) in THESIS_TABLE
    ]
    at04 = hyper[hyper.spacing_m.round(1) == 0.4]
    if len(at04):
        rows.append(
            {
                "quantity": "length scale, the magnitude's GP on the 0.4 m set (Table 6.1)",
                "thesis": THESIS_KERNEL[1],
                "kiseki": float(at04["length_scale"].iloc[0]),
                "note": "mx, my, mz with one kernel on the same points: l = "
                f"{float(at04['length_scale_xyz'].iloc[0]):.3f} m; the sources were aimed at "
                "the thesis' value",
            }
        )
    out = pd.DataFrame(rows)
    out["status"] = CALIBRATED
    return out


def _plot_errors(table: pd.DataFrame, rows: pd.DataFrame, figures: Path) -> Path:
    fig = new_figure(figsize=(9, 3.8), dpi=120)
    axes = fig.subplots(1, 2)
    for ax, ours, truth, thesis, name in (
        (axes[0], "mean_err_G", "mean_err_vs_truth_G", "thesis_mean_err_G", "mean of |error|"),
        (axes[1], "sd_err_G", "sd_err_vs_truth_G", "thesis_sd_err_G", "SD of |error|"),
    ):
        column = "mean_err" if ours.startswith("mean") else "sd_err"
        ax.plot(rows["spacing_m"], rows[column], ".", color="tab:blue", alpha=0.4)
        ax.plot(table["spacing_m"], table[ours], "o-", label="kiseki vs held-out readings")
        ax.plot(table["spacing_m"], table[truth], "s--", label="kiseki vs true field")
        ax.plot(table["spacing_m"], table[thesis], "k^-", label="thesis Table 6.2")
        ax.axhline(0.01, color="grey", lw=0.8, ls=":", label="sensor noise 0.01 G")
        ax.set_xlabel("training spacing (m)")
        ax.set_ylabel(f"{name} (G)")
        ax.set_ylim(bottom=0)
    axes[0].legend(fontsize=7)
    fig.suptitle("Table 6.2: error of the field magnitude (eq. 6.16) on held-out grid points")
    fig.tight_layout()
    return save_figure(fig, figures / "gp_table_6_2_errors.png")


def _plot_slice(config: Table62Config, row, figures: Path) -> Path:
    """Fig. 6.3's idea on one layer: the noise-free magnitude and each subsample's prediction,
    the training points of that layer marked."""
    grid = load_scene(config.scene).measurement_grid
    nx, ny, nz = grid.shape
    xs, ys, zs = grid.axes()
    k = int(np.argmin(np.abs(zs - config.slice_height)))
    truth = unpack(row["truth"][0]).reshape(nx, ny, nz)[:, :, k]
    predictions = [unpack(p).reshape(nx, ny, nz)[:, :, k] for p in row["prediction"]]
    lo, hi = float(truth.min()), float(truth.max())
    extent = [xs[0] - 0.1, xs[-1] + 0.1, ys[0] - 0.1, ys[-1] + 0.1]
    fig = new_figure(figsize=(3.0 * (1 + len(predictions)), 3.4), dpi=110)
    axes = np.atleast_1d(fig.subplots(1, 1 + len(predictions)))
    shown = axes[0].imshow(truth.T, origin="lower", extent=extent, vmin=lo, vmax=hi)
    axes[0].set_title(f"true |B|, z = {zs[k]:.1f} m", fontsize=8)
    for ax, step, image in zip(axes[1:], config.steps, predictions, strict=True):
        ax.imshow(image.T, origin="lower", extent=extent, vmin=lo, vmax=hi)
        keep = grid.mask(step).reshape(nx, ny, nz)[:, :, k]
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        ax.plot(gx[keep], gy[keep], "w.", ms=3)
        ax.set_title(f"from {step * grid.spacing:.1f} m subsample", fontsize=8)
    for ax in axes:
        ax.tick_params(labelsize=6)
    fig.colorbar(shown, ax=list(axes), shrink=0.8, label="G")
    return save_figure(fig, figures / "gp_table_6_2_slice.png")


def _notes(config: Table62Config, hyper: pd.DataFrame) -> str:
    sf, ls, sn = THESIS_KERNEL
    return f"""
Error definition: |m_pred - m| per held-out grid point, m the magnitude of eq. 6.16 (the
thesis fits m, a scalar: sec. 6.3.2 computes m by eq. 6.16 "in this measurement"); Table 6.2's
mean grows with the spacing, which a signed mean would not (kiseki's signed mean is in the
table: near 0). The reference is the held-out noisy reading, as in the thesis (its manual
survey was taken as the true values); the error against the simulator's noise-free field is
beside it. A |N(0, 0.01)| reading error alone has mean 0.0080 G and SD 0.0060 G, so the
thesis' mean of 0.00648 G at 0.4 m suggests its readings were averaged at each point (about
8 h for 2816 points), or that its sensor's noise on the magnitude was below 0.01 G.

Counts: 16 x 16 x 11 points (z from 0.2 m: the floor layer was not measured, which is what
makes 2816); every 2nd/3rd/4th/5th point per axis gives 8x8x6, 6x6x4, 4x4x3, 4x4x3 = 384, 144,
48, 48, the thesis' column exactly, including its equal 0.8 and 1.0 m counts. They differ in
reach: the 0.8 m set stops at 2.4 m in x and y and 1.8 m in z, so part of the held-out points
lie outside it (column held_out_outside_training_box) and are extrapolated; the 1.0 m set
spans the whole box.

Hyperparameters: Table 6.1 prints sigma_f {sf}, l {ls}, sigma_n {sn} without units. In G,
sigma_n would be 42 times the sensor's 0.01 G noise and sigma_f 3.7 times the Earth's whole
field: impossible for a 0.01 G sensor in a hall whose field varies by a few hundredths of a
gauss. Read in microtesla (1 uT = 0.01 G) they are sigma_f = {sf * UT:.4f} G, sigma_n =
{sn * UT:.4f} G: the field's spread and a noise below the sensor's, the scale kiseki finds
(table hyperparameters, G and uT columns). The GP mean depends on sigma_n / sigma_f and l only,
so the units cannot change Table 6.2's errors; they change the predicted variance: with Table
6.1 read in uT the noise-free error lies within 2 predicted SD at the share in the last table
(read in G every error would lie within 2 SD, trivially, the SD being about 1.7 G). Length
scale: the magnitude's GP finds a longer one than mx, my, mz fitted together on the same
points (column length_scale_xyz): the magnitude mostly follows the disturbance's component
along the Earth field and is smoother than the components; the scene was sized so that its
components' autocorrelation gives the thesis' 0.475 m.
"""


EXPERIMENT = Experiment(
    name="gp-table-6-2",
    paper="002_74cea16d239c028f.txt",
    artefact="Table 6.2 (with Table 6.1, Fig. 6.3)",
    description="GP accuracy from thinned-out surveys of an elevator hall (0.4-1.0 m spacing)",
    config_type=Table62Config,
    trial=trial,
    analyze=analyze,
    default_runs=5,
    preflight=preflight,
    claims=CLAIMS,
)
