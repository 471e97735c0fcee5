# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""gp-aalto's map-change detection (runs 6-9, shelves brought in): each run's share of readings
beyond change_sigma under the static map, the training runs held out in turn as the reference,
and, for each changed run, whether it passes where the other changed runs departed from the map
(a run that reads the static field there saw no change on its own track)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from kiseki_experiments.gp import gp_aalto_steps as st

__all__ = ["change_task"]


def _departures(config, gp, field, positions, kernels):
    """(covered (n,), beyond change_sigma (n,), standardized residuals (n, 3), log predictive
    density (n,)) of a run's readings under a map."""
    mean, var = st.predict(gp, positions)
    covered = (var < st.COVERED * st.sigma_f2(kernels)).all(axis=1)
    s2 = var + st.sigma_n(kernels) ** 2
    z = np.abs(field - mean) / np.sqrt(s2)
    outside = (z > config.change_sigma).any(axis=1)
    lpd = -0.5 * ((field - mean) ** 2 / s2 + np.log(2 * math.pi * s2)).sum(axis=1)
    return covered, outside, z, lpd


def _change_score(covered, outside, z, lpd, positions) -> dict:
    flagged = positions[covered & outside][::10]
    return {
        "coverage": float(covered.mean()),
        "rms_z": float(np.sqrt((z[covered] ** 2).mean())) if covered.any() else float("nan"),
        "share": float(outside[covered].mean()) if covered.any() else float("nan"),
        "mlpd": float(lpd[covered].mean()) if covered.any() else float("nan"),
        "flagged": np.round(flagged, 2).tolist(),
        "track": np.round(positions[::25], 2).tolist(),
    }


def change_task(config, folder: Path, sensor: str, timings: dict) -> dict:
    """Each run's share of readings beyond change_sigma under the map: the training runs held
    out in turn against the others (the reference), the other runs against all of them."""
    runs = st.load_runs(folder, sensor, st.all_runs(config))
    sm = st.static_map(config, folder, sensor)
    kernels = st.kernels_of(sm.gp)
    fields = {r: sm.corrected(r, runs[r]) for r in runs}
    rows = []
    for r in config.train_runs:
        others = [q for q in config.train_runs if q != r]
        gp = st.fit_fixed(*st.stack_runs(runs, others, fields, config.thinning), kernels)
        scored = _departures(config, gp, fields[r], runs[r].positions, kernels)
        rows.append(
            {"run": r, "role": "static, held out"} | _change_score(*scored, runs[r].positions)
        )
    masks = {}
    for r in [config.test_run, *config.changed_runs]:
        role = "static, test" if r == config.test_run else "shelves moved in"
        scored = _departures(config, sm.gp, fields[r], runs[r].positions, kernels)
        masks[r] = scored[:2]
        rows.append({"run": r, "role": role} | _change_score(*scored, runs[r].positions))
    changed = [row for row in rows if row["role"] == "shelves moved in"]
    for row in changed:
        others = [np.asarray(o["flagged"]).reshape(-1, 2) for o in changed if o is not row]
        row |= _where_others_changed(runs[row["run"]].positions, *masks[row["run"]], others)
    reference = max(row["share"] for row in rows[: len(config.train_runs)])
    return {"sensor": sensor, "rows": rows, "threshold": config.change_factor * reference}


NEAR_OTHERS = 0.2  # m: a reading this close to another changed run's departures is "there"


def _where_others_changed(positions, covered, outside, others) -> dict:
    """Whether a changed run passes where the other changed runs departed from the map: the
    share of its covered readings within NEAR_OTHERS of their flagged readings (every 4th),
    and the share of those beyond change_sigma (a run that reads the static field there saw no
    change on its own track)."""
    flagged = [o for o in others if len(o)]
    if not flagged:
        return {"near_others_share": float("nan"), "near_others_departed": float("nan")}
    d, _ = cKDTree(np.vstack(flagged)[::4]).query(positions)
    near = covered & (d < NEAR_OTHERS)
    return {
        "near_others_share": float(near.sum() / max(covered.sum(), 1)),
        "near_others_departed": float(outside[near].mean()) if near.any() else float("nan"),
    }
