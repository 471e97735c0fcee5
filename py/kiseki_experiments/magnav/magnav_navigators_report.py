# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnav-navigators' analysis: the per-navigator table, the evidence of the claims of sec.
4.5.2 (declared in magnav_navigators_claims), the r_z gate's validity share, and the figures
(trajectories of Fig. 4.9, cross-track error, priority history of Fig. 4.12)."""

from __future__ import annotations

import math
from pathlib import Path

import pandas as pd
from scipy.special import erfinv

from kiseki.magnetic.navigators import NAVIGATORS, RZ_MIN
from kiseki.plots import new_figure, save_figure
from kiseki_experiments.harness.base import Analysis
from kiseki_experiments.harness.records import unpack
from kiseki_experiments.magnav.magnav_navigators_claims import claim_evidence

__all__ = ["analyze_navigators", "required_noise"]

THESIS = {
    "odometry": "left the path after about 60 m (calibrated, not a result: the scene's slip)",
    "geometric": "left the path (area A: the heading reset failed there)",
    "magnetic": "(no figure of its own in the text)",
    "magnetic-geometric": "completed (text); left at the bicycle park (Fig. 4.11's text)",
    "multi": "completed, closest to the path",
}
COLOURS = {
    "odometry": "tab:brown",
    "geometric": "tab:green",
    "magnetic": "tab:blue",
    "magnetic-geometric": "tab:purple",
    "multi": "tab:red",
}


def required_noise(share: float, mean_count: float, gate: float = 1.0 - RZ_MIN) -> float:
    """The per-reading noise SD (G) at which the r_z gate passes ``share`` of the steps on
    noise alone, with nodes averaging ``mean_count`` readings (inverse of
    :func:`kiseki_experiments.magnav.magnav_navigators.closed_form_validity` at one count)."""
    return gate / (math.sqrt(2.0) * float(erfinv(share)) * math.sqrt(1.0 + 1.0 / mean_count))


def _worst_in(trials: pd.DataFrame, method: str, lo: float, hi: float) -> float:
    """The largest |cross-track| (m) between ``lo`` and ``hi`` m along, over the trials."""
    worst = float("nan")
    for text in trials[f"{method}:xte"]:
        a = unpack(text).reshape(-1, 2)
        inside = (a[:, 0] >= lo) & (a[:, 0] <= hi)
        if inside.any():
            worst = max(0.0 if math.isnan(worst) else worst, float(abs(a[inside, 1]).max()))
    return worst


def _table(config, trials: pd.DataFrame, methods) -> pd.DataFrame:
    rows = []
    for m in methods:
        leave = trials[f"{m}:leave_at"].astype(float)
        rows.append(
            {
                "navigator": m,
                "mean_abs_xte_m": float(trials[f"{m}:mean_xte"].mean()),
                "max_abs_xte_m": float(trials[f"{m}:max_xte"].mean()),
                "worst_xte_at_changed_park_m": _worst_in(
                    trials, m, config.changed_from, config.changed_to
                ),
                "left_path_runs": int(leave.notna().sum()),
                "left_at_m": float(leave.mean()) if leave.notna().any() else float("nan"),
                "completed_runs": int(trials[f"{m}:completed"].astype(bool).sum()),
                "reached_goal_runs": int(trials[f"{m}:reached_goal"].astype(bool).sum()),
                "travel_error_m": float(trials[f"{m}:travel_error"].mean()),
                "runs": len(trials),
                "thesis": THESIS[m],
            }
        )
    return pd.DataFrame(rows)


def _validity_table(trials: pd.DataFrame, noise_sd: float) -> pd.DataFrame:
    keys = [c.split(":", 1)[1] for c in trials.columns if c.startswith("multi:valid_")]
    row = {k: float(trials[f"multi:{k}"].mean()) for k in keys}
    row["closed_form_quiet"] = float(trials["multi:closed_form_quiet"].mean())
    count = float(trials["multi:mean_node_count"].mean())
    row["mean_readings_per_node"] = count
    row["sensor_noise_sd_G"] = noise_sd
    row["noise_sd_for_90pct_valid_G"] = required_noise(0.9, count)
    row["noise_sd_for_50pct_valid_G"] = required_noise(0.5, count)
    for n in NAVIGATORS:
        row[f"drove_{n}"] = float(trials[f"multi:drove_{n}"].mean())
    return pd.DataFrame([row])


def _plot_paths(config, trials, methods, figures: Path) -> Path:
    row = trials.iloc[0]
    fig = new_figure(figsize=(9, 6.5), dpi=120)
    axes = fig.subplots(3, 1, sharex=True)
    for m in methods:
        xy = unpack(row[f"{m}:xy"]).reshape(-1, 2)
        xte = unpack(row[f"{m}:xte"]).reshape(-1, 2)
        axes[0].plot(xy[:, 0], xy[:, 1], color=COLOURS[m], lw=1, label=m)
        axes[1].plot(xte[:, 0], xte[:, 1], color=COLOURS[m], lw=1, label=m)
    axes[0].axhline(0, color="k", lw=0.6, ls="--", label="taught route")
    for ax in axes[:2]:
        ax.axvspan(config.changed_from, config.changed_to, color="tab:orange", alpha=0.2)
        ax.axvspan(config.landmark_free_from, config.landmark_free_to, color="grey", alpha=0.1)
    for s in (-1, 1):
        axes[1].axhline(s * config.leave_xte, color="k", lw=0.6, ls=":")
    axes[0].set_ylabel("y (m)")
    axes[0].set_title(
        f"Fig. 4.9: trajectories (trial {int(row['trial'])}); orange: bicycle park changed, "
        "grey: no landmarks",
        fontsize=9,
    )
    axes[0].legend(fontsize=6, ncol=3)
    axes[1].set_ylabel("cross-track (m, left +)")
    names = str(row["multi:navigators"]).split(",")
    pri = unpack(row["multi:priorities"]).reshape(-1, 1 + len(names))
    for j, n in enumerate(names):
        axes[2].step(pri[:, 0], pri[:, 1 + j], where="post", color=COLOURS[n], lw=0.8, label=n)
    axes[2].set_ylabel("priority (0: invalid)")
    axes[2].set_xlabel("true distance along the route (m)")
    axes[2].set_title("Fig. 4.12: priorities of the multi-navigator system", fontsize=9)
    axes[2].legend(fontsize=6, ncol=4)
    fig.tight_layout()
    return save_figure(fig, figures / "magnav_navigators.png")


def analyze_navigators(config, trials, figures: Path, methods, noise_sd: float) -> Analysis:
    ok = trials[trials["error"].isna()].reset_index(drop=True)
    table = _table(config, ok, methods)
    valid = _validity_table(ok, noise_sd)
    figs = [_plot_paths(config, ok, methods, figures)] if len(ok) else []
    return Analysis(
        tables={"navigators": table, "validity": valid},
        figures=figs,
        notes=_notes(config, valid),
        evidence=claim_evidence(config, ok),
    )


def _notes(config, valid: pd.DataFrame) -> str:
    v = valid.iloc[0]
    return f"""
