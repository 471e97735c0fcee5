# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""magnav-fig-5-4's claims in the verdict form (declared before the run, judged on one value per
trial with a 95 % interval): the trajectories of Fig. 5.4 (odometry leaves the path, both MCLs
reach the goal, LIDAR-only MCL deviates in the landmark-free stretch and the proposed method
less, staying on the path), the resets of Fig. 5.5 and the particle SDs of Fig. 5.6. Most
controls run the proposed arm without the reset (``heading_reset=false``): it is then
LIDAR-only MCL with the same seed, and the claims about the reset fail."""

from __future__ import annotations

import pandas as pd

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

__all__ = ["CLAIMS", "OFF_PATH", "SD_RATIO", "evidence"]

OFF_PATH = 1.0
"""m of |cross-track error| beyond which a run counts as having left the path (our reading:
the thesis draws the trajectories, Fig. 5.4, and prints no number)."""
SHARE = (0.0, 1.0)

#: "markedly smaller" read as at most half of LIDAR-only MCL's SD (the thesis prints no number)
SD_RATIO = 0.5

NO_RESET = Control(
    name="the reset without the magnetic heading (LIDAR-only MCL in the proposed arm)",
    # a short run and a small filter: the two arms are the same run whatever their size
    overrides=("heading_reset=false", "particles=60", "beams=20", "distance=35"),
    runs=5,
    why="the proposed arm is then LIDAR-only MCL with the same seed: every ratio is 1",
)


def _ratio(axis: str, unit: str) -> ClaimSpec:
    return ClaimSpec(
        key=f"sd_{axis}",
        claim=f"the particles' SD in {axis} stays small with the heading reset (Fig. 5.6): "
        "proposed over LIDAR-only",
        unit=f"ratio of the mean SD in {axis} ({unit}) over the landmark-free stretch",
        criterion=Criterion(
            paper_value="markedly smaller SD than LIDAR-only MCL",
            compare="<=",
            threshold=SD_RATIO,
            why="'markedly smaller' read as at most half; the thesis prints only the plot",
            bounds=(0.0, float("inf")),
        ),
        control=NO_RESET,
        measure=f"one run's mean particle SD in {axis} over the stretch, proposed / LIDAR-only "
        "(same seed)",
    )


SHORT_RUN = Control(
    name="runs stopped after 25 m",
    overrides=("distance=25", "particles=60", "beams=20"),
    runs=5,
    why="25 m of travel is too short for the odometry's error to reach 1 m",
)
STOPPED = Control(
    name="runs stopped after 35 m",
    overrides=("distance=35", "particles=60", "beams=20"),
    runs=5,
    why="a run stopped on the way does not reach the goal (a check that the criterion can "
    "fail, not a change of method)",
)
NO_RESET_WHOLE_ROUTE = Control(
    name="the whole route without the magnetic heading reset",
    overrides=("heading_reset=false",),
    runs=5,
    why="LIDAR-only MCL leaves the path in the landmark-free stretch",
    minutes=True,
)


def _share(key: str, claim: str, paper: str, threshold: float, why: str, control, measure):
    criterion = Criterion(paper, ">=", threshold, why, bounds=SHARE)
    return ClaimSpec(key, claim, "share of runs", criterion, control, measure)


CLAIMS = (
    _share(
        "odometry-leaves",
        "odometry alone cannot correct its accumulated error and leaves the path (Fig. 5.4)",
        "largely deviates from the path",
        0.5,
        "in most runs",
        SHORT_RUN,
        f"whether its |cross-track| exceeds {OFF_PATH:g} m (our reading of leaving)",
    ),
    _share(
        "both-reach-goal",
        "both MCLs reach the goal (Fig. 5.4)",
        "reached the destination",
        0.8,
        "the thesis' runs did: in at least 4 of 5",
        STOPPED,
        "whether LIDAR-only MCL and the proposed method both end within 1 m of the goal",
    ),
    ClaimSpec(
        key="proposed-deviates-less",
        claim="LIDAR-only MCL deviates where no landmark is seen; the proposed method does less",
        unit="ratio of the largest |cross-track| in the landmark-free stretch",
        criterion=Criterion(
            paper_value="LIDAR-only deviates; the proposed follows the path",
            compare="<=",
            threshold=0.8,
            why="'less' read as at least a fifth less than LIDAR-only MCL",
            bounds=(0.0, float("inf")),
        ),
        control=NO_RESET,
        measure="one run's largest |xte| in the stretch, proposed / LIDAR-only (same seed)",
    ),
    _share(
        "proposed-stays-on-path",
        "the proposed method stays on the path in the landmark-free stretch (Fig. 5.4)",
        "accurate path following",
        0.8,
        "in at least 4 of 5 runs",
        NO_RESET_WHOLE_ROUTE,
        f"whether its |cross-track| in the stretch stays within {OFF_PATH:g} m",
    ),
    ClaimSpec(
        key="resets-many",
        claim="r_z and r_theta exceed their thresholds at many points (Fig. 5.5)",
        unit="share of 10 Hz steps",
        criterion=Criterion(
            paper_value="the heading is corrected at many points",
            compare=">=",
            threshold=0.1,
            why="'many points' read as a tenth of the steps at least",
            bounds=SHARE,
        ),
        control=NO_RESET,
        measure="the share of one run's steps on which both gates held (a heading reset)",
    ),
    _ratio("y", "m"),
    _ratio("theta", "deg"),
)


def evidence(ok: pd.DataFrame) -> list[Evidence]:
    n = len(ok)
    off = int((ok["odometry_max_xt"] > OFF_PATH).sum())
    both = int((ok["laser_reached"].astype(bool) & ok["magnetic_reached"].astype(bool)).sum())
    on = int((ok["magnetic_blind_max_xt"] <= OFF_PATH).sum())
    out = [
        Evidence.share("odometry-leaves", off, n),
        Evidence.share("both-reach-goal", both, n),
        Evidence.of(
            "proposed-deviates-less", ok["magnetic_blind_max_xt"] / ok["laser_blind_max_xt"]
        ),
        Evidence.share("proposed-stays-on-path", on, n),
        Evidence.of("resets-many", ok["magnetic_resets"]),
    ]
    for axis, key in (("y", "blind_sd_y"), ("theta", "blind_sd_theta_deg")):
        mag, las = ok[f"magnetic_{key}"], ok[f"laser_{key}"]
        out.append(
            Evidence.of(
                f"sd_{axis}",
                mag / las,
                shown=f"mean SD {float(mag.mean()):.3g} vs {float(las.mean()):.3g}",
            )
        )
    return out
