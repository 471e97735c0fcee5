# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnav-table-4-2's figures: the travel-distance error along the path (Fig. 4.6) and the ESS
along it with the changed places marked (Fig. 4.7)."""

from __future__ import annotations

from pathlib import Path

from kiseki.plots import new_figure, save_figure
from kiseki_experiments.harness.records import unpack

__all__ = ["CASES", "plot_errors", "plot_ess"]

CASES = {"none": "without localization", "static": "static field", "dynamic": "time-varying field"}


def _mark(ax, stretches, window: float) -> None:
    for k, (a, b) in enumerate(stretches):
        ax.axvspan(a, b, color="tab:orange", alpha=0.3, label="field changed" if k == 0 else None)
        ax.axvspan(b, b + window, color="tab:orange", alpha=0.1)


def plot_errors(row, stretches, figures: Path) -> Path:
    fig = new_figure(figsize=(8, 3.4), dpi=120)
    ax = fig.subplots()
    along = unpack(row["along_static"])
    colours = {"none": "tab:brown", "static": "tab:red", "dynamic": "tab:blue"}
    for case, label in CASES.items():
        x = unpack(row["along_dynamic"]) if case == "dynamic" else along
        ax.plot(x, unpack(row[f"error_{case}"]), color=colours[case], lw=1, label=label)
    _mark(ax, stretches, 0.0)
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_xlabel("true travel distance (m)")
    ax.set_ylabel("estimate - truth (m)")
    ax.set_title(f"Fig. 4.6: travel-distance error (trial {int(row['trial'])})", fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return save_figure(fig, figures / "magnav_fig_4_6_errors.png")


def plot_ess(row, config, stretches, figures: Path) -> Path:
    fig = new_figure(figsize=(8, 3.4), dpi=120)
    ax = fig.subplots()
    for case, colour in (("static", "tab:red"), ("dynamic", "tab:blue")):
        ax.plot(
            unpack(row[f"along_{case}"]),
            unpack(row[f"ess_{case}"]),
            color=colour,
            lw=0.8,
            label=CASES[case],
        )
    _mark(ax, stretches, config.window)
    ax.axhline(0.9, color="k", lw=0.8, ls="--", label="resampling below 9n/10")
    ax.set_xlabel("true travel distance (m)")
    ax.set_ylabel("ESS / n")
    ax.set_title(
        f"Fig. 4.7: ESS, {config.particles} particles (trial {int(row['trial'])}; shaded: the "
        f"changed field and the {config.window:g} m window after it)",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    return save_figure(fig, figures / "magnav_fig_4_7_ess.png")
