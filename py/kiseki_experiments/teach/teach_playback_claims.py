# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What exp1-corridor, exp2-turn and exp3-boxes claim of the teaching-and-playback thesis
(sec. 4, Tables 4.1-4.7), declared before any run with each claim's criterion and its control
(kiseki_experiments.harness.verdict), the thesis' numbers they cite, and their evidence from the
trials' records (one value per run: a teaching and its playbacks on one seed)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

__all__ = [
    "ALL_CONVENTIONAL",
    "DEAD_RECKONING",
    "EXP1_CLAIMS",
    "EXP2_CLAIMS",
    "EXP3_CLAIMS",
    "STOP_TOLERANCE_M",
    "THESIS_ODOMETRY_P2_M",
    "THESIS_ODOMETRY_Y_WORST_M",
    "THESIS_RUNS",
    "THESIS_TABLE_4_5",
    "THESIS_TABLE_4_7",
    "exp2_evidence",
    "exp3_evidence",
]

THESIS_ODOMETRY_Y_WORST_M = -0.49  # thesis sec. 4 Exp. 1: the largest odometry y error at P2
THESIS_ODOMETRY_P2_M = (0.01, -0.20)  # thesis Tables 4.1-4.4: mean odometry error at P2 (x, y)
# Exp. 1's control: one particle, on which the space observation model's weights change
# nothing (resampling one particle keeps it): dead reckoning with the motion model's noise
DEAD_RECKONING = Control(
    name="one particle (the space observation update has no effect: dead reckoning)",
    overrides=("particles=1",),
    runs=5,
    why="without the update the estimate drifts with the odometry: the stops miss P2",
    # 5 playbacks of the corridor: 18 s beside another test (47 s before the tiled depth cast)
)
EXP1_CLAIMS = (
    ClaimSpec(
        key="exp1_within",
        claim="the stops at P2 are within 0.1 m (share of runs)",
        unit="share of runs",
        criterion=Criterion(
            paper_value="11/11",
            compare=">=",
            threshold=0.7,
            why="the thesis' 11 of 11 have a 95 % Wilson interval from 0.74: a share of at "
            "least 0.7 is what its runs show",
            bounds=(0.0, 1.0),
            paper_number=1.0,
        ),
        control=DEAD_RECKONING,
        measure="1 if the robot came to rest within 0.1 m of where P2 was taught",
    ),
)


THESIS_TABLE_4_5 = {  # thesis Table 4.5, 5 runs each: stop error mean, SD, estimate, within 0.1 m
    "conventional": (0.13, 0.01, 0.13, 0),
    "proposal1": (0.09, 0.01, 0.08, 4),
    "proposal2": (0.07, 0.01, 0.05, 5),
}
THESIS_RUNS = 5
STOP_TOLERANCE_M = 0.1  # the thesis' stop rule (sec. 2.2)


# Exp. 2's claims: the thesis' findings (Table 4.5, 5 runs per method) as comparisons between
# methods on the same teaching and seeds, one paired value per run. Their control plays every
# method as conventional: each difference is then 0, a margin away from each criterion.
ALL_CONVENTIONAL = Control(
    name="proposals 1 and 2 played as conventional",
    overrides=(
        "plays=proposal1=conventional,proposal2=conventional",
        "methods=conventional,proposal1,proposal2",
        "particles=50",  # the control's trials are test time; the differences are 0 at any
    ),
    runs=5,
    why="every method is conventional's run on the same seed: every difference is 0",
    # a teaching and 15 playbacks of the turn route: 25 s beside another test
)
WITHIN_MARGIN = 0.2  # one run in five more within 0.1 m
WITHIN_WHY = (
    f"one run in {THESIS_RUNS} (the thesis' runs per method) more within 0.1 m; a difference of "
    "shares from paired runs"
)
FARTHER_MARGIN = 0.01  # m
FARTHER_WHY = (
    "the thesis' stop errors have an SD of 0.01 m for every method (Table 4.5): a difference "
    "of one SD; paired runs"
)
WITHIN_PAIRS = (("proposal2", "conventional"), ("proposal1", "conventional"))
FARTHER_PAIRS = (
    ("conventional", "proposal2"),
    ("conventional", "proposal1"),
    ("proposal1", "proposal2"),
)


