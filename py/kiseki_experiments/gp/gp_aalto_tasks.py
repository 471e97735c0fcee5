# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The four tasks of gp-aalto (:mod:`kiseki_experiments.gp.gp_aalto`), each returning a
JSON-ready dict: the held-out map of one sensor, the change detection, the magnetic-map MCL
and the 3-D walks."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import scipy.io

from kiseki.datasets.kok import SENSOR_TO_BODY, quaternion_to_matrix, read_kok_walk
from kiseki.gp import ExactGP
from kiseki.magnetic.field_map import MagneticFieldMap
from kiseki.magnetic.localization import MagneticMclConfig, localize_on_magnetic_map
from kiseki_experiments.gp import gp_aalto_steps as st

__all__ = [
    "bounds",
    "map_task",
    "mcl_task",
    "noisy_odometry",
    "travel_subsample",
    "walks_task",
]

EXACT_LIMIT = 2000  # readings; above, the denser-data sweep uses the reduced-rank GP


def _kernel_rows(gp) -> list[dict]:
    return [k.to_dict() for k in st.kernels_of(gp)]


def bounds(runs, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) corners of the runs' positions, widened by ``margin`` m."""
    p = np.vstack([s.positions for s in runs.values()])
    return p.min(axis=0) - margin, p.max(axis=0) + margin


def map_task(config, folder: Path, sensor: str, timings: dict) -> dict:
    """Held-out prediction of the test run by maps of the training runs, raw and corrected;
    the reduced-rank GP beside the exact one; denser training data."""
    runs = st.load_runs(folder, sensor, st.all_runs(config))
    sm = st.static_map(config, folder, sensor)
    timings["static_map_seconds"] = sm.fit_seconds
    test = runs[config.test_run]
    kernels = st.kernels_of(sm.gp)
    raw = st.held_out(test.field, *st.predict(sm.raw, test.positions), st.kernels_of(sm.raw))
    corrected_test = sm.corrected(config.test_run, test)
    start = time.perf_counter()
    mean, var = st.predict(sm.gp, test.positions)
    timings["exact_predict_seconds"] = time.perf_counter() - start
    out = {
        "sensor": sensor,
        "train_points": int(
            sum(len(runs[r].positions[:: config.thinning]) for r in config.train_runs)
        ),
        "train_samples": int(sum(len(runs[r]) for r in config.train_runs)),
        "kernels_raw": _kernel_rows(sm.raw),
        "kernels": _kernel_rows(sm.gp),
        "lml": sm.gp.log_marginal_likelihood(),
        "offset": sm.offset.tolist(),
        "offset_iterations": sm.offset_steps,
        "raw": raw,
        "corrected": st.held_out(corrected_test, mean, var, kernels),
        "test_positions": np.round(test.positions[::25], 3).tolist(),
        "train_positions": np.round(
            np.vstack([runs[r].positions[:: config.thinning] for r in config.train_runs]), 3
        ).tolist(),
    }
    lower, upper = bounds(runs, 0.3)
    reach = 4 * max(k.length_scale for k in (*kernels, *st.kernels_of(sm.raw)))
    domain = (lower - reach, upper + reach)
    out |= _scalable(config, runs, sm, domain, (mean, var), timings)
    # how long the raw residual stays the same along the track: autocorrelation after 1 s
    e = test.field - st.predict(sm.raw, test.positions)[0]
    lag = max(1, int(round(1.0 / np.median(np.diff(test.times)))))
    out["raw_autocorrelation_1s"] = [
        float(np.corrcoef(e[:-lag, c], e[lag:, c])[0, 1]) for c in range(3)
    ]
    out["grid"] = st.grid_prediction(sm.gp, lower, upper, config.grid_resolution)
    if sensor != "invensense" and (folder / "aalto" / "invensense").is_dir():
        out["offset_vs_invensense"] = _offsets_vs_invensense(config, folder, sensor)
    return out