Why the magnetic navigators are rarely valid. Sec. 4.3.2 disables them when r_z = 1 -
|m_z,n - m_z,t| / 1 G < {RZ_MIN}, i.e. when the reading's mz differs from the node's by more than
{1 - RZ_MIN:.3f} G. The thesis' sensor (MicroStrain 3DM-DH) has an SD of about 0.01 G (sec.
6.3.2), the simulated one {v["sensor_noise_sd_G"]:g} G per axis. The map averages the readings of
each 0.1 m node (sec. 3.3.2: "when several readings fall in 10 cm, their mean is recorded"; 10 Hz
at 0.6 m/s gives {v["mean_readings_per_node"]:.2f} readings per node here); the reading during
playback is a single one (m_t of eq. 4.5), so the difference has SD 0.01 sqrt(1 + 1/c) G and the
gate passes erf(0.002 / (sqrt 2 SD)) of the steps on noise alone: {v["closed_form_quiet"]:.3f}
over the undisturbed nodes, measured {v["valid_magnetic_quiet"]:.3f} there
({v["valid_magnetic"]:.3f} over the whole run; at the disturbances
{v["valid_magnetic_disturbed"]:.3f}).
For the gate to pass 90 % of the undisturbed steps the sensor's noise would have to be
{v["noise_sd_for_90pct_valid_G"]:.5f} G per reading (50 %: {v["noise_sd_for_50pct_valid_G"]:.5f}
G), about a tenth of the 0.01 G the thesis states for its sensor; so either its playback readings
were averaged over many samples (not said), or its r_z was computed on smoothed values, or the
threshold in the text is not the one it ran. The gate and the scene are left as the thesis and
the issue give them (not tuned to make a claim hold).

Consequences. The multi-navigator system is steered by the odometry navigator most of the time
(drove_* columns of the validity table) and by the geometric one where buildings are in sight;
the magnetic navigators drive in short bursts. Alone, a navigator drives whatever its validity,
so the magnetic navigators alone steer by the field's azimuth at every step, while the
multi-navigator system hands the steering to the odometry navigator whenever the gate fails: it
then follows the path about as closely as the navigators it hands over to (table navigators),
not clearly better as in the thesis, whose ranking needs the magnetic navigators valid most of
the time. At the disturbances the gate passes about as often as elsewhere (validity table): the
noise already fails it 88 % of the time, so the disturbances cannot lower it visibly.

The odometry navigator runs on the odometry's travel distance (navigate()'s default); the others
on the travel-distance filter with the azimuth heading reset of sec. 4.4.2 (gates 0.992 and
0.990: r_z >= 0.992 allows 0.008 G, which noise passes {_share(0.008, v):.0%} of the time). The
odometry navigator steers to the taught heading theta_n, itself the teaching run's odometry: the
same tyres curve both runs alike (scene header: 2e-4 rad/m), so that drift cancels and only the
wheel slip's random walk and the 0.5 deg start error remain; the robot wanders 0.5-1.2 m off the
path in the landmark-free stretch and crosses 2 m late or not at all (the scene header's "1.2 m
after 60 m" is for a robot steered on its odometry pose, not against taught headings). The
geometric navigator alone is pushed by the rearranged bicycle rows (column
worst_xte_at_changed_park_m) but not past {config.leave_xte:g} m: the g terms weigh 0.3 rad/m and
the rows' near ends moved about 0.5 m away (1.6 -> 2.1 m from the path) and along it.
"Leaving the path": |cross-track| > {config.leave_xte:g} m (the thesis gives no figure). Each
trial teaches once and plays every method back with the same seed.
"""


def _share(gate: float, v) -> float:
    sd = v["sensor_noise_sd_G"] * math.sqrt(1.0 + 1.0 / v["mean_readings_per_node"])
    return math.erf(gate / (math.sqrt(2.0) * sd))
