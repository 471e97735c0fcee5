# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-aalto's held-out map claims, decided over leave-one-run-out folds: each static run (the
training runs and the test run, 1-5 by default) held out in turn, the thesis' map (one exact GP
per component, eqs. 6.7-6.15, on every ``thinning``-th reading, the robot-frame offset estimated
from the training runs alone) fitted on the other static runs of the reference sensor, and the
held-out run predicted at every reading. One fold is one trial and one value of each claim.

Each claim keeps the criterion of the point verdict it replaces (a map of runs 1-4 scored on
run 5 only), now with an interval over the folds:

* the RMSE per component under half the held-out run's own SD (what a constant guess misses by);
* the share of errors inside 2 and 1 predictive sigma (sigma^2 = variance of the noise-free
  field + sigma_n^2) near the Gaussian 95.4 % and 68.3 %;
* the reduced-rank GP (eq. 6.15's Hilbert-space basis) on the same readings and
  hyperparameters within 2 % of the exact GP's RMSE per component.

Controls: the map replaced by the training readings' mean (``fold_model=mean``); the posterior
variance replaced by the prior's, sigma_f^2 (``fold_variance=prior``: what the readings say
about where the map is sure is dropped); the reduced-rank basis cut at a spectral tolerance of
0.5 (``hilbert_tolerance=0.5``)."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki_experiments.gp import gp_aalto_steps as st
from kiseki_experiments.gp.gp_aalto_tasks import bounds
from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion, Evidence

__all__ = [
    "FOLD_CLAIMS",
    "FOLD_MODELS",
    "FOLD_VARIANCES",
    "fold_evidence",
    "fold_table",
    "fold_task",
    "static_runs",
]

FOLD_MODELS = ("gp", "mean")
FOLD_VARIANCES = ("posterior", "prior")
# the controls run the folds alone, at the small test's size (a fold is then 2-4 s)
_SMALL = ("thinning=100", "max_points=300", "restarts=0")


def static_runs(config) -> list[int]:
    """The runs held out in turn: the training runs and the test run, in order."""
    return sorted({*config.train_runs, config.test_run})


def fold_task(config, folder: Path, sensor: str, held_out: int, timings: dict) -> dict:
    """One fold: the map of the other static runs scored on every reading of ``held_out``."""
    others = [r for r in static_runs(config) if r != held_out]
    fold = dataclasses.replace(config, train_runs=others, test_run=held_out)
    sm = st.static_map(fold, folder, sensor)
    runs = st.load_runs(folder, sensor, st.all_runs(fold))
    test = runs[held_out]
    truth = sm.corrected(held_out, test)
    kernels = st.kernels_of(sm.gp)
    start = time.perf_counter()
    prior = np.broadcast_to(st.sigma_f2(kernels), truth.shape)
    if config.fold_model == "mean":  # the control: the training readings' mean everywhere
        x, y = st.stack_runs(runs, others, {r: sm.corrected(r, runs[r]) for r in others}, 1)
        mean, var = np.broadcast_to(y.mean(axis=0), truth.shape), prior
    else:
        mean, var = st.predict(sm.gp, test.positions)
    if config.fold_variance == "prior":  # the control: no shrinkage by the readings
        var = prior
    exact = st.held_out(truth, mean, var, kernels)
    timings["fold_predict_seconds"] = time.perf_counter() - start
    out = {"sensor": sensor, "held_out": held_out, "train_runs": others, "corrected": exact}
    out["offset"] = sm.offset.tolist()
    out["fit_seconds"] = sm.fit_seconds
    if config.hilbert:
        fields = {r: sm.corrected(r, runs[r]) for r in others}
        x, y = st.stack_runs(runs, others, fields, config.thinning)
        lower, upper = bounds(runs, 0.3)  # the map task's box (gp_aalto_tasks.map_task)
        reach = 4 * max(k.length_scale for k in (*kernels, *st.kernels_of(sm.raw)))
        domain = (lower - reach, upper + reach)
        gp = st.hilbert_fit(x, y, kernels, domain, config.hilbert_tolerance)
        out["hilbert_same"] = st.held_out(truth, *st.predict(gp, test.positions), kernels)
        out["hilbert_basis"] = int(gp[0].basis_size)
    return out


def _ratio(fold: dict) -> float:
    s = fold["corrected"]
    return max(r / sd for r, sd in zip(s["rmse"], s["sd"], strict=True))


def _hilbert_gap(fold: dict) -> float:
    h, e = fold["hilbert_same"]["rmse"], fold["corrected"]["rmse"]
    return max(abs(a / b - 1) for a, b in zip(h, e, strict=True))