def _scalable(config, runs, sm, domain, exact, timings) -> dict:
    """The denser-data sweep (corrected readings, and as recorded) and the reduced-rank GP
    against the exact one (``exact``: its mean and variance on the test run) on the same
    readings."""
    test = runs[config.test_run]
    kernels = st.kernels_of(sm.gp)
    fields = {r: sm.corrected(r, runs[r]) for r in config.train_runs}
    corrected_test = sm.corrected(config.test_run, test)
    variants = [("corrected", fields, corrected_test, kernels)]
    if config.offset_calibration and config.sweep_raw:
        raw_fields = {r: runs[r].field for r in config.train_runs}
        variants.append(("raw", raw_fields, test.field, st.kernels_of(sm.raw)))
    out: dict = {"sweep": []}
    for variant, train_fields, truth, k in variants:
        for row in _denser(config, runs, (variant, train_fields, truth), k, domain, timings):
            out["sweep"].append({"readings": variant} | row)
            if variant == "corrected" and row["step"] == 1:
                out["hilbert_all"] = row
    if config.hilbert:
        x, y = st.stack_runs(runs, config.train_runs, fields, config.thinning)
        gp = st.hilbert_fit(x, y, kernels, domain, config.hilbert_tolerance)
        m, v = st.predict(gp, test.positions)
        mean, var = exact
        out["hilbert_same"] = {
            "rmse": st.held_out(corrected_test, m, v, kernels)["rmse"],
            "max_abs_mean_difference": float(np.abs(m - mean).max()),
            "max_abs_sd_difference": float(np.abs(np.sqrt(v) - np.sqrt(var)).max()),
        }
    return out


def _denser(config, runs, data, kernels, domain, timings) -> list[dict]:
    """Held-out scores of maps with the same hyperparameters on denser or sparser readings
    (every step-th): the exact GP up to EXACT_LIMIT readings, the reduced-rank GP above.
    data: (label, training fields per run, the test run's readings)."""
    label, fields, truth = data
    positions = runs[config.test_run].positions
    rows = []
    for step in sorted(set(config.sweep) | ({1} if config.hilbert else set())):
        x, y = st.stack_runs(runs, config.train_runs, fields, step)
        if len(x) > EXACT_LIMIT and not config.hilbert:
            continue
        start = time.perf_counter()
        if len(x) > EXACT_LIMIT:
            gp = st.hilbert_fit(x, y, kernels, domain, config.hilbert_tolerance)
            method = "hilbert"
        else:
            gp, method = st.fit_fixed(x, y, kernels), "exact"
        score = st.held_out(truth, *st.predict(gp, positions), kernels)
        timings[f"sweep_{label}_{step}_seconds"] = time.perf_counter() - start
        row = {"step": step, "points": len(x), "method": method, "rmse": score["rmse"]}
        row |= {"in2_all": score["in2_all"], "mlpd": score["mlpd"]}
        if method == "hilbert":
            row["basis"] = int(gp[0].basis_size)
        rows.append(row)
    return rows


def _offsets_vs_invensense(config, folder: Path, sensor: str) -> list[dict]:
    """Per run: the sensor's mean reading minus the InvenSense's at the same instants."""
    mine = st.load_runs(folder, sensor, st.all_runs(config))
    ref = st.load_runs(folder, "invensense", st.all_runs(config))
    rows = []
    for r, s in mine.items():
        at = np.column_stack(
            [np.interp(s.times, ref[r].times, ref[r].field[:, c]) for c in range(3)]
        )
        d = s.field - at
        rows.append({"run": r, "mean": d.mean(axis=0).tolist(), "sd": d.std(axis=0).tolist()})
    return rows


def travel_subsample(positions: np.ndarray, step: float) -> np.ndarray:
    """Indices of the positions kept one per ``step`` m of travel (the first always)."""
    keep, last = [0], positions[0]
    for i in range(1, len(positions)):
        if math.hypot(*(positions[i] - last)) >= step:
            keep.append(i)
            last = positions[i]
    return np.asarray(keep)


