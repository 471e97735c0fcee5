# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The computations of gp-aalto (:mod:`kiseki_experiments.gp.gp_aalto`): the static map of runs
1-4, the residual offset fixed to the robot, and the scores every task reports.

The Aalto readings are in the world frame, turned there with the recorded orientation. Their
horizontal components still carry a part that turns with the robot: on run 5 the x residual of
a map of runs 1-4 is +5 uT driving west and -4 uT driving east. A constant offset b in the
robot frame (a residual hard iron, what the sphere fit of eq. 6.16 removes on a sensor turned
in place) adds R(heading) b to every world-frame reading. It is estimated from runs 1-4 alone:
each run held out in turn against a map of the others, b by least squares on the held-out
residuals (x, y) = R(heading) b, repeated on the corrected readings until b settles. The heading
is the direction of travel from the Vicon positions (the robot drives forward).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kiseki.datasets.magnetic import MagneticSamples, read_aalto_run
from kiseki.gp import ExactGP, HilbertGP, SquaredExponential

__all__ = [
    "COVERED",
    "ERROR_BINS",
    "Z_BINS",
    "StaticMap",
    "all_runs",
    "estimate_offset",
    "fit_fixed",
    "grid_prediction",
    "held_out",
    "hilbert_fit",
    "kernels_of",
    "load_runs",
    "predict",
    "robot_to_world",
    "sigma_f2",
    "sigma_n",
    "stack_runs",
    "static_map",
    "travel_heading",
]

COVERED = 0.25  # a point is mapped where the noise-free variance is below this share of sigma_f^2
_RUNS: dict[tuple, dict[int, MagneticSamples]] = {}
_MAPS: dict[tuple, StaticMap] = {}


def load_runs(folder: Path, sensor: str, runs) -> dict[int, MagneticSamples]:
    """The runs of one sensor (read once per process)."""
    key = (str(folder), sensor, tuple(sorted(runs)))
    if key not in _RUNS:
        if len(_RUNS) >= 2:  # two sensors' runs at most: about 20 MB
            _RUNS.clear()
        _RUNS[key] = {r: read_aalto_run(folder / "aalto" / sensor / str(r)) for r in key[2]}
    return _RUNS[key]


def travel_heading(positions: np.ndarray, half_window: int = 12, min_move: float = 0.02):
    """Direction of travel (rad) at each sample: of the displacement over +-half_window samples
    (0.5 s at 50 Hz); where the robot moved less than min_move (m) in that time, the last
    heading it had (the first one at the start)."""
    p = np.asarray(positions, dtype=float)[:, :2]
    n = len(p)
    ahead = p[np.minimum(np.arange(n) + half_window, n - 1)]
    behind = p[np.maximum(np.arange(n) - half_window, 0)]
    d = ahead - behind
    heading = np.arctan2(d[:, 1], d[:, 0])
    moving = np.hypot(d[:, 0], d[:, 1]) >= min_move
    if not moving.any():
        return np.zeros(n)
    index = np.where(moving, np.arange(n), 0)
    np.maximum.accumulate(index, out=index)
    index[: int(np.argmax(moving))] = int(np.argmax(moving))
    return heading[index]


def robot_to_world(offset: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """(n, 3) world-frame vectors of a horizontal robot-frame offset (bx forward, by left)."""
    c, s = np.cos(heading), np.sin(heading)
    return np.column_stack([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], 0 * c])


def kernels_of(gp) -> tuple[SquaredExponential, ...]:
    """The kernel of each of the three components."""
    if isinstance(gp, list):
        return tuple(g.kernel for g in gp)
    kernels = tuple(gp.kernels)
    return kernels * 3 if len(kernels) == 1 else kernels


def fit_fixed(x: np.ndarray, y: np.ndarray, kernels) -> list | ExactGP:
    """Exact GPs with given hyperparameters: one for all components when they share a kernel,
    else one per component."""
    if len(set(kernels)) == 1:
        return ExactGP.fit(x, y, kernels[0])
    return [ExactGP.fit(x, y[:, [c]], k) for c, k in enumerate(kernels)]


