# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Every number in the teaching experiments' report text comes from the run: the analyses of
exp1-corridor, exp2-turn and exp3-boxes applied to three different sets of trials (records of
the form their trial writes, values drawn at random) give notes whose numbers change with the
data; a number found in every draw's notes must be one of the constants the code cites (the
thesis' values, the stop rule, the offsets the likelihood profile is taken at). A fixed figure
typed into the prose (a share measured once, on another run) is in all of them and fails.
Exp. 2's claims on trials with the thesis' Table 4.5 numbers hold, and fail when the proposals
are conventional's runs (its negative control)."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from kiseki_experiments.harness.verdict import judge
from kiseki_experiments.teach import teach_playback as tp

METHODS = ["conventional", "proposal1", "proposal2", "both"]
MARKS = ["P0", "P1", "P2", "T1", "T2", "G"]


def _trials(rng: np.random.Generator, runs: int = 5) -> pd.DataFrame:
    rows = []
    for i in range(runs):
        r = {"trial": i, "error": None, "final_leg_m": rng.uniform(2.0, 4.0)}
        r |= {"final_leg_boxes_left": 1, "final_leg_boxes_right": 1}
        for band in ("plane", "band"):
            for key in tp.TAUGHT_SHARES:
                r[f"taught_{band}_{key}"] = rng.uniform(0.0, 0.1)
        for m in METHODS:
            dx, dy = rng.normal(0.0, 0.07, 2)
            r |= {f"{m}_stop_dx": dx, f"{m}_stop_dy": dy, f"{m}_stop_error": np.hypot(dx, dy)}
            r |= {f"{m}_estimate_error": rng.uniform(0, 0.1), f"{m}_reached": True}
            r |= {f"{m}_goal_peak_along": rng.uniform(-0.1, 0.1)}
            r |= {f"{m}_goal_peak_side": rng.uniform(-0.1, 0.1)}
            for off in tp.PROFILE_OFFSETS:
                for axis in ("along", "side"):
                    r[f"{m}_goal_like_{axis}_{off:+.2f}"] = rng.uniform(0.5, 1.0)
            r |= {f"{m}_nobox_stop_dx": dx + rng.normal(0, 0.02)}
            r |= {f"{m}_nobox_stop_dy": dy + rng.normal(0, 0.02)}
            for name in MARKS:
                for kind in ("loc", "odo"):
                    for axis in ("dx", "dy"):
                        r[f"{m}_{name}_{kind}_{axis}"] = rng.normal(0.0, 0.1)
        rows.append(r)
    return pd.DataFrame(rows)


@pytest.fixture(autouse=True)
def _no_figures(monkeypatch):
    """The notes are what is tested here; drawing the figures would take most of the time."""
    for name in ("stop_figure", "_profile_figure"):
        monkeypatch.setattr(tp, name, lambda config, trials, figures: figures / "none.png")


def _numbers(text: str) -> set[float]:
    return {float(t) for t in re.findall(r"\d+(?:\.\d+)?", text)}


def _cited_constants() -> set[float]:
    """The numbers the code cites by name (each shown as written, in m, %, runs or deg)."""
    out = {tp.STOP_TOLERANCE_M, float(tp.THESIS_RUNS), abs(tp.THESIS_ODOMETRY_Y_WORST_M)}
    out |= {abs(v) for v in tp.THESIS_ODOMETRY_P2_M}
    for values in tp.THESIS_TABLE_4_5.values():
        out |= {float(v) for v in values}
    out |= {float(v) for v in tp.BOX_SIZE_M} | {float(v) for v in tp.BOX_OFFSET_M}
    out |= {0.1, 0.3}  # the profile offsets the drops are taken at (table `diagnostics`)
    out |= {1.0}  # 1 deg of heading error, turned into metres over the final leg
    out |= {95.0}  # the confidence level of every interval
    out |= {4.5, 4.6, 4.7, 3.0, 2.0, 8.0}  # the thesis' table numbers; 3 boxes; 8 neighbours
    return out


@pytest.mark.parametrize(
    ("analyze", "config"),
    [
        (tp.analyze_exp1, tp.Exp1Config()),
        (tp.analyze_exp2, tp.Exp2Config(methods=METHODS)),
        (tp.analyze_exp3, tp.Exp3Config()),
    ],
    ids=["exp1", "exp2", "exp3"],
)
def test_every_number_in_the_notes_changes_with_the_trials_or_is_a_cited_constant(
    tmp_path, analyze, config
):
    notes = []
    for draw in (1, 2, 3):  # three draws: a value shown to 2 decimals may repeat in two
        folder = tmp_path / str(draw)
        folder.mkdir()
        notes.append(analyze(config, _trials(np.random.default_rng(draw)), None, folder).notes)
    fixed = set.intersection(*(_numbers(n) for n in notes)) - _cited_constants()
    assert fixed == set(), (fixed, notes[0])
    assert len(set(notes)) == 3


