# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-mcl's claims (secs. 6.7-6.8, Figs. 6.15-6.18), declared before the run: each with the
per-run quantity it is decided on and the control under which it must fail; and their evidence
from the trials' records. The controls pair each position with the readings taken 30 s later
along the route (``reading_lag_steps=300``): the filter then weighs its particles with the field
of somewhere else."""

from __future__ import annotations

import numpy as np
import pandas as pd

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

__all__ = [
    "CLAIMS",
    "HEADING_BOUND",
    "POSITION_BOUND",
    "better_than_odometry",
    "claim_evidence",
]

POSITION_BOUND, HEADING_BOUND = 0.8, 0.14  # m, rad: Fig. 6.16 (sec. 6.8)

LAGGED = Control(
    name="readings paired with the poses 30 s later",
    overrides=("reading_lag_steps=300",),
    runs=10,  # 5 per route: an interval per route
    why="the field of a place 9 m away: the filter follows a wrong field and its error grows "
    "beyond the bounds, beyond odometry's",
    minutes=True,
)
SWAPPED = Control(
    name="the routes' names swapped",
    overrides=("swap_route_names=true",),
    runs=10,
    why="route a, well surveyed, is then called b: the difference changes sign (a check that the "
    "criterion can fail, not a change of method)",
    minutes=True,
)


def _bound(key: str, what: str, unit: str, threshold: float, stays: str, paper: str, top: float):
    """A run's largest error of `what` along its route at most Fig. 6.16's `threshold`."""
    return ClaimSpec(
        key=key,
        claim=f"the {what} error stays {stays} all along (Figs. 6.16, 6.18)",
        unit=f"{unit}, largest error of a run",
        criterion=Criterion(
            paper_value=paper,
            compare="<=",
            threshold=threshold,
            why="Fig. 6.16's bound",
            bounds=(0.0, top),
            paper_number=threshold,
        ),
        control=LAGGED,
        measure=f"one run's largest {what} error along its route",
    )


def better_than_odometry(key: str, claim: str, control: Control, whose: str) -> ClaimSpec:
    """MCL's mean position error over odometry's on the same run at most 0.5 (sec. 6.8)."""
    return ClaimSpec(
        key=key,
        claim=claim,
        unit="ratio of mean position errors",
        criterion=Criterion(
            paper_value="MCL corrects odometry's drift",
            compare="<=",
            threshold=0.5,
            why="'corrects the drift' read as at most half of odometry's mean error",
            bounds=(0.0, np.inf),
        ),
        control=control,
        measure=f"{whose} mean position error, MCL over odometry (the same odometry)",
    )


CLAIMS = (
    _bound(
        "position-bound",
        "position",
        "m",
        POSITION_BOUND,
        "below 0.8 m",
        "< 0.8 (route b: equivalent to route a)",
        np.inf,
    ),
    _bound(
        "heading-bound",
        "heading",
        "rad",
        HEADING_BOUND,
        "within 0.14 rad",
        "<= 0.14 (route b: larger)",
        np.pi,
    ),
    better_than_odometry(
        "better-than-odometry",
        "magnetic-map MCL is more accurate than odometry (sec. 6.8, Fig. 1.2)",
        LAGGED,
        "one run's",
    ),
    ClaimSpec(
        key="sparse-heading",
        claim="the heading error grows at the sparsely surveyed place (Fig. 6.18)",
        unit="rad, mean heading error",
        criterion=Criterion(
            paper_value="b > a, heading especially",
            compare=">=",
            threshold=0.0,
            why="larger on route b than on route a",
            bounds=(-np.pi, np.pi),
        ),
        control=SWAPPED,
        measure="the k-th run of route b's mean heading error minus the k-th of route a's",
    ),
)


def claim_evidence(ok: pd.DataFrame) -> list[Evidence]:
    """The per-run evidence of :data:`CLAIMS`, the bounds' once per route."""
    out = []
    for name in sorted(ok["route"].unique()):
        runs = ok[ok["route"] == name]
        subject = f"route {name}"
        out.append(Evidence.of("position-bound", runs["max_position_error"], subject=subject))
        out.append(Evidence.of("heading-bound", runs["max_heading_error"], subject=subject))
    ratio = ok["mean_position_error"] / ok["odometry_mean_position_error"]
    out.append(Evidence.of("better-than-odometry", ratio))
    a = ok[ok["route"] == "a"]["mean_heading_error"].to_numpy(float)
    b = ok[ok["route"] == "b"]["mean_heading_error"].to_numpy(float)
    pairs = min(len(a), len(b))
    if pairs:
        out.append(Evidence.of("sparse-heading", b[:pairs] - a[:pairs]))
    return out