def _within_claim(better: str, worse: str) -> ClaimSpec:
    b, w = THESIS_TABLE_4_5[better][3], THESIS_TABLE_4_5[worse][3]
    return ClaimSpec(
        key=f"within_{better}_vs_{worse}",
        claim=f"{better} stops within 0.1 m in more runs than {worse}: {better}'s share "
        f"minus {worse}'s",
        unit="difference of shares of runs",
        criterion=Criterion(
            paper_value=f"{b}/{THESIS_RUNS} vs {w}/{THESIS_RUNS} ({(b - w) / THESIS_RUNS:+.1f})",
            compare=">=",
            threshold=WITHIN_MARGIN,
            why=WITHIN_WHY,
            bounds=(-1.0, 1.0),
            paper_number=(b - w) / THESIS_RUNS,
        ),
        control=ALL_CONVENTIONAL,
        measure=f"1 if {better} stopped within 0.1 m, minus the same for {worse}",
    )


def _farther_claim(farther: str, nearer: str) -> ClaimSpec:
    f, n = THESIS_TABLE_4_5[farther][0], THESIS_TABLE_4_5[nearer][0]
    return ClaimSpec(
        key=f"farther_{farther}_than_{nearer}",
        claim=f"{farther} stops farther from the goal than {nearer}: mean stop error difference",
        unit="m",
        criterion=Criterion(
            paper_value=f"{f:.2f} - {n:.2f} = {f - n:+.2f}",
            compare=">=",
            threshold=FARTHER_MARGIN,
            why=FARTHER_WHY,
            paper_number=round(f - n, 2),
        ),
        control=ALL_CONVENTIONAL,
        measure=f"{farther}'s stop error minus {nearer}'s",
    )


EXP2_CLAIMS = (
    *(_within_claim(b, w) for b, w in WITHIN_PAIRS),
    *(_farther_claim(f, n) for f, n in FARTHER_PAIRS),
)


def exp2_evidence(ok: pd.DataFrame, methods) -> list[Evidence]:
    """Exp. 2's evidence: per run, the paired differences between methods."""
    evidence = []
    for better, worse in WITHIN_PAIRS:
        if better in methods and worse in methods:
            a = (ok[f"{better}_stop_error"] <= STOP_TOLERANCE_M).astype(float)
            b = (ok[f"{worse}_stop_error"] <= STOP_TOLERANCE_M).astype(float)
            shown = f"{int(a.sum())}/{len(a)} vs {int(b.sum())}/{len(b)}"
            evidence.append(Evidence.of(f"within_{better}_vs_{worse}", a - b, shown=shown))
    for farther, nearer in FARTHER_PAIRS:
        if farther in methods and nearer in methods:
            a, b = ok[f"{farther}_stop_error"], ok[f"{nearer}_stop_error"]
            shown = f"{a.mean():.3f} - {b.mean():.3f} m"
            evidence.append(Evidence.of(f"farther_{farther}_than_{nearer}", a - b, shown=shown))
    return evidence


RAY_CLAIM = (
    ClaimSpec(
        key="ray-stop-within",
        claim="with unknown boxes, kiseki's ray space observation model stops the robot as "
        "closely as the thesis' model (mean stop error within 0.02 m, same runs)",
        unit="m, stop error of kiseki's model minus the thesis' (same teaching, boxes, seeds)",
        criterion=Criterion(
            paper_value="(kiseki's model; the thesis' model reaches 0.07 m, SD 0.02, Table 4.7)",
            compare="within",
            threshold=0.0,
            tolerance=0.02,
            why="the issue's target: the thesis' stop error's SD (0.02 m, Table 4.7) is the "
            "difference no run could tell apart",
            bounds=(-math.inf, math.inf),
        ),
        control=Control(
            name="kiseki's model with every reading 20 % long (a miscalibrated range)",
            overrides=("ray=true", "ray_range_scale=1.2"),
            runs=5,
            why="walls read 20 % further away than they are pull every estimate along the "
            "route, and the stop with it, far beyond 0.02 m",
            minutes=True,
        ),
        measure="a run's stop error with kiseki's model minus the thesis' model's",
    ),
)[0]


