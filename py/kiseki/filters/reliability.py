# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A reliability estimate that reads as a probability: P(the filter is localised | features).

Two estimates, chosen by name (``LocalizeConfig.reliability``):

* ``agreement``: the engine's own (``MonteCarloLocalization::reliability``), the recent share
  of updates whose scan agrees with the map seen from the estimate, r <- r + 0.1 (s - r). In a
  place that looks like another the beams agree with the map from the wrong pose too, so it
  can stay at 1 while the robot is metres off.
* ``learned``: a logistic model over two features of each measurement update (als_ros'
  reliability is likewise learned from labelled simulated updates),

      p_t = sigmoid(b0 + b1 a_t + b2 delta_t)                                            (1)
      delta_t = l_t - lbar_{t-1},   lbar_t = lbar_{t-1} + alpha_slow (l_t - lbar_{t-1})   (2)

  where, at the filter's estimate x^_t (the weighted mean after weighing), a_t is the agreement
  of the scan with the map (emcl2's non-penetration share) and l_t the per-reading
  log-likelihood of the scan, log p(z_t | x^_t) / readings, clipped to [-10, 10]; lbar is its
  long-term average (Augmented MCL's w_slow, on the log scale, alpha_slow = 0.001 as nav2's
  recovery_alpha_slow; lbar_0 = l_0). So delta is how much worse the scan fits than scans have
  fitted on this run: a kidnapped robot in a look-alike place keeps its agreement but loses
  likelihood (the README's aisle: 1.9 per beam while tracking, 0.7 at the turned pose).

  Why these two and not more: both are relative to the run itself, so they carry from the
  simulator to a robot whose laser is noisier or whose map is coarser. Two others were tried
  and left out: the log-likelihood relative to that of the scan ray-cast at the estimate (the
  simulator's near-perfect scans make it ~0 while tracking, real scans do not) and the
  particles' spread (it depends on the particle count and the motion noise).

  The coefficients b are fitted by maximum likelihood (iteratively reweighted least squares)
  on simulated updates labelled localised when the position error is at most
  ``LOST_DISTANCE`` and the heading error at most ``LOST_HEADING``. They and their provenance
  live in :data:`LEARNED_RELIABILITY`; ``python -m kiseki_experiments.mcl.mcl_reliability``
  refits them. A logistic model fitted by maximum likelihood matches the observed share on
  its fitting distribution; its calibration on held-out simulated updates is a test.
* ``learned-real``: (1) and (2) with coefficients fitted the same way on labelled updates of
  recorded laser logs (:data:`REAL_LOG_RELIABILITY`: kidnapping trials spliced into four
  CARMEN logs). Real scans fit their map less evenly than simulated ones, so the simulator's
  coefficients call a tracking robot lost too often on real data; fitted on three logs and
  scored on the fourth, in turn, the real-log coefficients are not (the README's table; the
  calibration on a log left out of the fit is a test).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kiseki._support.real_numbers import check_number

__all__ = [
    "FEATURES",
    "LEARNED_RELIABILITY",
    "LOST_DISTANCE",
    "LOST_HEADING",
    "LearnedReliability",
    "REAL_LOG_RELIABILITY",
    "RELIABILITY_ESTIMATES",
    "ReliabilityModel",
    "fit_logistic",
    "learned_model",
    "localised",
]

RELIABILITY_ESTIMATES = ("agreement", "learned", "learned-real")
FEATURES = ("agreement", "log_likelihood_drop")
LOST_DISTANCE = 1.0  # m: a position error above this is lost (the "error above 1 m")
LOST_HEADING = math.radians(10.0)  # rad: the kidnapping experiment's recovery tolerance


def localised(errors: np.ndarray, heading_errors: np.ndarray) -> np.ndarray:
    """The label: position error <= LOST_DISTANCE and |heading error| <= LOST_HEADING."""
    return (np.asarray(errors) <= LOST_DISTANCE) & (np.abs(heading_errors) <= LOST_HEADING)


@dataclass(frozen=True)
class ReliabilityModel:
    """The coefficients of (1), (b0, b_agreement, b_log_likelihood_drop), and how they were
    obtained."""

    coefficients: tuple[float, ...] = (0.0, 0.0, 0.0)
    provenance: str = "unfitted"

    def __post_init__(self) -> None:
        if len(self.coefficients) != 1 + len(FEATURES):
            raise ValueError(
                f"reliability model: need {1 + len(FEATURES)} finite coefficients, "
                f"got {self.coefficients!r}"
            )
        names = ("b0", *(f"b_{feature}" for feature in FEATURES))
        for name, value in zip(names, self.coefficients, strict=True):
            check_number(value, f"reliability model: {name}")

    def probability(self, features: np.ndarray) -> np.ndarray:
        """P(localised) for features (..., 2); NaN where a feature is NaN."""
        f = np.asarray(features, dtype=float)
        b = np.asarray(self.coefficients)
        return 1.0 / (1.0 + np.exp(-(b[0] + f @ b[1:])))


LEARNED_RELIABILITY = ReliabilityModel(
    coefficients=(0.9532, 2.07, 9.8137),
    provenance=(
        "maximum likelihood on 16268 updates (0.682 localised) of simulated kidnapping trials, "
        "seeds 101-130, factory_turn, likelihood field, 1000 particles, 90 beams, recovery "
        "none and resetting (kiseki_experiments.mcl.mcl_reliability)"
    ),
)
REAL_LOG_RELIABILITY = ReliabilityModel(
    coefficients=(-7.8948, 13.7425, 3.2754),
    provenance=(
        "maximum likelihood on 107884 updates (0.709 localised) of kidnapping trials spliced "
        "into the CARMEN logs intel-corrected, aces-corrected, csail-corrected, "
        "freiburg-079-corrected, seeds 101-130, likelihood field, 1000 particles, 90 beams, "
        "odometry noise 0.1, recovery none and resetting "
        "(kiseki_experiments.mcl.mcl_reliability)"
    ),
)
ALPHA_SLOW = 0.001  # (2)'s rate: nav2's recovery_alpha_slow


def learned_model(estimate: str) -> ReliabilityModel | None:
    """The coefficients behind a reliability estimate's name; None for the engine's own."""
    models = {"learned": LEARNED_RELIABILITY, "learned-real": REAL_LOG_RELIABILITY}
    if estimate not in RELIABILITY_ESTIMATES:
        raise ValueError(f"reliability must be one of {', '.join(RELIABILITY_ESTIMATES)}")
    return models.get(estimate)


class LearnedReliability:
    """(1) and (2) along one run: call :meth:`update` after each measurement update."""

    def __init__(self, model: ReliabilityModel = LEARNED_RELIABILITY) -> None:
        self.model = model
        self.baseline: float | None = None  # lbar

    def features(self, sensor_model, estimate: np.ndarray, agreement: float) -> np.ndarray:
        """(a_t, delta_t) for the scan ``sensor_model`` holds, at the estimate; advances lbar."""
        pose = np.asarray(estimate, dtype=float)[None, :]
        readings = max(int(sensor_model.readings), 1)
        level = float(sensor_model.log_likelihoods(pose)[0]) / readings
        level = float(np.clip(level, -10.0, 10.0)) if math.isfinite(level) else -10.0
        if self.baseline is None:
            self.baseline = level
        drop = level - self.baseline
        self.baseline += ALPHA_SLOW * drop
        return np.array([agreement, drop])

    def update(
        self, sensor_model, estimate: np.ndarray, agreement: float
    ) -> tuple[float, np.ndarray]:
        """p_t of (1) and its features."""
        f = self.features(sensor_model, estimate, agreement)
        return float(self.model.probability(f)), f


def fit_logistic(features: np.ndarray, labels: np.ndarray, iterations: int = 50) -> np.ndarray:
    """Maximum-likelihood coefficients (b0, b...) of P(label | features) = sigmoid(b0 + f b) by
    Newton's method (iteratively reweighted least squares), with a tiny ridge (1e-6) so that
    separable data stay finite. Deterministic."""
    f = np.asarray(features, dtype=float)
    y = np.asarray(labels, dtype=float)
    if f.ndim != 2 or len(f) != len(y) or not np.isfinite(f).all():
        raise ValueError("fit_logistic: need finite features (n, k) and n labels")
    x = np.column_stack([np.ones(len(f)), f])
    b = np.zeros(x.shape[1])
    for _ in range(iterations):
        p = 1.0 / (1.0 + np.exp(-(x @ b)))
        w = np.maximum(p * (1.0 - p), 1e-12)
        hessian = x.T @ (x * w[:, None]) + 1e-6 * np.eye(x.shape[1])
        step = np.linalg.solve(hessian, x.T @ (y - p) - 1e-6 * b)
        b += step
        if np.max(np.abs(step)) < 1e-10:
            break
    return b