def predict(gp, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(mean (m, 3), variance of the noise-free field (m, 3)) of one GP or a list of three."""
    if not isinstance(gp, list):
        return gp.predict(points)
    parts = [g.predict(points) for g in gp]
    return np.hstack([m for m, _ in parts]), np.hstack([v for _, v in parts])


def sigma_n(kernels) -> np.ndarray:
    return np.array([k.sigma_n for k in kernels])


def sigma_f2(kernels) -> np.ndarray:
    return np.array([k.sigma_f**2 for k in kernels])


def held_out(field: np.ndarray, mean: np.ndarray, var: np.ndarray, kernels) -> dict:
    """Errors of a prediction: RMSE, bias, the readings' own SD (a constant guess's RMSE), the
    share inside 1 and 2 predictive sigma (sigma^2 = var + sigma_n^2) per component and over
    all, and the mean log predictive density per reading (the three components' sum)."""
    e = field - mean
    s2 = var + sigma_n(kernels) ** 2
    z = e / np.sqrt(s2)
    lpd = -0.5 * (e**2 / s2 + np.log(2 * math.pi * s2)).sum(axis=1)
    return {
        "rmse": np.sqrt((e**2).mean(axis=0)).tolist(),
        "bias": e.mean(axis=0).tolist(),
        "sd": field.std(axis=0).tolist(),
        "in1": (np.abs(z) < 1).mean(axis=0).tolist(),
        "in2": (np.abs(z) < 2).mean(axis=0).tolist(),
        "in1_all": float((np.abs(z) < 1).mean()),
        "in2_all": float((np.abs(z) < 2).mean()),
        "mlpd": float(lpd.mean()),
        "count": len(e),
        "error_hist": [np.histogram(e[:, c], ERROR_BINS)[0].tolist() for c in range(3)],
        "z_hist": np.histogram(z.ravel(), Z_BINS)[0].tolist(),
    }


ERROR_BINS = np.arange(-15.0, 15.01, 0.5)  # uT
Z_BINS = np.arange(-5.0, 5.01, 0.25)


@dataclass
class StaticMap:
    """The maps of the training runs: ``raw`` on the readings as recorded, ``gp`` on the
    readings less the robot-frame ``offset`` (zero without the calibration)."""

    sensor: str
    raw: object
    gp: object
    offset: np.ndarray  # (2,) uT, robot frame
    offset_steps: int
    headings: dict[int, np.ndarray]
    fit_seconds: float

    def corrected(self, run: int, samples: MagneticSamples) -> np.ndarray:
        return samples.field - robot_to_world(self.offset, self.headings[run])


def stack_runs(runs, numbers, fields, step: int) -> tuple[np.ndarray, np.ndarray]:
    """Positions and readings (``fields[run]``) of every step-th sample of the runs."""
    x = np.vstack([runs[r].positions[::step] for r in numbers])
    y = np.vstack([fields[r][::step] for r in numbers])
    return x, y


def _fit(config, x: np.ndarray, y: np.ndarray) -> ExactGP:
    return ExactGP.fit(
        x,
        y,
        per_component=config.per_component,
        max_points=config.max_points,
        restarts=config.restarts,
        seed=config.gp_seed,
    )


def estimate_offset(config, runs, headings, kernels, iterations: int = 5) -> tuple:
    """The robot-frame offset b (2,) from runs 1-4 held out in turn (module text); returns
    (b, iterations used)."""
    train = list(config.train_runs)
    b = np.zeros(2)
    every = 5  # held-out readings scored: one in five
    cover = COVERED * sigma_f2(kernels)
    used = 0
    while used < iterations:
        used += 1
        fields = {r: runs[r].field - robot_to_world(b, headings[r]) for r in train}
        rows, targets = [], []
        for r in train:
            x, y = stack_runs(runs, [q for q in train if q != r], fields, config.thinning)
            mean, var = predict(fit_fixed(x, y, kernels), runs[r].positions[::every])
            ok = (var < cover).all(axis=1)
            e = (fields[r][::every] - mean)[ok]
            c, s = np.cos(headings[r][::every][ok]), np.sin(headings[r][::every][ok])
            rows += [np.column_stack([c, -s]), np.column_stack([s, c])]
            targets += [e[:, 0], e[:, 1]]
        step, *_ = np.linalg.lstsq(np.vstack(rows), np.concatenate(targets), rcond=None)
        b = b + step
        if np.hypot(*step) < 0.05:
            break
    return b, used


def static_map(config, folder: Path, sensor: str) -> StaticMap:
    """The hyperparameters and maps of the training runs (computed once per process)."""
    key = (str(folder), sensor, repr(config))
    if key in _MAPS:
        return _MAPS[key]
    start = time.perf_counter()
    runs = load_runs(folder, sensor, all_runs(config))
    headings = {r: travel_heading(s.positions) for r, s in runs.items()}
    train = list(config.train_runs)
    raw = _fit(config, *stack_runs(runs, train, {r: runs[r].field for r in train}, config.thinning))
    offset, used = np.zeros(2), 0
    gp = raw
    if config.offset_calibration:
        offset, used = estimate_offset(config, runs, headings, kernels_of(raw))
        fields = {r: runs[r].field - robot_to_world(offset, headings[r]) for r in train}
        gp = _fit(config, *stack_runs(runs, train, fields, config.thinning))
    result = StaticMap(sensor, raw, gp, offset, used, headings, time.perf_counter() - start)
    if len(_MAPS) >= 2:
        _MAPS.clear()
    _MAPS[key] = result
    return result


def all_runs(config) -> list[int]:
    return sorted({*config.train_runs, config.test_run, *config.changed_runs})


def hilbert_fit(x: np.ndarray, y: np.ndarray, kernels, domain, tolerance: float) -> list:
    """Reduced-rank GPs, one per component (one kernel each), on a shared box; ``tolerance``:
    the spectral tolerance of the basis (HilbertGP.fit's)."""
    return [
        HilbertGP.fit(x, y[:, [c]], k, domain=domain, tolerance=tolerance)
        for c, k in enumerate(kernels)
    ]


def grid_prediction(gp, lower, upper, resolution: float, height: float | None = None) -> dict:
    """Mean and SD of the noise-free field on cell centres (for the pictures); with `height`,
    the horizontal slice of a 3-D GP there."""
    lower, upper = np.asarray(lower, dtype=float)[:2], np.asarray(upper, dtype=float)[:2]
    nx, ny = np.ceil((upper - lower) / resolution).astype(int).tolist()
    xs = lower[0] + (np.arange(nx) + 0.5) * resolution
    ys = lower[1] + (np.arange(ny) + 0.5) * resolution
    gx, gy = np.meshgrid(xs, ys)
    points = np.column_stack([gx.ravel(), gy.ravel()])
    if height is not None:
        points = np.column_stack([points, np.full(len(points), height)])
    mean, var = predict(gp, points)
    return {
        "origin": lower.tolist(),
        "resolution": resolution,
        "shape": [ny, nx],
        "mean": np.round(mean.T, 3).tolist(),  # (3, ny * nx), row-major from the lowest y
        "sd": np.round(np.sqrt(var).T, 4).tolist(),
    }