def test_the_turn_routes_taught_map_shares_are_this_runs(tmp_path):
    """The shares the prose gives for the taught maps are the means of the trials' records,
    with the one-cell shift forgiven and cell by cell (percent, one decimal)."""
    trials = _trials(np.random.default_rng(3))
    notes = tp.analyze_exp2(tp.Exp2Config(methods=METHODS), trials, None, tmp_path).notes
    for band in ("plane", "band"):
        shares = [100 * trials[f"taught_{band}_{key}"].mean() for key in tp.TAUGHT_SHARES]
        assert (
            f"{band} map {shares[0]:.1f} % erased / {shares[1]:.1f} % falsely occupied with a "
            f"one-cell shift forgiven, {shares[2]:.1f} % / {shares[3]:.1f} % cell by cell"
        ) in notes


def _thesis_like(rng: np.random.Generator, conventional_for: tuple[str, ...] = ()) -> pd.DataFrame:
    """Five runs with the stop errors of the thesis' Table 4.5 (mean, SD 0.01 m, and as many
    stops within 0.1 m); the methods in `conventional_for` take conventional's errors run by
    run (what the negative control does)."""
    trials = _trials(rng)
    errors = {
        "conventional": rng.normal(0.13, 0.01, 5).clip(0.105),
        "proposal1": np.r_[rng.normal(0.085, 0.005, 4), 0.11],  # 4/5 within
        "proposal2": rng.normal(0.07, 0.01, 5).clip(max=0.095),
        "both": rng.normal(0.07, 0.01, 5).clip(max=0.095),
    }
    for m in METHODS:
        trials[f"{m}_stop_error"] = errors["conventional" if m in conventional_for else m]
    return trials


@pytest.mark.parametrize("draw", range(3))
def test_exp2_claims_hold_on_the_thesis_numbers_and_fail_when_the_methods_are_one(tmp_path, draw):
    config = tp.Exp2Config(methods=METHODS)
    for spec in tp.EXP2_CLAIMS:
        assert spec.criterion.problems() == [], spec.key
    rng = np.random.default_rng(draw)
    thesis = tp.analyze_exp2(config, _thesis_like(rng), None, tmp_path)
    verdicts = {v.claim: v.verdict for v in judge(tp.EXP2_CLAIMS, thesis.evidence, draw)}
    assert len(verdicts) == len(tp.EXP2_CLAIMS) == 5
    # on the thesis' own five runs none of its findings fails, and its main ones hold:
    # proposal 2 5/5 within 0.1 m against conventional's 0/5, 0.07 against 0.13 m (proposal 1's
    # 0.02 m lead over proposal 2 is twice the SD, too close to the 0.01 m margin for 5 runs)
    assert "fails" not in verdicts.values(), verdicts
    for spec in tp.EXP2_CLAIMS:
        if spec.key in ("within_proposal2_vs_conventional", "farther_conventional_than_proposal2"):
            assert verdicts[spec.claim] == "holds", (spec.key, verdicts)
    same = _thesis_like(rng, conventional_for=("proposal1", "proposal2"))
    control = tp.analyze_exp2(config, same, None, tmp_path)
    verdicts = {v.claim: v.verdict for v in judge(tp.EXP2_CLAIMS, control.evidence, draw)}
    assert set(verdicts.values()) == {"fails"}, verdicts


@pytest.mark.parametrize("draw", range(3))
def test_exp3_box_claims_hold_near_the_thesis_numbers_and_fail_off_by_dead_reckonings(
    tmp_path, draw
):
    """Exp. 3's claims (proposal 2 with the boxes: mean stop error <= 0.09 m, estimate error
    <= 0.08 m) on five runs near Table 4.7's 0.07 / 0.06 m hold; on runs whose errors are a
    drifting estimate's (0.2-0.5 m) they fail."""
    config = tp.Exp3Config()
    rng = np.random.default_rng(draw)
    keys = {s.claim: s.key for s in tp.EXP3_CLAIMS}
    for stop, estimate, want in (
        (rng.normal(0.07, 0.005, 5), rng.normal(0.06, 0.005, 5), "holds"),
        (rng.uniform(0.2, 0.5, 5), rng.uniform(0.2, 0.5, 5), "fails"),
    ):
        trials = _trials(rng)
        trials["proposal2_stop_error"], trials["proposal2_estimate_error"] = stop, estimate
        analysis = tp.analyze_exp3(config, trials, None, tmp_path)
        verdicts = {keys[v.claim]: v.verdict for v in judge(tp.EXP3_CLAIMS, analysis.evidence, 0)}
        assert verdicts == {"boxes_stop": want, "boxes_estimate": want}, verdicts
