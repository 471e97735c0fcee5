# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What mcl-unknown-obstacles (kiseki_experiments.mcl.mcl_unknown_obstacles) claims of the
models with unknown obstacles on the CARMEN logs, declared before any run with each claim's
criterion and its control (kiseki_experiments.harness.verdict)."""

from __future__ import annotations

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion

__all__ = ["CLAIMS", "NO_OBSTACLES"]

NO_OBSTACLES = Control(
    name="no obstacles at any density",
    # one short stretch of one log: without obstacles every density is the reference
    overrides=(
        "logs=intel-corrected",
        "max_scans=150",
        "particles=200",
        "methods=likelihood-field,space-observation,ray-space-observation",
        "recoveries=none",
        "densities=0,1e-9",
    ),
    runs=5,
    why="with no obstacle the field's RMSE is its own (ratio 1), and neither the thesis' model, "
    "blind along corridors (mcl-excursions), nor kiseki's, whose tolerance of intrusion costs "
    "it some precision, tracks closer than the field",
)

CLAIMS = (
    ClaimSpec(
        key="field-doubles",
        claim="at the densest setting the likelihood field's RMSE is at least twice its own "
        "without obstacles (the sweep reaches obstacles that matter)",
        unit="RMSE with / without obstacles",
        criterion=Criterion(
            paper_value="(kiseki's sweep; the thesis has no real-log runs)",
            compare=">=",
            threshold=2.0,
            why="the sweep must reach where the plain field's error at least doubles, else it "
            "tests nothing the thesis' model was built for",
            bounds=(0.0, float("inf")),
        ),
        control=NO_OBSTACLES,
        measure="a seed's likelihood-field RMSE at the densest setting over its RMSE at 0",
    ),
    ClaimSpec(
        key="ray-closer",
        claim="at the densest setting kiseki's ray space observation model tracks more closely "
        "than the likelihood field (the interval of the ratio below 1: the two RMSEs' paired "
        "intervals do not overlap)",
        unit="RMSE ratio, ray space observation / likelihood field",
        criterion=Criterion(
            paper_value="(kiseki's model; the issue's target)",
            compare="<=",
            threshold=1.0,
            why="a model that keeps the thesis' tolerance of intrusion and is not blind must "
            "beat the field where obstacles mislead the field",
            bounds=(0.0, float("inf")),
        ),
        control=NO_OBSTACLES,
        measure="a seed's RMSE of the ray space observation model over the field's, at the "
        "densest setting",
    ),
    ClaimSpec(
        key="thesis-closer",
        claim="at the densest setting the thesis' space observation model tracks more closely "
        "than the likelihood field",
        unit="RMSE ratio, thesis' model / likelihood field",
        criterion=Criterion(
            paper_value="tolerates unknown obstacles (sec. 3.3)",
            compare="<=",
            threshold=1.0,
            why="the model's purpose: intrusion costs little, so obstacles that mislead the "
            "field should not mislead it",
            bounds=(0.0, float("inf")),
        ),
        control=NO_OBSTACLES,
        measure="a seed's RMSE of the thesis' model over the field's, at the densest setting",
    ),
)
