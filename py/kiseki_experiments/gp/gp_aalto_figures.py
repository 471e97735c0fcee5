# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-aalto's pictures: the maps (mean and SD, as the thesis' Fig. 6.13) with the paths, the
held-out errors, denser training data, the MCL trajectories and errors, the change detection
and the 3-D walks."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from kiseki.plots import new_figure, save_figure
from kiseki_experiments.gp.gp_aalto_steps import ERROR_BINS, Z_BINS

__all__ = ["draw_all"]

XYZ = ("x", "y", "z")


def _grid_image(grid: dict, layer: str, c: int) -> tuple[np.ndarray, list[float]]:
    ny, nx = grid["shape"]
    image = np.asarray(grid[layer][c]).reshape(ny, nx)
    (x0, y0), r = grid["origin"], grid["resolution"]
    return image, [x0, x0 + nx * r, y0, y0 + ny * r]


def _map_figure(sensor: str, p: dict, figures: Path) -> Path:
    fig = new_figure(figsize=(13, 7.5), dpi=110)
    axes = fig.subplots(2, 3)
    train, test = np.asarray(p["train_positions"]), np.asarray(p["test_positions"])
    for c in range(3):
        for row, (layer, cmap, label) in enumerate(
            (("mean", "RdBu_r", "mean"), ("sd", "viridis", "SD of the noise-free field"))
        ):
            ax = axes[row, c]
            image, extent = _grid_image(p["grid"], layer, c)
            shown = ax.imshow(image, origin="lower", extent=extent, cmap=cmap)
            fig.colorbar(shown, ax=ax, shrink=0.8, label="uT")
            ax.plot(train[:, 0], train[:, 1], ".", ms=1, color="k", alpha=0.4)
            ax.plot(test[:, 0], test[:, 1], "-", lw=0.6, color="orange")
            ax.set_title(f"m{XYZ[c]}: {label}", fontsize=9)
            ax.set_aspect("equal")
    fig.suptitle(
        f"{sensor}: GP map of the training runs (corrected readings; dots: training readings, "
        "orange: held-out run)",
        fontsize=10,
    )
    return save_figure(fig, figures / f"map_{sensor}.png")


def _errors_figure(maps: dict, figures: Path) -> Path:
    fig = new_figure(figsize=(13, 3.2 * len(maps)), dpi=110)
    axes = np.atleast_2d(fig.subplots(len(maps), 4))
    centres = 0.5 * (ERROR_BINS[1:] + ERROR_BINS[:-1])
    zc = 0.5 * (Z_BINS[1:] + Z_BINS[:-1])
    for row, (sensor, p) in zip(axes, maps.items(), strict=True):
        for c in range(3):
            for variant, colour in (("raw", "tab:gray"), ("corrected", "tab:blue")):
                row[c].step(centres, p[variant]["error_hist"][c], where="mid", color=colour)
            row[c].set_title(f"{sensor}: error in m{XYZ[c]} (uT)", fontsize=9)
        counts = np.asarray(p["corrected"]["z_hist"], dtype=float)
        width = Z_BINS[1] - Z_BINS[0]
        row[3].bar(zc, counts / counts.sum() / width, width=width, color="tab:blue", alpha=0.6)
        row[3].plot(zc, np.exp(-0.5 * zc**2) / np.sqrt(2 * np.pi), color="k", lw=1)
        row[3].set_title(f"{sensor}: error / predictive sigma vs N(0, 1)", fontsize=9)
    axes[0, 0].legend(["as recorded", "less the robot-frame offset"], fontsize=7)
    fig.tight_layout()
    return save_figure(fig, figures / "held_out_errors.png")


def _sweep_figure(maps: dict, figures: Path) -> Path:
    fig = new_figure(figsize=(6 * len(maps), 4), dpi=110)
    axes = np.atleast_1d(fig.subplots(1, len(maps)))
    for ax, (sensor, p) in zip(axes, maps.items(), strict=True):
        for variant, style in (("corrected", "-o"), ("raw", "--s")):
            rows = [r for r in p["sweep"] if r.get("readings", "corrected") == variant]
            for c, colour in zip(range(3), ("tab:red", "tab:green", "tab:blue"), strict=True):
                ax.plot(
                    [r["points"] for r in rows],
                    [r["rmse"][c] for r in rows],
                    style,
                    ms=3,
                    color=colour,
                    label=f"m{XYZ[c]} {'as recorded' if variant == 'raw' else 'corrected'}",
                )
        ax.set_xscale("log")
        ax.set_xlabel("training readings (reduced-rank GP above 2,000)")
        ax.set_ylabel("RMSE on the held-out run (uT)")
        ax.set_title(f"{sensor}: denser training readings, same hyperparameters", fontsize=9)
        ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    return save_figure(fig, figures / "denser_training.png")


