# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What mcl-excursions (kiseki_experiments.mcl.mcl_excursions) claims of the space observation
model and kiseki's ray space observation model on the CARMEN logs, declared before any run with
each claim's criterion and its control (kiseki_experiments.harness.verdict)."""

from __future__ import annotations

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion

__all__ = ["CLAIMS", "RAY_WIDE_ODOMETRY", "WIDE_ODOMETRY"]

WIDE_ODOMETRY = (
    "logs=intel-corrected",
    "max_scans=120",
    "particles=200",
    "recoveries=none",
    "odometry_noise=1.0",
)

RAY_WIDE_ODOMETRY = Control(
    name="kiseki's model, no recovery, odometry as noisy as its increments (F = 1.0)",
    overrides=(*WIDE_ODOMETRY, "methods=ray-space-observation"),
    runs=5,
    why="a motion model this wide spreads the cloud faster than the scans can gather it, and "
    "nothing brings it back",
)

CLAIMS = (
    ClaimSpec(
        key="returns",
        claim="space observation excursions beyond 0.5 m return within 20 scans (the longest "
        "of a seed's run, mean over seeds)",
        unit="scans",
        criterion=Criterion(
            paper_value="(the issue's target; the thesis has no real-log runs)",
            compare="<=",
            threshold=20.0,
            why="the issue's target: 20 scans, 2 s of a 10 Hz laser",
            bounds=(0.0, float("inf")),
        ),
        control=Control(
            name="no recovery, odometry as noisy as its increments (F = 1.0)",
            # no recovery: each reset under such odometry draws 20,000 candidates (the control
            # took 9 min with resetting on a loaded machine)
            overrides=(*WIDE_ODOMETRY, "methods=space-observation"),
            runs=5,
            why="a motion model this wide spreads the cloud faster than the scans can gather "
            "it, and nothing brings it back",
        ),
        measure="a seed's longest excursion (inf when it never came back)",
    ),
    ClaimSpec(
        key="ray-never-lost",
        claim="kiseki's ray space observation model is never lost: its position error after "
        "the first 10 % of the scans stays within 2 m (the worst scan of a seed, mean over "
        "seeds; the worst seed is shown)",
        unit="m",
        criterion=Criterion(
            paper_value="(the issue's target; the thesis has no real-log runs)",
            compare="<=",
            threshold=2.0,
            why="the issue's target: never more than 2 m off once the first tenth has passed",
            bounds=(0.0, float("inf")),
        ),
        control=RAY_WIDE_ODOMETRY,
        measure="a seed's largest position error after the first 10 % of the scans",
    ),
    ClaimSpec(
        key="ray-returns",
        claim="kiseki's ray space observation model's excursions beyond 0.5 m return within "
        "20 scans (the longest of a seed's run, mean over seeds)",
        unit="scans",
        criterion=Criterion(
            paper_value="(the issue's target; the thesis has no real-log runs)",
            compare="<=",
            threshold=20.0,
            why="the issue's target: 20 scans, 2 s of a 10 Hz laser",
            bounds=(0.0, float("inf")),
        ),
        control=RAY_WIDE_ODOMETRY,
        measure="a seed's longest excursion (inf when it never came back)",
    ),
    ClaimSpec(
        key="ray-rmse",
        claim="kiseki's ray space observation model's RMSE is at most 1.5 times the likelihood "
        "field's on the same log, seed and odometry",
        unit="RMSE ratio, ray space observation / likelihood field",
        criterion=Criterion(
            paper_value="(the issue's target)",
            compare="<=",
            threshold=1.5,
            why="the issue's target: the price of tolerating unknown obstacles is bounded",
            bounds=(0.0, float("inf")),
        ),
        control=Control(
            name="intrusion made free (z_intrusion = 1000: the thesis' blindness)",
            overrides=(
                "logs=intel-corrected",
                "max_scans=400",
                "particles=200",
                "recoveries=none",
                "methods=likelihood-field,ray-space-observation",
                "z_intrusion=1000",
            ),
            runs=5,
            why="a beam that stops short in free space then scores as well as one that ends on "
            "a wall, so, like the thesis' model, it cannot tell positions along a corridor apart",
        ),
        measure="a seed's RMSE of the ray model over the field's",
    ),
)
