# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The recorded logs' reliability models with one log left out of each fit, for
``mcl-kidnapping-carmen``: a trial on log L is scored with REAL_LOG_FOLDS[L], fitted on the
labelled updates of the other three logs only (kiseki_experiments.mcl.mcl_reliability, trial
seeds 101-130 on each log; ``python -m kiseki_experiments.mcl.mcl_reliability --real`` refits
and prints them). Users get the model of every log,
kiseki.filters.reliability.REAL_LOG_RELIABILITY."""

from __future__ import annotations

from kiseki.filters import ReliabilityModel

__all__ = ["REAL_LOG_FOLDS"]

REAL_LOG_FOLDS: dict[str, ReliabilityModel] = {
    "intel-corrected": ReliabilityModel(
        coefficients=(-7.3336, 12.9476, 3.0901),
        provenance=(
            "maximum likelihood on 78714 updates (0.693 localised) of kidnapping trials "
            "spliced into the CARMEN logs aces-corrected, csail-corrected, "
            "freiburg-079-corrected, seeds 101-130, likelihood field, 1000 particles, 90 "
            "beams, odometry noise 0.1, recovery none and resetting "
            "(kiseki_experiments.mcl.mcl_reliability)"
        ),
    ),
    "aces-corrected": ReliabilityModel(
        coefficients=(-9.1714, 15.681, 4.311),
        provenance=(
            "maximum likelihood on 84960 updates (0.711 localised) of kidnapping trials "
            "spliced into the CARMEN logs intel-corrected, csail-corrected, "
            "freiburg-079-corrected, seeds 101-130, likelihood field, 1000 particles, 90 "
            "beams, odometry noise 0.1, recovery none and resetting "
            "(kiseki_experiments.mcl.mcl_reliability)"
        ),
    ),
    "csail-corrected": ReliabilityModel(
        coefficients=(-8.5801, 14.7121, 3.0692),
        provenance=(
            "maximum likelihood on 86156 updates (0.706 localised) of kidnapping trials "
            "spliced into the CARMEN logs intel-corrected, aces-corrected, "
            "freiburg-079-corrected, seeds 101-130, likelihood field, 1000 particles, 90 "
            "beams, odometry noise 0.1, recovery none and resetting "
            "(kiseki_experiments.mcl.mcl_reliability)"
        ),
    ),
    "freiburg-079-corrected": ReliabilityModel(
        coefficients=(-5.7958, 10.9646, 3.3577),
        provenance=(
            "maximum likelihood on 73822 updates (0.727 localised) of kidnapping trials "
            "spliced into the CARMEN logs intel-corrected, aces-corrected, csail-corrected, "
            "seeds 101-130, likelihood field, 1000 particles, 90 beams, odometry noise 0.1, "
            "recovery none and resetting (kiseki_experiments.mcl.mcl_reliability)"
        ),
    ),
}
