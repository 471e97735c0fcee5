# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The learned reliability estimate's data and fit (kiseki.filters.reliability, equation (1)).

Labelled updates come from simulated kidnapping trials of the thesis' factory aisle with the
turn (`data/worlds/factory_turn.yaml`, as ``mcl-kidnapping``): one simulated run per trial seed,
spliced at the kidnapping that seed chooses, tracked with the likelihood field (1,000
particles, 90 beams) once with recovery ``none`` (lost from the jump on) and once with
``resetting`` (lost, then found again); every update is labelled localised or lost by
:func:`kiseki.filters.reliability.localised`. The coefficients are fitted by maximum likelihood
on the trial seeds ``FIT_SEEDS``; the calibration test draws its held-out updates from other
seeds, and ``mcl-kidnapping`` is judged on seeds 1-25, which neither uses.

``python -m kiseki_experiments.mcl.mcl_reliability`` refits and prints the model.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, fields

import numpy as np

from kiseki.filters import LocalizeConfig, localize
from kiseki.filters.reliability import FEATURES, ReliabilityModel, fit_logistic, localised
from kiseki_experiments.mcl.mcl_kidnapping import choose_jump, simulated_run, splice
from kiseki_experiments.mcl.mcl_kidnapping_config import KidnapConfig

FIT_SEEDS = tuple(range(101, 131))
ARMS = ("none", "resetting")


@dataclass(frozen=True)
class LabelledUpdates:
    features: np.ndarray  # (m, 2) the learned estimate's features at each update
    localised: np.ndarray  # (m,) the label
    agreement_reliability: np.ndarray  # (m,) the engine's estimate at the same updates


def labelled_updates(seed: int, arms: tuple[str, ...] = ARMS) -> LabelledUpdates:
    """Every update of one simulated kidnapping trial (trial seed ``seed``), for each arm."""
    config = KidnapConfig()
    scans, grid = simulated_run(config.scene, seed)
    k, j = choose_jump(scans, config, seed)
    spliced = splice(scans, k, j, config.before_scans, config.after_scans)
    parts = []
    for arm in arms:
        lc = LocalizeConfig(
            seed=seed,
            particles=config.particles,
            beams=config.beams,
            recovery=arm,
            threads=1,
            reliability="learned",
        )
        result = localize(spliced, grid, lc)
        d = result.estimates - spliced.poses
        heading = np.remainder(d[:, 2] + np.pi, 2 * np.pi) - np.pi
        label = localised(np.hypot(d[:, 0], d[:, 1]), heading)
        rows = result.updated & np.isfinite(result.reliability_features).all(axis=1)
        parts.append(
            (result.reliability_features[rows], label[rows], result.agreement_reliability[rows])
        )
    return LabelledUpdates(*(np.concatenate(column) for column in zip(*parts, strict=True)))


def pooled(seeds) -> LabelledUpdates:
    """The labelled updates of several trial seeds, pooled."""
    parts = [labelled_updates(s) for s in seeds]
    return LabelledUpdates(
        *(np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(LabelledUpdates))
    )


def refit(seeds: tuple[int, ...] = FIT_SEEDS) -> ReliabilityModel:
    """The model of (1) fitted on the labelled updates of the trial seeds."""
    data = pooled(seeds)
    labels = data.localised
    b = fit_logistic(data.features, labels)
    provenance = (
        f"maximum likelihood on {len(labels)} updates ({labels.mean():.3f} localised) of "
        f"simulated kidnapping trials, seeds {seeds[0]}-{seeds[-1]}, factory_turn, "
        f"likelihood field, 1000 particles, 90 beams, recovery {' and '.join(ARMS)}"
    )
    return ReliabilityModel(tuple(round(float(c), 4) for c in b), provenance)


def main() -> int:
    model = refit()
    names = ", ".join(("intercept", *FEATURES))
    print(f"coefficients ({names}):")
    print(f"    {model.coefficients}")
    print(f"provenance: {model.provenance}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
