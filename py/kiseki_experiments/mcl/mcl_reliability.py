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

The recorded logs' coefficients (``learned-real``) come the same way from kidnapping trials
spliced into the four CARMEN logs as ``mcl-kidnapping-carmen`` splices them (trial seeds
``FIT_SEEDS`` on each log, arms none and resetting): fitted on every log for users
(kiseki.filters.reliability.REAL_LOG_RELIABILITY), and on three logs with the fourth left out,
in turn, for ``mcl-kidnapping-carmen`` (mcl_reliability_folds), which scores each trial with the
model that never saw its log.

``python -m kiseki_experiments.mcl.mcl_reliability`` refits and prints the simulator's model;
with ``--real`` the recorded logs' five.
"""

from __future__ import annotations

import functools
import sys
from dataclasses import dataclass, fields

import numpy as np

from kiseki.datasets import read_carmen_log
from kiseki.filters import LocalizeConfig, localize
from kiseki.filters.reliability import FEATURES, ReliabilityModel, fit_logistic, localised
from kiseki.mapping import MapBuildConfig, map_of_log
from kiseki_experiments.harness.paths import CARMEN_LOGS, shared_data
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
    return _labelled_arms(spliced, grid, config, seed, 0.0, arms)


@functools.lru_cache(maxsize=4)
def _carmen_log(name: str, data_dir: str = ""):
    scans = read_carmen_log(shared_data("carmen", data_dir) / f"{name}.log.gz").scans
    return scans, map_of_log(scans, MapBuildConfig(resolution=0.05))


@functools.cache  # the leave-one-log-out fits reuse every trial three times
def carmen_labelled_updates(
    log: str, seed: int, arms: tuple[str, ...] = ARMS, data_dir: str = ""
) -> LabelledUpdates:
    """Every update of one kidnapping trial on a CARMEN log, spliced and tracked as
    ``mcl-kidnapping-carmen`` does (its map from the corrected poses, odometry noise 0.1), for
    each arm."""
    config = KidnapConfig()
    scans, grid = _carmen_log(log, data_dir)
    k, j = choose_jump(scans, config, seed)
    spliced = splice(scans, k, j, config.before_scans, config.after_scans)
    return _labelled_arms(spliced, grid, config, seed, config.odometry_noise, arms)


def _labelled_arms(spliced, grid, config: KidnapConfig, seed: int, noise: float, arms):
    parts = []
    for arm in arms:
        lc = LocalizeConfig(
            seed=seed,
            odometry_noise=noise,
            particles=config.particles,
            beams=config.beams,
            recovery=arm,
            # the proposal the stored coefficients were fitted with (LocalizeConfig's default
            # then); their held-out checks draw their updates the same way
            sensor_reset_proposal="uniform",
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


def refit_real(
    logs: tuple[str, ...] = tuple(CARMEN_LOGS), seeds: tuple[int, ...] = FIT_SEEDS
) -> ReliabilityModel:
    """The model of (1) fitted on the labelled updates of kidnapping trials spliced into the
    CARMEN logs ``logs`` (each with every trial seed)."""
    parts = [carmen_labelled_updates(log, s) for log in logs for s in seeds]
    features = np.concatenate([p.features for p in parts])
    labels = np.concatenate([p.localised for p in parts])
    b = fit_logistic(features, labels)
    provenance = (
        f"maximum likelihood on {len(labels)} updates ({labels.mean():.3f} localised) of "
        f"kidnapping trials spliced into the CARMEN logs {', '.join(logs)}, seeds "
        f"{seeds[0]}-{seeds[-1]}, likelihood field, 1000 particles, 90 beams, odometry noise "
        f"0.1, recovery {' and '.join(ARMS)}"
    )
    return ReliabilityModel(tuple(round(float(c), 4) for c in b), provenance)


def _print(title: str, model: ReliabilityModel) -> None:
    names = ", ".join(("intercept", *FEATURES))
    print(f"{title}: coefficients ({names}):")
    print(f"    {model.coefficients}")
    print(f"provenance: {model.provenance}")


def main(argv: list[str] | None = None) -> int:
    """Refits the simulator's coefficients (kiseki.filters.reliability.LEARNED_RELIABILITY);
    with --real, the recorded logs' (REAL_LOG_RELIABILITY, every log) and the leave-one-log-out
    models of kiseki_experiments.mcl.mcl_reliability_folds (each log left out in turn)."""
    argv = sys.argv[1:] if argv is None else argv
    if argv not in ([], ["--real"]):
        print("usage: python -m kiseki_experiments.mcl.mcl_reliability [--real]", file=sys.stderr)
        return 2
    if not argv:
        _print("simulation", refit())
        return 0
    _print("every log", refit_real())
    for held_out in CARMEN_LOGS:
        _print(f"without {held_out}", refit_real(tuple(x for x in CARMEN_LOGS if x != held_out)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
