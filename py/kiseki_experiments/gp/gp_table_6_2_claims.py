# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-table-6-2's claims, declared before the run, and their per-trial evidence. Each trial is
one seed of the sensor's noise over the whole protocol (every spacing), so a claim about how the
error changes with the spacing has one value per trial.

Not claims: the training counts and the length scale (the hall was built to give them: the
scene's ``calibrated`` marks; gp_table_6_2.calibrated shows them), and "every spacing's error
SD exceeds the sensor's 0.01 G" (no control fails it: a constant map's errors are larger still;
table_6_2's sd_err_G shows it)."""

from __future__ import annotations

import pandas as pd

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

__all__ = ["CLAIMS", "GROWTH_MARGIN", "evidence"]

#: G: the smallest rise of the mean error from the closest to the widest spacing claimed, a
#: quarter of the thesis' rise from 0.4 to 1.0 m (0.01440 - 0.00648 = 0.0079 G)
GROWTH_MARGIN = 0.002
#: share of noise seeds in which the "<= 0.6 m suffices" pattern must show
SUFFICES_SHARE = 0.5

CONSTANT = Control(
    name="the GP replaced by a constant map (the training points' mean magnitude)",
    overrides=("model=constant",),
    runs=5,
    why="a constant map's error is the field's spread about its mean at every spacing: it "
    "neither grows with the spacing nor shows a step beyond 0.6 m",
)

CLAIMS = (
    ClaimSpec(
        key="grows",
        claim="the mean error grows with the spacing (Table 6.2): widest minus closest spacing",
        unit="G, mean |m error| at 1.0 m minus at 0.4 m",
        criterion=Criterion(
            paper_value="0.01440 - 0.00648 = 0.0079",
            compare=">=",
            threshold=GROWTH_MARGIN,
            why="a quarter of the thesis' rise from 0.4 to 1.0 m",
        ),
        control=CONSTANT,
        measure="one noise seed's mean |m error| at the widest spacing minus at the closest",
    ),
    ClaimSpec(
        key="suffices",
        claim="spacing <= 0.6 m suffices: SD(0.6) close to SD(0.4), SD(0.8) and SD(1.0) "
        "clearly above it (sec. 6.3.2), in most noise seeds",
        unit="share of noise seeds",
        criterion=Criterion(
            paper_value=f"SD ratios 0.6/0.4 = {0.01303 / 0.01205:.2f}, min(0.8, 1.0)/0.6 = "
            f"{0.01838 / 0.01303:.2f}",
            compare=">=",
            threshold=SUFFICES_SHARE,
            why="the thesis shows the pattern in its one survey; kiseki asks it of most noise "
            "draws (ratios within / beyond 1 + suffices_margin)",
            bounds=(0.0, 1.0),
        ),
        control=CONSTANT,
        measure="1 if SD(0.6)/SD(0.4) <= 1 + margin and min(SD(0.8), SD(1.0))/SD(0.6) >= "
        "1 + margin",
    ),
)


def evidence(config, rows: pd.DataFrame) -> list[Evidence]:
    """rows: one per (trial, spacing) with mean_err and sd_err."""
    out = []
    per = rows.assign(spacing=rows["spacing_m"].round(1)).pivot_table(
        index="trial", columns="spacing", values=["mean_err", "sd_err"]
    )
    spacings = sorted(per["mean_err"].columns)
    if len(spacings) >= 2:
        rise = per["mean_err"][spacings[-1]] - per["mean_err"][spacings[0]]
        out.append(
            Evidence.of(
                "grows",
                rise,
                shown=f"{spacings[0]:g} to {spacings[-1]:g} m",
            )
        )
    if {0.4, 0.6, 0.8, 1.0} <= set(spacings):
        sd = per["sd_err"]
        m = config.suffices_margin
        near = sd[0.6] / sd[0.4]
        far = sd[[0.8, 1.0]].min(axis=1) / sd[0.6]
        shows = (near <= 1 + m) & (far >= 1 + m)
        out.append(
            Evidence.share(
                "suffices",
                int(shows.sum()),
                len(shows),
                shown=f"ratios {near.mean():.2f}, {far.mean():.2f} (means over seeds)",
            )
        )
    return out
