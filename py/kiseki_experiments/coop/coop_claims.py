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


def _outside(count) -> Control:
    """The one control of every coop-forms claim: sweeps kept outside the paper's ranges."""
    return _control(
        count,
        "sweeps kept outside the paper's ranges: form 1 at 51 moves, form 2 at 3-4 moves, "
        "angles 30-40 deg",
        "each claimed optimum can only lie in its sweep, outside the paper's range; and form "
        "1's 51 moves (26 units at 21 deg) end 1.9 (crossing) to 6.7 (pair and scout) times "
        "further off than form 2's 4 moves",
        form1_moves=[51],
        form2_moves=[3, 4],
        angles_deg=[30.0, 35.0, 40.0],
    )


def _best(count, key: str, form: int, what: str, low: float, high: float, slack: float,
          fig: int) -> ClaimSpec:  # fmt: skip
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
        control=_outside(count),
        measure="the swept value with the smallest mean error at the goal, per repeat",
    )


def claims(config_type: type, setting_count: Callable[[Any], int]) -> tuple[ClaimSpec, ...]:
    """coop-forms' claims; ``config_type`` and ``setting_count`` (its config and the number of
    settings of a config) size the controls."""

    def count(fields: dict) -> int:
        return setting_count(replace(config_type(), **fields))

    return (
        _best(count, "moves_1", 1, "moves", 10, 20, 0.0, 5),
        _best(count, "moves_2", 2, "moves", 5, 10, 0.0, 6),
        _best(count, "angle_1", 1, "deg", 50, 60, ANGLE_SLACK, 7),
        _best(count, "angle_2", 2, "deg", 50, 60, ANGLE_SLACK, 8),
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
            control=_outside(count),
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
            control=_outside(count),
            measure="the measurement count with the smallest along-track RMS error, per repeat",
        ),
    )