def _mcl_figure(mcl: dict, background: dict | None, figures: Path) -> Path:
    fig = new_figure(figsize=(13, 5), dpi=110)
    ax, ax_err = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.3]})
    if background is not None:
        image, extent = _grid_image(background, "mean", 2)
        ax.imshow(image, origin="lower", extent=extent, cmap="Greys", alpha=0.6)
    truth = np.asarray(mcl["truth"])
    first = mcl["trajectories"][0]
    ax.plot(truth[:, 0], truth[:, 1], "r-", lw=1.2, label="Vicon (truth)")
    ax.plot(*np.asarray(first["odometry"]).T, "k--", lw=1, label="odometry")
    ax.plot(*np.asarray(first["mcl"]).T, "b-", lw=1, label="magnetic-map MCL")
    ax.set_aspect("equal")
    ax.legend(fontsize=7)
    ax.set_title("trajectories, odometry seed 0 (background: map of mz)", fontsize=9)
    travel = np.asarray(mcl["travel"])
    for k, row in enumerate(mcl["rows"]):
        ax_err.plot(travel, row["mcl_error"], "b-", lw=0.8, label="MCL" if k == 0 else None)
        ax_err.plot(
            travel, row["odometry_error"], "k--", lw=0.6, label="odometry" if k == 0 else None
        )
    ax_err.axhline(0.8, color="r", ls=":", label="thesis bound 0.8 m")
    ax_err.set_xlabel("travel (m)")
    ax_err.set_ylabel("position error (m)")
    ax_err.legend(fontsize=7)
    ax_err.set_title(f"position error, {len(mcl['rows'])} odometry seeds", fontsize=9)
    fig.tight_layout()
    return save_figure(fig, figures / "mcl.png")


def _change_figure(change: dict, background: dict | None, figures: Path) -> Path:
    fig = new_figure(figsize=(13, 4.5), dpi=110)
    ax, ax_map = fig.subplots(1, 2)
    rows = change["rows"]
    colours = ["tab:green" if r["role"].startswith("static") else "tab:red" for r in rows]
    labels = [f"{r['run']}\n{'ref' if r['role'] == 'static, held out' else ''}" for r in rows]
    ax.bar(range(len(rows)), [100 * r["share"] for r in rows], color=colours)
    ax.set_xticks(range(len(rows)), labels)
    ax.axhline(100 * change["threshold"], color="k", ls="--", label="threshold")
    ax.set_xlabel("run (green: static field, red: shelves moved in; ref: held out in turn)")
    ax.set_ylabel("% of mapped readings beyond 3 sigma")
    ax.legend(fontsize=7)
    if background is not None:
        image, extent = _grid_image(background, "mean", 2)
        ax_map.imshow(image, origin="lower", extent=extent, cmap="Greys", alpha=0.5)
    for r in rows:
        if r["role"] == "static, held out":
            continue
        track = np.asarray(r["track"])
        line = ax_map.plot(track[:, 0], track[:, 1], "-", lw=0.5, label=f"run {r['run']}")
        if r["flagged"]:
            ax_map.plot(*np.asarray(r["flagged"]).T, "o", ms=2.5, color=line[0].get_color())
    ax_map.set_aspect("equal")
    ax_map.legend(fontsize=7)
    ax_map.set_title("tracks; dots: readings beyond 3 sigma", fontsize=9)
    fig.tight_layout()
    return save_figure(fig, figures / "change_detection.png")


def _walks_figure(walks: dict, figures: Path) -> Path:
    items = walks["walks"]
    fig = new_figure(figsize=(6.5 * len(items), 8), dpi=110)
    axes = np.atleast_2d(fig.subplots(2, len(items)).reshape(2, -1))
    for k, w in enumerate(items):
        ax, ax_t = axes[0, k], axes[1, k]
        image, extent = _grid_image(w["grid"], "mean", 2)
        shown = ax.imshow(image, origin="lower", extent=extent, cmap="RdBu_r")
        fig.colorbar(shown, ax=ax, shrink=0.8, label="mz (uT)")
        p, cut = np.asarray(w["positions"]), w["train"]
        ax.plot(p[:cut, 0], p[:cut, 1], "k-", lw=0.8, label="training part")
        ax.plot(p[cut:, 0], p[cut:, 1], "--", color="orange", lw=0.8, label="predicted part")
        ax.set_aspect("equal")
        ax.legend(fontsize=7)
        ax.set_title(f"{w['walk']}: 3-D map, slice at z = {w['slice_height']:.2f} m", fontsize=9)
        labels = [k for k in ("raw", "corrected") if k in w]
        label = min(labels, key=lambda k: sum(w[k]["score"]["rmse"]))  # the better of the two
        v = w[label]
        measured, predicted = np.asarray(v["measured"]), np.asarray(v["predicted"])
        sd = np.asarray(v["sd"])
        t = np.arange(len(measured))
        for c, colour in zip(range(3), ("tab:red", "tab:green", "tab:blue"), strict=True):
            ax_t.plot(t, measured[:, c], ".", ms=2, color=colour)
            ax_t.plot(t, predicted[:, c], "-", lw=0.8, color=colour, label=f"m{XYZ[c]}")
            ax_t.fill_between(
                t,
                predicted[:, c] - 2 * sd[:, c],
                predicted[:, c] + 2 * sd[:, c],
                color=colour,
                alpha=0.15,
            )
        ax_t.set_xlabel("sample of the predicted part (10 Hz)")
        ax_t.set_ylabel("uT")
        ax_t.legend(fontsize=7)
        ax_t.set_title(f"{w['walk']} ({label}): measured (dots), predicted +- 2 sigma", fontsize=9)
    fig.tight_layout()
    return save_figure(fig, figures / "walks_3d.png")


def draw_all(config, maps, change, mcl, walks, figures: Path) -> list[Path]:
    del config
    paths = [_map_figure(s, p, figures) for s, p in maps.items()]
    background = (maps.get("invensense") or {}).get("grid")
    if maps:
        paths += [_errors_figure(maps, figures), _sweep_figure(maps, figures)]
    if mcl is not None:
        paths.append(_mcl_figure(mcl, background, figures))
    if change is not None:
        paths.append(_change_figure(change, background, figures))
    if walks is not None:
        paths.append(_walks_figure(walks, figures))
    return paths
