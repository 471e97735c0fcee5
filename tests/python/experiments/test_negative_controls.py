# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Every declared claim can fail: run under its control (a config override that replaces the
method by its baseline or switches off what the claim is about), at the control's trial count,
its verdict must be *fails*, not inconclusive. The checking function itself is tested with
deliberately weakened controls (one that leaves the method unchanged, one too small to decide),
and every criterion is checked against the bounds of its quantity (no share >= 0).

Why some controls take about 20 s: a control runs its experiment for real, for the trials it
states, and a verdict needs an interval, so at least 5 trials (verdict.MIN_TRIALS). exp2-turn's
runs 5 teaching-and-playback trials of the turn; magnav-table-4-2's filter-off control drives the
whole 118 m route 5 times, because its claims are about the error over the whole route."""

from __future__ import annotations

import dataclasses
import math
import os

import pandas as pd
import pytest

from kiseki_experiments.harness.controls import control_groups, control_problems, run_control
from kiseki_experiments.harness.registry import all_experiments
from kiseki_experiments.harness.verdict import Control, Criterion

# the experiments whose inputs are the recorded datasets (skipped without them, as elsewhere)
RECORDED = ("carmen-maps", "mcl-", "gp-aalto", "magnetic-walks", "merge-rules")


# A control declared as taking minutes (layouts-exp2-exp3's: six layouts taught and played
# back, 63 s beside another test, more than the suite's budget for one control) runs when
# KISEKI_TEST_HEAVY=1 and is skipped, with this reason shown, otherwise.
heavy = pytest.mark.skipif(
    os.environ.get("KISEKI_TEST_HEAVY") != "1",
    reason="a control that takes minutes; set KISEKI_TEST_HEAVY=1 to run it",
)


def _cases():
    for name, experiment in sorted(all_experiments().items()):
        for control, specs in control_groups(name).items():
            marks = [heavy] if control.minutes else []
            yield pytest.param(name, control, specs, id=f"{name}:{control.name}", marks=marks)
        del experiment


@pytest.mark.parametrize(("name", "control", "specs"), list(_cases()))
def test_every_claim_fails_under_its_control(name, control, specs, tmp_path, request):
    if name.startswith(RECORDED):
        request.getfixturevalue("shared_data")
    claims = run_control(name, control, tmp_path / "control")
    problems = [p for spec in specs for p in control_problems(claims, spec)]
    assert not problems, "\n".join(problems)


def test_every_migrated_claim_names_a_control_and_a_criterion_that_can_fail():
    declared = [(n, s) for n, e in sorted(all_experiments().items()) for s in e.claims]
    assert len(declared) >= 4  # corridor-scans, carmen-maps, speed-pedestrian at least
    for name, spec in declared:
        assert spec.control is not None, f"{name}: {spec.key} has no control"
        assert spec.control.runs >= 1 and spec.control.overrides, f"{name}: {spec.key}"
        assert not spec.criterion.problems(), f"{name}: {spec.key}: {spec.criterion.problems()}"
    keys = [(n, s.key) for n, s in declared]
    assert len(keys) == len(set(keys))  # a key joins one claim to its evidence


@pytest.mark.parametrize(
    ("compare", "threshold", "bounds", "needle"),
    [
        (">=", 0.0, (0.0, 1.0), "holds for every value"),  # a share >= 0
        ("<=", 1.0, (0.0, 1.0), "holds for every value"),  # a share <= 1
        (">=", -0.5, (0.0, math.inf), "holds for every value"),  # an error >= -0.5
        (">=", 1.2, (0.0, 1.0), "holds for no value"),  # a share >= 1.2
    ],
)
def test_a_criterion_at_its_quantitys_bound_is_refused(compare, threshold, bounds, needle):
    criterion = Criterion("x", compare, threshold, "because", bounds=bounds)
    assert any(needle in p for p in criterion.problems())
    fine = Criterion("x", compare, 0.5, "because", bounds=(0.0, 1.0))
    assert fine.problems() == []


def _weakened(name: str, **changes):
    (control, specs), *_ = control_groups(name).items()
    return dataclasses.replace(control, **changes), specs


def test_a_control_that_leaves_the_method_unchanged_is_caught(tmp_path):
    # corridor-scans' control raises the range noise from 1 cm to 0.15 m; "weakened", the
    # override keeps the paper's 1 cm: the claim then holds, and the check must say so
    control, specs = _weakened("corridor-scans", overrides=("range_noise_sd=0.01",))
    claims = run_control("corridor-scans", control, tmp_path / "weak")
    problems = control_problems(claims, specs[0])
    assert len(problems) == 1 and "the verdict is holds, not fails" in problems[0]


def test_a_control_with_the_feature_left_on_is_caught(shared_data, tmp_path):
    # carmen-maps' control blurs the corrected poses by 0.3 m; weakened to 0 m (the corrected
    # poses as recorded) the Intel map agrees with its scans (0.96 >= 0.90): caught
    del shared_data
    control, specs = _weakened("carmen-maps", overrides=("pose_noise_sd=0", "logs=intel-corrected"))
    claims = run_control("carmen-maps", control, tmp_path / "weak")
    problems = control_problems(claims, specs[0])
    assert len(problems) == 1 and "the verdict is holds, not fails" in problems[0]


def test_a_control_too_small_to_decide_is_caught(tmp_path):
    # the right override at 2 trials: no interval (fewer than 5 values), inconclusive
    control, specs = _weakened("corridor-scans", runs=2)
    claims = run_control("corridor-scans", control, tmp_path / "small")
    problems = control_problems(claims, specs[0])
    assert len(problems) == 1 and "inconclusive" in problems[0]


def test_a_claim_without_a_control_or_without_rows_is_caught():
    (_, specs), *_ = control_groups("corridor-scans").items()
    empty = pd.DataFrame({"claim": [], "verdict": []})
    assert "not judged" in control_problems(empty, specs[0])[0]
    bare = dataclasses.replace(specs[0], control=None)
    assert "no control" in control_problems(empty, bare)[0]
    assert isinstance(specs[0].control, Control)
