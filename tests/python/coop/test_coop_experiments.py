# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The cooperative-positioning experiments: their claims and command line, the paper's
analytic optimum (eqs. 5-6) and the claims' per-repeat minima against brute force."""

from __future__ import annotations

import numpy as np
import pytest


def test_coop_experiment_claims_and_cli(tmp_path) -> None:
    import subprocess
    import sys

    import pandas as pd

    from kiseki_experiments.harness.runner import run_experiment

    small = ["form1_moves=3,5,7,9", "form2_moves=5,7", "angles_deg=45,55"]
    with pytest.raises(ValueError, match="22 settings"):  # 4 x 2 + 2 moves, 2 x 3 angles, 6
        run_experiment(
            "coop-forms",
            runs=23,
            overrides=small,
            out=tmp_path / "too_many",
            progress=False,
        )
    run = run_experiment(
        "coop-forms",
        seed=0,
        overrides=[*small, "dead_reckoning_runs=50"],
        out=tmp_path / "c",
        progress=False,
    )
    assert run.failed == 0
    claims = pd.read_csv(run.run_dir / "claims.csv").set_index("claim")
    lower = claims.filter(like="lower minimum", axis=0)
    assert len(lower) == 2  # each reading of form 1 against form 2
    table = pd.read_csv(run.run_dir / "tables" / "sweep.csv")
    assert set(table["form"]) == {1, 2} and len(table) == 10
    angles = pd.read_csv(run.run_dir / "tables" / "angle_sweep.csv")
    assert sorted(angles["angle_deg"].round(6).unique()) == [45.0, 55.0] and len(angles) == 6
    # the crossing reading's weakest triangle is wider than pair and scout's at every angle
    sight = angles[angles["form"] == 1].pivot(index="angle_deg", columns="reading",
                                              values="min_sight_angle_deg")  # fmt: skip
    assert (sight["crossing"] > sight["pair-scout"]).all()
    assert (table["mean_error_m"] > 0).all() and (table["mean_error_m"] < 1.0).all()
    dead = pd.read_csv(run.run_dir / "tables" / "dead_reckoning.csv")
    assert dead["mean_error_m"].iloc[0] > table["mean_error_m"].min()
    planner = pd.read_csv(run.run_dir / "tables" / "planner.csv")
    # the planner beats pair and scout and form 2; the crossing reading of form 1 can beat it
    first = table[table["reading"].fillna("") != "crossing"]
    assert planner["predicted_rms_m"].iloc[0] < first["predicted_rms_m"].min()
    done = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "coop", "simulate", "--form", "2", "--moves", "7",
         "--runs", "50", "--plot", str(tmp_path / "g.png")],
        capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "error at the goal mean" in done.stdout and (tmp_path / "g.png").stat().st_size > 5000
    bad = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "coop", "simulate", "--form", "1", "--moves", "4"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert bad.returncode == 1 and bad.stderr.startswith("kiseki: error: form 1 takes an odd")
    both = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "coop", "simulate", "--planner", "--moves", "5"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert both.returncode == 1 and "--planner chooses the moves itself" in both.stderr
    chosen = subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "coop", "simulate", "--planner", "--runs", "20"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert chosen.returncode == 0 and chosen.stdout.startswith("planner, 5 moves")


def test_the_papers_analytic_optimum_n_equals_tan_theta_e() -> None:
    from kiseki_experiments.coop.coop_optimum import analytic_optimum

    n, theta, _ = analytic_optimum(10.0, 1.0)
    assert (n, round(theta, 6)) == (10, 45.0)  # eqs. 5-6 for the paper's goal
    assert analytic_optimum(6.0, 1.0)[0] == 6  # n = tan(theta_e) = L / d elsewhere too
    assert analytic_optimum(10.0, 2.0)[0] == 5


def test_per_repeat_argmin_against_brute_force() -> None:
    import pandas as pd

    from kiseki_experiments.coop.coop_claims import _per_repeat_argmin, _per_repeat_min

    rng = np.random.default_rng(3)
    values = rng.uniform(0.01, 0.1, (6, 5))  # 6 settings, 5 repeats
    rows = pd.DataFrame({"moves": [1, 3, 5, 7, 9, 11], "repeat_mean_m": list(values)})
    want = [rows["moves"][int(np.argmin(values[:, r]))] for r in range(5)]
    assert _per_repeat_argmin(rows, "moves", "repeat_mean_m").tolist() == want
    assert _per_repeat_min(rows).tolist() == values.min(axis=0).tolist()