THESIS_TABLE_4_7 = {"proposal2": (0.07, 0.02, 0.06)}  # stop error mean, SD, estimate error mean
# Exp. 3's control: one particle on the turn route with the boxes, as Exp. 1's (dead
# reckoning: the space observation update changes nothing)
BOXES_DEAD_RECKONING = Control(
    name="one particle (the space observation update has no effect: dead reckoning)",
    # the runs without the boxes feed a table, not these claims: not played
    overrides=("particles=1", "without_boxes=false"),
    runs=10,
    why="without the update the estimate drifts with the odometry around the turn: the stop "
    "and the estimate miss the goal by far more than the thesis' SD",
    # a teaching and 10 playbacks of the turn route with the boxes (25 s). 5 decided both claims
    # while the robot drove through what it met; since a contact ends a run, a lost robot's run
    # can end early against an obstacle (4 of 10 here), with a smaller estimate error, and
    # the estimate errors spread more (SD 0.14 m): 5 runs left the estimate claim undecided
    # (0.184 [0.077, 0.292] m against 0.08), 10 decide it (0.241 [0.164, 0.324] m)
)


def _boxes_claim(key: str, what: str, thesis: float, column: str) -> ClaimSpec:
    sd = THESIS_TABLE_4_7["proposal2"][1]
    return ClaimSpec(
        key=key,
        claim=f"proposal 2 with unknown boxes: {what} mean at most the thesis' plus its SD",
        unit="m",
        criterion=Criterion(
            paper_value=f"{thesis:.2f} (SD {sd:.2f}, Table 4.7)",
            compare="<=",
            threshold=round(thesis + sd, 2),
            why=f"the thesis' {thesis:.2f} m plus the SD of its stop errors ({sd:.2f} m, "
            f"{THESIS_RUNS} runs): as close as its runs tell apart; the mean over runs",
            bounds=(0.0, math.inf),
            paper_number=thesis,
        ),
        control=BOXES_DEAD_RECKONING,
        measure=f"a run's {column.replace('_', ' ')} (proposal 2, three boxes)",
    )


EXP3_CLAIMS = (
    _boxes_claim("boxes_stop", "stop error", THESIS_TABLE_4_7["proposal2"][0], "stop_error"),
    _boxes_claim(
        "boxes_estimate", "estimate error", THESIS_TABLE_4_7["proposal2"][2], "estimate_error"
    ),
    RAY_CLAIM,
)


def exp3_evidence(ok: pd.DataFrame, methods) -> list[Evidence]:
    """Exp. 3's evidence: proposal 2's stop and estimate errors per run (when it played), and
    with ``ray`` kiseki's model's stop error minus the thesis' model's, per run."""
    evidence = []
    if "proposal2" in methods and "proposal2_stop_error" in ok:
        for key, column in (("boxes_stop", "stop_error"), ("boxes_estimate", "estimate_error")):
            v = ok[f"proposal2_{column}"]
            kept = v[np.isfinite(v)]  # a refused route (layouts-exp2-exp3) never stopped: inf
            shown = f"SD {kept.std(ddof=1):.3f} m" + (
                f", {len(v) - len(kept)} run(s) refused" if len(kept) < len(v) else ""
            )
            evidence.append(Evidence.of(key, v, shown=shown))
    m = list(methods)[0]
    if f"{m}_ray_stop_error" in ok:
        thesis, ray = ok[f"{m}_stop_error"], ok[f"{m}_ray_stop_error"]
        evidence.append(
            Evidence.of(
                "ray-stop-within",
                ray - thesis,
                subject=m,
                shown=f"kiseki's {ray.mean():.3f} m vs the thesis' {thesis.mean():.3f} m",
            )
        )
    return evidence
