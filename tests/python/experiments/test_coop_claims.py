# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""coop-forms' claims on its anchors (dead reckoning, CPS-II, the planner, 3-D) decided on
synthetic records of the form its trials write: each criterion holds on records where it must
and fails on records where it must not, with the per-repeat values computed by hand."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from _helpers.cli_main import kiseki
from kiseki_experiments.coop.coop_claims import CPS2_DISTANCE, claim_evidence
from kiseki_experiments.coop.coop_forms import EXPERIMENT, _groups
from kiseki_experiments.harness.verdict import judge

REPEATS = 10
ANCHORS = ("dead_reckoning", "cps2", "planner", "three_d")


def _records(rng, sweep_mm, dead_mm, planner_mm, cps2_mm, across_over_planar):
    """Records: a moves sweep per form (three settings, the best form 1's first, at
    ``sweep_mm``),
    dead reckoning, the planner, CPS-II per form and 3-D per form, each with per-repeat means
    near the given ones (1 % noise)."""

    def near(mm):
        return list(mm / 1000 * (1 + 0.01 * rng.standard_normal(REPEATS)))

    rows = []
    for form, reading, moves in ((1, "pair-scout", (3, 5, 7)), (2, "", (5, 7, 9))):
        for k, n in enumerate(moves):
            means = near(sweep_mm * (1 + 0.5 * k) * (1.0 if form == 1 else 1.1))
            rows.append({"kind": "sweep", "form": form, "reading": reading, "moves": n,
                         "mean_error_m": float(np.mean(means)), "repeat_mean_m": means,
                         "repeat_along_rms_m": means})  # fmt: skip
    rows.append({"kind": "dead-reckoning", "form": 0, "moves": 0, "distance_m": 11.0,
                 "mean_error_m": dead_mm / 1000, "repeat_mean_m": near(dead_mm)})  # fmt: skip
    rows.append({"kind": "planner", "form": 0, "moves": 5, "mean_error_m": planner_mm / 1000,
                 "repeat_mean_m": near(planner_mm)})  # fmt: skip
    for form in (1, 2):
        means = near(cps2_mm * form)  # form 2 twice form 1's: the smaller is form 1's
        rows.append({"kind": "cps2", "form": form, "moves": 9, "distance_m": CPS2_DISTANCE,
                     "mean_error_m": float(np.mean(means)), "repeat_mean_m": means})  # fmt: skip
        planar = near(60.0)
        across = list(np.asarray(planar) * across_over_planar)
        rows.append({"kind": "3d", "form": form, "moves": 5, "horizontal_m": np.mean(across),
                     "planar_m": np.mean(planar), "repeat_horizontal_m": across,
                     "repeat_planar_m": planar})  # fmt: skip
    frame = pd.DataFrame(rows)
    frame["reading"] = frame["reading"].fillna("")
    return frame


def _verdicts(ok: pd.DataFrame) -> dict[str, list[str]]:
    evidence = claim_evidence(_groups(ok, "sweep", "moves"), {}, ok)
    keys = {s.claim: s.key for s in EXPERIMENT.claims}
    out: dict[str, list[str]] = {}
    for v in judge(EXPERIMENT.claims, [e for e in evidence if e.key in ANCHORS], seed=0):
        out.setdefault(keys[v.claim.split(" [")[0]], []).append(v.verdict)
    return out


@pytest.mark.parametrize("draw", range(3))
def test_the_anchor_claims_hold_where_they_must_and_fail_where_they_must_not(draw):
    rng = np.random.default_rng(draw)
    # cooperative 55 mm against dead reckoning's 176; planner 50 against 55; CPS-II 20 mm
    # over 21.5 m (0.09 %); 3-D 5 % above planar
    good = _verdicts(_records(rng, 55.0, 176.0, 50.0, 20.0, 1.05))
    assert good == {k: ["holds"] * (2 if k == "three_d" else 1) for k in ANCHORS}, good
    # cooperative 550 mm (bearings 10x worse) against 176; planner 900 against 550; CPS-II
    # 170 mm (0.8 %); 3-D 50 % above planar
    bad = _verdicts(_records(rng, 550.0, 176.0, 900.0, 170.0, 1.5))
    assert bad == {k: ["fails"] * (2 if k == "three_d" else 1) for k in ANCHORS}, bad


def test_the_anchor_evidence_is_the_per_repeat_ratio_computed_by_hand():
    ok = _records(np.random.default_rng(7), 55.0, 176.0, 50.0, 20.0, 1.05)
    evidence = {e.key + e.subject: e for e in claim_evidence(_groups(ok, "sweep", "moves"), {}, ok)}
    # the sweep's best setting over all repeats (form 1, 3 moves: the first of its sweep)
    sweep = np.array([r for r in ok.loc[ok["kind"] == "sweep", "repeat_mean_m"]])
    sweep = sweep[np.argmin(sweep.mean(axis=1))]
    assert "form 1 (pair-scout), 3 moves" in evidence["planner"].shown
    dead = np.asarray(ok.loc[ok["kind"] == "dead-reckoning", "repeat_mean_m"].iloc[0])
    planner = np.asarray(ok.loc[ok["kind"] == "planner", "repeat_mean_m"].iloc[0])
    cps2 = np.array([r for r in ok.loc[ok["kind"] == "cps2", "repeat_mean_m"]]).min(axis=0)
    np.testing.assert_allclose(evidence["dead_reckoning"].values, sweep / dead)
    np.testing.assert_allclose(evidence["planner"].values, planner / sweep)
    np.testing.assert_allclose(evidence["cps2"].values, 100 * cps2 / CPS2_DISTANCE)
    three = ok[ok["kind"] == "3d"].iloc[1]
    want = np.asarray(three["repeat_horizontal_m"]) / np.asarray(three["repeat_planar_m"])
    np.testing.assert_allclose(evidence["three_dform 2"].values, want)


@pytest.mark.parametrize("moves", ["2", "2,3,4"])
def test_angle_moves_without_two_counts_is_refused_naming_the_key(moves, monkeypatch, capsys):
    """The trial count is taken from the settings before the preflight: a wrong arity was a
    bare 'not enough values to unpack' there."""
    status, _, err = kiseki(
        monkeypatch, capsys, "experiment", "run", "coop-forms", "--runs", "1",
        "--set", f"angle_moves={moves}",
    )  # fmt: skip
    assert status != 0 and len(err.strip().splitlines()) == 1
    assert "angle_moves takes 2 counts (form 1, form 2)" in err
