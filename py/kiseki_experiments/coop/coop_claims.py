# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What coop-forms claims of Hirose, Nagata and Kurazume's simulation (sec. 4, Figs. 5-8, and
sec. 3.1's n = tan(theta_e)), declared before any run with each claim's criterion and its
control, a config override under which the criterion must fail
(kiseki_experiments.harness.verdict). The evidence is one value per repeat of the whole sweep
(``repeats``, each repeat its own seeds): the setting with the smallest error in that repeat,
or a ratio of two minima. Claims about form 1 are made once per reading of form 1 (the
subject: "form 1 (pair-scout)", "form 1 (crossing)")."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion

__all__ = ["FACTOR", "N_PAPER", "claims"]

N_PAPER = 10.0  # eq. 5: n = tan(theta_e), the goal 10 m ahead of a baseline of half-width 1 m
FACTOR = 2.0
"""n = tan(theta_e)'s tolerance: within a factor of 2, the agreement the paper itself draws in
sec. 4 (form 2's best 5-10 moves and form 1's 10-20 "agree well" with n = 10)."""
ANGLE_SLACK = 2.5  # deg: half the angle sweep's 5 deg step either side of the paper's 50-60
MEDIAN = "the median over the repeats of the sweep"


def _control(count: Callable[[dict], int], name: str, why: str, **fields) -> Control:
    """A control that runs coop-forms without its anchors, with 5 repeats and 20 runs per
    setting, and ``fields`` changed; its trial count is its config's settings (``count``)."""
    fields = {"anchors": False, "repeats": 5, "runs": 20, **fields}
    overrides = tuple(
        f"{k}={','.join(str(x) for x in v) if isinstance(v, list) else str(v).lower()}"
        for k, v in fields.items()
    )
    return Control(name=name, overrides=overrides, runs=count(fields), why=why)


def _best(count, key: str, form: int, what: str, low: float, high: float, slack: float,
          fig: int, ctl: dict) -> ClaimSpec:  # fmt: skip
    return ClaimSpec(
        key=key,
        claim=f"form {form}: the error at the goal is smallest at about {low:g}-{high:g} {what}",
        unit=what,
        criterion=Criterion(
            paper_value=f"{low:g}-{high:g} (Fig. {fig})",
            compare="within",
            threshold=(low + high) / 2,
            tolerance=(high - low) / 2 + slack,
            why=f"the paper's range (sec. 4){' plus half the 5 deg step' if slack else ''}; "
            + MEDIAN,
        ),
        control=_control(
            count,
            "a sweep kept outside the paper's range ("
            + ", ".join(f"{k}={v}" for k, v in ctl.items())
            + ")",
            "the smallest error can only lie in the sweep, outside the range",
            **ctl,
        ),
        measure="the swept value with the smallest mean error at the goal, per repeat",
    )


def claims(config_type: type, setting_count: Callable[[Any], int]) -> tuple[ClaimSpec, ...]:
    """coop-forms' claims; ``config_type`` and ``setting_count`` (its config and the number of
    settings of a config) size the controls."""

    def count(fields: dict) -> int:
        return setting_count(replace(config_type(), **fields))

    return (
        _best(count, "moves_1", 1, "moves", 10, 20, 0.0, 5, {"form1_moves": [1, 3, 5, 7]}),
        _best(count, "moves_2", 2, "moves", 5, 10, 0.0, 6, {"form2_moves": [12, 13, 14]}),
        _best(
            count, "angle_1", 1, "deg", 50, 60, ANGLE_SLACK, 7, {"angles_deg": [30.0, 35.0, 40.0]}
        ),
        _best(
            count, "angle_2", 2, "deg", 50, 60, ANGLE_SLACK, 8, {"angles_deg": [30.0, 35.0, 40.0]}
        ),
        ClaimSpec(
            key="lower_min",
            claim="form 1 reaches a lower minimum error than form 2 (over the moves sweep)",
            unit="form 1's minimum / form 2's",
            criterion=Criterion(
                paper_value="form 1 < form 2 (sec. 4)",
                compare="<=",
                threshold=1.0,
                why="lower: a ratio below 1; " + MEDIAN,
                bounds=(0.0, math.inf),
            ),
            control=_control(
                count,
                "form 1 swept at one move only (form1_moves=1)",
                "a single scout move from the start's 2 m baseline to a goal 11 m ahead: its "
                "lines of sight meet at 11 deg, far worse than form 2's best",
                form1_moves=[1],
            ),
            measure="form 1's smallest mean error over the moves sweep over form 2's, per repeat",
        ),
        ClaimSpec(
            key="n_tan",
            claim="the along-track error at the goal is smallest at n = tan(theta_e) measurements "
            "(sec. 3.1, eq. 5; form 1's measurements are its scout moves, (moves + 1) / 2)",
            unit="measurements",
            criterion=Criterion(
                paper_value=f"n = tan(theta_e) = {N_PAPER:g}",
                compare="within",
                threshold=(N_PAPER / FACTOR + N_PAPER * FACTOR) / 2,
                tolerance=(N_PAPER * FACTOR - N_PAPER / FACTOR) / 2,
                why=f"within a factor of {FACTOR:g} of n: the agreement the paper draws in sec. 4; "
                + MEDIAN,
                paper_number=N_PAPER,
            ),
            control=_control(
                count,
                "sweeps kept below n / 2 measurements (form1_moves=1,3,5,7, form2_moves=1,2,3)",
                "the smallest along-track error can only lie in the sweep, below n / 2",
                form1_moves=[1, 3, 5, 7],
                form2_moves=[1, 2, 3],
            ),
            measure="the measurement count with the smallest along-track RMS error, per repeat",
        ),
    )