def fold_table(folds: list[dict]) -> pd.DataFrame:
    """One row per fold: the held-out run, RMSE and SD per component, coverage, the offset."""
    rows = []
    for f in folds:
        s = f["corrected"]
        row = {"held_out": f["held_out"], "train_runs": " ".join(map(str, f["train_runs"]))}
        row |= {f"rmse_{c}": s["rmse"][i] for i, c in enumerate("xyz")}
        row |= {f"sd_{c}": s["sd"][i] for i, c in enumerate("xyz")}
        row |= {"rmse_over_sd": _ratio(f), "in1_all": s["in1_all"], "in2_all": s["in2_all"]}
        row |= {"bx_forward": f["offset"][0], "by_left": f["offset"][1]}
        if "hilbert_same" in f:
            row |= {f"hilbert_rmse_{c}": f["hilbert_same"]["rmse"][i] for i, c in enumerate("xyz")}
            row |= {"hilbert_basis": f["hilbert_basis"], "hilbert_gap": _hilbert_gap(f)}
        rows.append(row)
    return pd.DataFrame(rows)


def fold_evidence(folds: list[dict]) -> list[Evidence]:
    """One value per fold for each held-out claim."""
    if not folds:
        return []
    subject = f"{folds[0]['sensor']}, runs {' '.join(str(f['held_out']) for f in folds)}"
    out = [
        Evidence.of("held-out-rmse", [_ratio(f) for f in folds], subject=subject),
        Evidence.of("held-out-in2", [f["corrected"]["in2_all"] for f in folds], subject=subject),
        Evidence.of("held-out-in1", [f["corrected"]["in1_all"] for f in folds], subject=subject),
    ]
    if all("hilbert_same" in f for f in folds):
        out.append(Evidence.of("reduced-rank-equals-exact", [_hilbert_gap(f) for f in folds]))
    return out


_PRIOR = Control(
    name="the posterior variance replaced by the prior's (sigma_f^2)",
    overrides=(*_SMALL, "fold_variance=prior", "hilbert=false"),
    runs=5,
    why="the prior SD (the field's spread, several times the map's error on these tracks) "
    "puts nearly every error inside 1 and 2 sigma: far above a Gaussian's 68 and 95 %",
)

FOLD_CLAIMS = (
    ClaimSpec(
        key="held-out-rmse",
        claim="a map of the other static runs predicts the held-out run: RMSE per component "
        "under half the run's own SD (each static run held out in turn)",
        unit="largest RMSE / SD of the three components",
        criterion=Criterion(
            paper_value="thesis Table 6.2: mean error 0.65-1.44 uT on its hall",
            compare="<=",
            threshold=0.5,
            why="half of what a constant guess misses by (the run's SD): a map that is worth "
            "having; the thesis scores its hall, not this room, so its numbers are not the bound",
            bounds=(0.0, np.inf),
        ),
        control=Control(
            name="the map replaced by the training readings' mean",
            overrides=(*_SMALL, "fold_model=mean", "hilbert=false"),
            runs=5,
            why="a constant map misses the held-out run by its SD and more (the runs' means "
            "differ): the ratio is about 1",
        ),
        measure="one fold's largest RMSE / SD",
    ),
    ClaimSpec(
        key="held-out-in2",
        claim="the held-out map's predictive variance is calibrated: errors inside 2 sigma",
        unit="share of readings",
        criterion=Criterion(
            paper_value="95.4 % (Gaussian)",
            compare="within",
            threshold=0.945,
            tolerance=0.045,
            why="90-99 %: the point verdict's bound; the errors along a track are correlated, "
            "so a fold's share moves by a few points",
            bounds=(0.0, 1.0),
        ),
        control=_PRIOR,
        measure="one fold's share of errors inside 2 sigma",
    ),
    ClaimSpec(
        key="held-out-in1",
        claim="... and inside 1 sigma",
        unit="share of readings",
        criterion=Criterion(
            paper_value="68.3 % (Gaussian)",
            compare="within",
            threshold=0.683,
            tolerance=0.10,
            why="68.3 +- 10 points: the point verdict's bound",
            bounds=(0.0, 1.0),
        ),
        control=_PRIOR,
        measure="one fold's share of errors inside 1 sigma",
    ),
    ClaimSpec(
        key="reduced-rank-equals-exact",
        claim="the reduced-rank GP equals the exact GP on the same readings and hyperparameters "
        "(RMSE per component within 2 %)",
        unit="largest |RMSE ratio - 1| of the three components",
        criterion=Criterion(
            paper_value="(issue: accuracy against the exact GP on the same data)",
            compare="<=",
            threshold=0.02,
            why="2 %: well under the folds' spread, well over the basis' truncation at the "
            "default spectral tolerance",
            bounds=(0.0, np.inf),
        ),
        control=Control(
            name="the reduced-rank basis cut at a spectral tolerance of 0.5",
            overrides=(*_SMALL, "hilbert_tolerance=0.5"),
            runs=5,
            why="only the basis functions whose spectral density is above half the peak: "
            "length scales several times the fitted one, a map too smooth for the field",
        ),
        measure="one fold's largest relative RMSE difference",
    ),
)
