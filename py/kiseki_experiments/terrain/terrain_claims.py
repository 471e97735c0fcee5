# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the rubble experiments claim (paper 003), declared before any run: each claim's
criterion (the paper's value, the comparison, the threshold and why) and its control, a config
override under which the criterion must fail (kiseki_experiments.harness.verdict). The analyses
(terrain_envs, terrain_corridor, terrain_global_map) hand over the per-seed evidence; claims
made for each cost of eq. 4 carry the cost as their subject ("eq. 4 (sum)", the paper's, and
"kiseki (mean cost)")."""

from __future__ import annotations

import numpy as np

from kiseki_experiments.harness.paths import WORLDS
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion

__all__ = [
    "CLAIMS_A",
    "CLAIMS_B",
    "CLAIMS_CORRIDOR",
    "CLAIMS_GLOBAL_MAP",
    "LARGE",
    "TOLERANCE",
]

TRUTH_CM = (35.0, 30.0, 5.0)  # sec. 7.3: the true motion in both environments
PAPER_A_CM = (32.0, 26.0, 6.0)  # the paper's estimate in environment A (a success)
PAPER_B_CM = (44.0, -26.0, 20.0)  # and in environment B (a failure)
TOLERANCE = float(np.linalg.norm(np.subtract(PAPER_A_CM, TRUTH_CM))) / 100 + 1e-9
"""m: "found" means no further from the truth than the paper's own success in A (5.10 cm).
The search's 2 cm grid makes the errors discrete (... 4.69, 5.10, 5.48 ... cm against the
paper's odd-centimetre truth), so a round 5 cm would call the paper's own A a failure."""
PAPER_B_ERROR_CM = float(np.linalg.norm(np.subtract(PAPER_B_CM, TRUTH_CM)))
LARGE = 0.05  # m: an along-track error above 5 cm (A's tolerance, rounded) is "large"
MOST = "more than half of the seeds: the median seed decides, as in the paper's one trial"

# A 10 cm grid has no candidate within 5.10 cm of (35, 30, 5) cm: the nearest is 7.07 cm off
COARSE = Control(
    name="the search grid coarsened to 10 cm (no candidate within the tolerance)",
    overrides=("step=0.1", "removals=none", "exact_gyro_rows=false", "variant_costs=mean"),
    runs=5,
    why="every estimate is at least 7.07 cm off: 0 of 5 within, Wilson 95 % upper 43 %",
)

# the contrast taken against B itself: every paired difference is 0 cm (PCL's share of B found
# is a table row, terrain-env-b's summary: its control would need PCL's slow RANSAC)
B_CONTROL = Control(
    name="B's move taken against itself (contrast_env=B)",
    overrides=("contrast_env=B", "step=0.1", "removals=none", "exact_gyro_rows=false",
               "label_objects=false", "variant_costs=mean"),
    runs=5,
    why="the same sweeps and search on both sides make every difference 0 cm",
)  # fmt: skip

CLAIMS_A = (
    ClaimSpec(
        key="found",
        claim="environment A: the paper's method (Hough removal, exhaustive search) finds the "
        "move within the paper's own A error (5.10 cm) in most seeds",
        unit="share of seeds",
        criterion=Criterion(
            paper_value="(32, 26, 6) cm against (35, 30, 5): 5.10 cm off (a success)",
            compare=">=",
            threshold=0.5,
            why=MOST,
            bounds=(0.0, 1.0),
        ),
        control=COARSE,
        measure="1 if the estimate lies within 5.10 cm of the true move",
    ),
)

CLAIMS_B = (
    ClaimSpec(
        key="harder",
        claim="environment B is harder than A for the paper's method: on the same seed, B's "
        "error exceeds A's by more than A's tolerance (5.10 cm)",
        unit="cm (median of paired differences)",
        criterion=Criterion(
            paper_value=f"B {PAPER_B_ERROR_CM:.1f} cm off vs A 5.1 cm: "
            f"{PAPER_B_ERROR_CM - 100 * TOLERANCE:.1f} cm more",
            compare=">=",
            threshold=round(100 * TOLERANCE, 2),
            why="the paper's contrast (A found, B not) needs B worse than A by more than the "
            "error the paper calls a success in A",
            paper_number=round(PAPER_B_ERROR_CM - 100 * TOLERANCE, 1),
        ),
        control=B_CONTROL,
        measure="B's error minus A's error (cm), the same seed, the paper's removal",
    ),
)


CLAIMS_CORRIDOR = (
    ClaimSpec(
        key="none_large",
        claim="without plane removal the error along the travel direction is large (above "
        "5 cm) in most seeds in a narrow flat-walled corridor",
        unit="share of seeds",
        criterion=Criterion(
            paper_value="large along-track error (sec. 3; no figure given)",
            compare=">=",
            threshold=0.5,
            why=MOST + "; 5 cm is A's tolerance rounded",
            bounds=(0.0, 1.0),
        ),
        control=Control(
            name="the flat-walled corridor replaced by environment A's room (the same level "
            "35 cm move)",
            overrides=(
                f"scene={WORLDS / 'rubble_a.yaml'}",
                "removals=none",
                "exact_gyro_rows=false",
                "variant_costs=sum",
                "search=coarse-to-fine",
            ),
            runs=10,
            why="without walls running along the move, the ranges change with the move in "
            "every direction and the along-track position is fixed",
        ),  # fmt: skip
        measure="1 if |x estimate - x true| > 5 cm without removal",
    ),
)

CLAIMS_GLOBAL_MAP = (
    ClaimSpec(
        key="drift",
        claim="the loop of local maps, searches and merges keeps the final position error "
        "below 10 % of the distance travelled",
        unit="final error / distance",
        criterion=Criterion(
            paper_value="Fig. 1's loop; no multi-move error figure",
            compare="<=",
            threshold=0.10,
            why="kiseki's criterion (the paper gives none): a tenth of the distance, the drift "
            "of wheel odometry on rough ground",
            bounds=(0.0, float("inf")),
        ),
        control=Control(
            name="the correlation search replaced by no motion estimate (motion=zero)",
            overrides=("motion=zero", "moves=2"),
            runs=5,
            why="every move estimated as zero: the final error is the straight distance "
            "from the start, about the distance travelled",
        ),
        measure="the final error over the distance travelled, per seed",
    ),
)