def noisy_odometry(truth: np.ndarray, rng, scale_sd: float, heading_walk: float) -> np.ndarray:
    """Odometry from true poses (x, y, heading): every distance times one scale error
    1 + N(0, scale_sd^2) for the run, the heading's increments plus a random walk of
    N(0, heading_walk^2 per metre of travel)."""
    d = np.diff(truth[:, :2], axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    turn = np.angle(np.exp(1j * np.diff(truth[:, 2])))
    scale = 1.0 + rng.normal(0.0, scale_sd)
    walk = np.cumsum(rng.normal(0.0, heading_walk * np.sqrt(length)))
    heading = truth[0, 2] + np.concatenate([[0.0], np.cumsum(turn) + walk])
    steps = scale * length[:, None] * np.column_stack([np.cos(heading[1:]), np.sin(heading[1:])])
    xy = truth[0, :2] + np.vstack([np.zeros(2), np.cumsum(steps, axis=0)])
    return np.column_stack([xy, heading])


def mcl_task(config, folder: Path, sensor: str, seed: int, timings: dict) -> dict:
    """Magnetic-map MCL (eqs. 6.17-6.18) along the test run, one update per mcl_step of
    travel, against odometry alone, for mcl_seeds odometry-noise seeds."""
    runs = st.load_runs(folder, sensor, st.all_runs(config))
    sm = st.static_map(config, folder, sensor)
    test = runs[config.test_run]
    lower, upper = bounds({r: runs[r] for r in config.train_runs}, 0.5)
    gps = sm.gp if isinstance(sm.gp, list) else [sm.gp]
    start = time.perf_counter()
    field_map = MagneticFieldMap.from_gp(gps, lower, upper, config.map_resolution, units="uT")
    timings["mcl_map_seconds"] = time.perf_counter() - start
    keep = travel_subsample(test.positions, config.mcl_step)
    xy = test.positions[keep]
    readings = sm.corrected(config.test_run, test)[keep][:, None, :]
    readings = np.roll(readings, -config.mcl_reading_lag, axis=0)
    d = np.diff(xy, axis=0)
    heading = np.arctan2(d[:, 1], d[:, 0])  # of the step that arrives at each update
    truth = np.column_stack([xy, np.concatenate([heading[:1], heading])])
    mcl = MagneticMclConfig(particles=config.particles, alphas=tuple(config.alphas))
    rows, trajectories = [], []
    start = time.perf_counter()
    for k in range(config.mcl_seeds):
        stream = np.random.SeedSequence([seed, k])
        rng = np.random.default_rng(stream)
        odometry = noisy_odometry(truth, rng, config.odometry_scale_sd, config.heading_walk)
        filter_seed = int(stream.generate_state(1, np.uint64)[0])
        result = localize_on_magnetic_map(
            field_map,
            odometry,
            readings,
            [[0.0, 0.0]],
            initial_pose=truth[0],
            config=mcl,
            seed=filter_seed,
            frame="world",
        )
        est = result.estimates
        e = np.hypot(*(est[:, :2] - xy).T)
        eo = np.hypot(*(odometry[:, :2] - xy).T)
        eh = np.abs(np.angle(np.exp(1j * (est[:, 2] - truth[:, 2]))))
        rows.append(
            {
                "noise_seed": k,
                "mcl_mean": float(e.mean()),
                "mcl_max": float(e.max()),
                "odometry_mean": float(eo.mean()),
                "odometry_max": float(eo.max()),
                "odometry_final": float(eo[-1]),
                "heading_mean": float(eh.mean()),
                "heading_max": float(eh.max()),
                "resamplings": int(result.resamplings),
                "mcl_error": np.round(e, 3).tolist(),
                "odometry_error": np.round(eo, 3).tolist(),
            }
        )
        trajectories.append(
            {
                "mcl": np.round(est[:, :2], 3).tolist(),
                "odometry": np.round(odometry[:, :2], 3).tolist(),
            }
        )
    timings["mcl_filter_seconds"] = time.perf_counter() - start
    travel = np.concatenate([[0.0], np.cumsum(np.hypot(d[:, 0], d[:, 1]))])
    return {
        "sensor": sensor,
        "updates": len(keep),
        "travel": np.round(travel, 3).tolist(),
        "truth": np.round(xy, 3).tolist(),
        "rows": rows,
        "trajectories": trajectories[:1],
    }


def _walk_rotations(path: Path) -> np.ndarray:
    """(n, 3, 3) sensor-to-world rotations of a Kok-Solin walk (its reader's convention)."""
    q = np.asarray(scipy.io.loadmat(path)["quat"], dtype=float)
    return quaternion_to_matrix(q / np.linalg.norm(q, axis=1, keepdims=True)) @ SENSOR_TO_BODY


def sensor_offset(field: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """Least-squares sensor-frame offset b (3,) of world-frame readings f_k = c + R_k b + noise,
    c a constant world field: the offset turns with the device, so no constant mean holds it."""
    n = len(field)
    a = np.zeros((3 * n, 6))
    a[:, :3] = np.tile(np.eye(3), (n, 1))
    a[:, 3:] = rotations.reshape(3 * n, 3)
    solution, *_ = np.linalg.lstsq(a, field.reshape(-1), rcond=None)
    return solution[3:]


def walks_task(config, folder: Path, timings: dict) -> dict:
    """3-D maps of each walk's first part, predicting the rest (raw, and less a sensor-frame
    offset fitted on the first part)."""
    out = []
    for name in config.walks:
        path = folder / "kok_1d" / f"{name}.mat"
        walk = read_kok_walk(path)
        cut = int(round(config.walk_train_share * len(walk)))
        rotations = _walk_rotations(path)
        variants = {"raw": (walk.field, np.zeros(3))}
        if config.walk_offset_calibration:
            b = sensor_offset(walk.field[:cut], rotations[:cut])
            variants["corrected"] = (walk.field - np.einsum("nij,j->ni", rotations, b), b)
        row = {
            "walk": name,
            "samples": len(walk),
            "train": cut,
            "positions": np.round(walk.positions, 3).tolist(),
        }
        for label, (field, b) in variants.items():
            start = time.perf_counter()
            gp = ExactGP.fit(
                walk.positions[:cut],
                field[:cut],
                per_component=config.per_component,
                max_points=config.max_points,
                restarts=config.restarts,
                seed=config.gp_seed,
            )
            mean, var = gp.predict(walk.positions[cut:])
            timings[f"walk_{name}_{label}_seconds"] = time.perf_counter() - start
            kernels = st.kernels_of(gp)
            score = st.held_out(field[cut:], mean, var, kernels)
            covered = (var < st.COVERED * st.sigma_f2(kernels)).all(axis=1)
            near = (
                st.held_out(field[cut:][covered], mean[covered], var[covered], kernels)
                if covered.any()
                else None
            )
            row[label] = {
                "offset": b.tolist(),
                "kernels": [k.to_dict() for k in kernels],
                "score": score,
                "covered_share": float(covered.mean()),
                "covered_rmse": near["rmse"] if near else None,
                "measured": np.round(field[cut:], 2).tolist(),
                "predicted": np.round(mean, 2).tolist(),
                "sd": np.round(np.sqrt(var + st.sigma_n(kernels) ** 2), 3).tolist(),
            }
            if label == list(variants)[-1]:
                height = float(np.median(walk.positions[:cut, 2]))
                lower, upper = (
                    walk.positions[:, :2].min(axis=0) - 0.5,
                    walk.positions[:, :2].max(axis=0) + 0.5,
                )
                row["slice_height"] = height
                row["grid"] = st.grid_prediction(gp, lower, upper, config.grid_resolution, height)
        out.append(row)
    return {"walks": out}
