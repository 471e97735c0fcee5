# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnav-fig-5-4's figures (Figs. 5.4-5.6) and its notes; its claims are in
magnav_fig_5_4_claims."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.plots import new_figure, save_figure
from kiseki_experiments.harness.records import unpack
from kiseki_experiments.magnav.magnav_fig_5_4_claims import OFF_PATH

__all__ = ["NOTES", "figures"]

LABELS = {"odometry": "odometry", "laser": "LIDAR MCL", "magnetic": "LIDAR MCL + magnetic heading"}
COLOURS = {"odometry": "k", "laser": "tab:orange", "magnetic": "tab:blue"}


def figures(ok: pd.DataFrame, out: Path) -> list[Path]:
    first = ok.iloc[0]
    lo, hi = float(first["blind_lo"]), float(first["blind_hi"])
    paths = []
    fig = new_figure(figsize=(11, 6.5), dpi=110)
    top, bottom = fig.subplots(2, 1, sharex=True)
    for m, colour in COLOURS.items():
        truth = unpack(first[f"{m}_truth"])
        top.plot(truth[:, 0], truth[:, 1], color=colour, lw=1.3, label=LABELS[m])
        for i, (_, run) in enumerate(ok.iterrows()):
            t = unpack(run[f"{m}_truth"])
            bottom.plot(t[:, 0], np.abs(t[:, 1]), color=colour, lw=0.9, alpha=1 if i == 0 else 0.4)
    for ax in (top, bottom):
        ax.axvspan(lo, hi, color="0.9", zorder=0)
    top.axhline(0.0, color="0.5", ls=":", lw=0.8)
    top.set_ylabel("true y (m)")
    top.legend(fontsize=8)
    top.set_title(
        f"Fig. 5.4: true trajectories (grey: no laser landmark), run {first['trial']}", fontsize=10
    )
    bottom.axhline(OFF_PATH, color="r", ls=":", lw=0.8)
    bottom.set_xlabel("x (m)")
    bottom.set_ylabel("|cross-track| (m)")
    bottom.set_title(f"every run ({len(ok)})", fontsize=9)
    paths.append(save_figure(fig, out / "magnav_fig_5_4_trajectories.png"))

    fig = new_figure(figsize=(11, 3.5), dpi=110)
    ax = fig.subplots()
    t, r = unpack(first["magnetic_truth"]), unpack(first["magnetic_r"])
    ax.plot(t[:, 0], r[:, 0], ".", ms=2, label="r_z (eq. 4.5)")
    ax.plot(t[:, 0], r[:, 1], ".", ms=2, label="r_theta (eq. 4.13)")
    ax.axhline(0.992, color="tab:blue", ls=":", lw=0.8)
    ax.axhline(0.990, color="tab:orange", ls=":", lw=0.8)
    ax.set_ylim(0.97, 1.0005)
    ax.set_xlabel("x (m)")
    ax.legend(fontsize=8)
    ax.set_title(
        "Fig. 5.5: r_z and r_theta of the proposed method (thresholds dotted)", fontsize=10
    )
    paths.append(save_figure(fig, out / "magnav_fig_5_5_gates.png"))

    fig = new_figure(figsize=(11, 7), dpi=110)
    axes = fig.subplots(3, 1, sharex=True)
    for m in ("laser", "magnetic"):
        t, sd = unpack(first[f"{m}_truth"]), unpack(first[f"{m}_sd"])
        for k, (ax, name) in enumerate(zip(axes, ("x (m)", "y (m)", "theta (rad)"), strict=True)):
            ax.semilogy(t[:, 0], np.maximum(sd[:, k], 1e-4), color=COLOURS[m], label=LABELS[m])
            ax.set_ylabel(f"SD {name}")
            ax.axvspan(lo, hi, color="0.9", zorder=0)
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("x (m)")
    axes[0].set_title("Fig. 5.6: SD of the particles", fontsize=10)
    paths.append(save_figure(fig, out / "magnav_fig_5_6_sd.png"))
    return paths


NOTES = """
Scene: data/worlds/magnetic_lidar_path.yaml (its header states the geometry, the pipes and the
odometry; tests/python/sim/test_sim_magnetic_lidar_path.py measures them). The laser is 180 deg /
30 m as in sec. 5.3; the odometry is magnetic_path.yaml's outdoor robot, the same for every
method. The magnetic map is the taught route's linear map (0.1 m nodes) looked up by position
(kiseki.magnetic.lidar_mcl: the thesis' 2-D grid holds values only along the taught path, sec.
5.2.2), recorded with the mapping run's true poses. sigma_theta = 1 deg (the thesis prints
"sigma_theta^2 = 1 deg"). sigma_d, the particle count, the beams weighed and the motion noise
are not in the thesis: 0.2 m, 300, 60 of 181, and the engine's AMCL-like alphas, the same for
both MCLs. "Stays on the path" and "leaves the path" use 1 m of cross-track error (our reading).

Why the heading reset does not remove every cross-track error: it sets the heading from one
reading, whose azimuth carries the magnetometer's 0.01 G noise (1.9 deg on the 0.30 G horizontal
field) and the map node's (about 1.4 deg, 1-2 readings per node), and the r_theta gate (1.8 deg)
compares the reading with the map at the predicted heading, so a heading already wrong by more
than the gate is not corrected. Near a pipe the field's azimuth turns by several degrees per
metre, so the along-track error the laser cannot see in the stretch turns into a heading bias
there. The mean heading error over the stretch (summary: blind_heading_err_deg) is therefore
no smaller with the reset than without (4 seeds: 1.57 deg against 1.17 deg LIDAR-only, 1.58 deg
odometry); what differs is its kind: the reset's error is renewed at every reset (21 % of the
steps) and changes sign along the path (each pipe bends the field one way, then the
other), the odometry's persists and integrates into cross-track error, so
the stretch ends nearer the path with the reset (0.43 against 1.32 m, 3 of 4 runs) while in a
run whose odometry happens to drift little (trial 0: at most 0.15 m in the stretch LIDAR-only)
the reset's noise is the
larger error (0.67 m). The reset's clear effect is on the particles' spread (Fig. 5.6), as the
thesis says.

LIDAR-only runs that miss the goal: when the goal building's front comes into view (x = 29.6 m)
the cloud is about 13 m wide in y and 11 deg in theta (Fig. 5.6), 300 particles leave few near
the true pose, and the first scans of the front at 26-30 m collapse it onto a wrong y that the
robot then steers by (up to 12 m off). The thesis' LIDAR-only run reached the goal; it names no
recovery for such a failure (sec. 5.5.1 points to sensor and expansion resetting), and none is
used here for either MCL. The corrected cloud (0.2 m in y) re-locks on the front every time.
The runs do not check collisions (a run 12 m off the route passes beside the building).
"""
