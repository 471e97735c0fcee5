# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What mcl-kidnapping and mcl-kidnapping-carmen (kiseki_experiments.mcl.mcl_kidnapping)
claim of recovery and of the reliability estimate, declared before any run with each claim's
criterion and its control (kiseki_experiments.harness.verdict)."""

from __future__ import annotations

from kiseki_experiments.harness.verdict import ClaimSpec, Control, Criterion

__all__ = ["CARMEN_CLAIMS", "SIM_CLAIMS"]


def _issue_target(why: str) -> Criterion:
    """A share of at least 0.95, the issue's target for recovery and reliability."""
    return Criterion(
        paper_value=">= 0.95 (the issue's target)",
        compare=">=",
        threshold=0.95,
        why=f"the issue's target: {why}",
        bounds=(0.0, 1.0),
    )


def _lost_control(small: tuple[str, ...], recorded: bool) -> Control:
    """The control of "low when lost". In simulation the simulator's coefficients with the
    likelihood drop switched off: agreement alone never goes under sigmoid(b0) = 0.72. On the
    recorded logs agreement alone does say "lost" (the real-log fit weighs it 13.7, against
    2.07 in simulation: a lost real robot's scan rarely agrees with the map), so there the
    control is the estimate blind to the scan, which no evidence moves."""
    if recorded:
        return Control(
            name="an estimate blind to the scan (0.7 at every update, the fits' share localised)",
            overrides=("blind=true", "recoveries=none", *small),
            runs=3,  # decides: 0 of 3 has a Wilson interval up to 0.56
            why="an estimate that does not read the scan cannot tell a lost robot from a "
            "localised one",
        )
    return Control(
        name="the learned estimate without its likelihood drop (agreement alone)",
        overrides=("drop_weight=0", "recoveries=none", *small),
        runs=3,  # decides: its estimate never goes under sigmoid(b0) = 0.72
        why="in a look-alike place the scan agrees with the map from the wrong pose",
    )


def _claims(small: tuple[str, ...] = (), recorded: bool = False) -> tuple[ClaimSpec, ...]:
    """The claims; ``small`` adds overrides that keep a control's trials small (one log);
    ``recorded``: the claims of the recorded logs."""
    return (
        ClaimSpec(
            key="recovers",
            claim="with resetting, kidnapped trials recover (0.5 m, 10 deg, held 10 updates)",
            unit="share of trials",
            criterion=_issue_target("at most 1 kidnapping in 20 left unrecovered"),
            control=Control(
                name="no recovery in the resetting arm",
                overrides=("resetting_runs=none", "recoveries=resetting", *small),
                runs=5,
                why="without a recovery the filter's particles stay where the robot was",
            ),
            measure="whether a trial's resetting arm recovered",
        ),
        ClaimSpec(
            key="falls",
            claim="the reliability estimate falls when the robot is lost (no recovery)",
            unit="mean reliability over the 10 updates after the jump",
            criterion=Criterion(
                paper_value="falls (als_ros users report 99.99 % while lost)",
                compare="<=",
                threshold=0.5,
                why="below half: most recent scans disagree with the map seen from the particles",
                bounds=(0.0, 1.0),
            ),
            control=Control(
                name="no kidnapping",
                overrides=("kidnap=false", "recoveries=none", *small),
                runs=5,
                why="a robot that is not carried stays localised and its scans agree with the map",
            ),
            measure="a trial's mean reliability over the 10 updates after the jump (no recovery)",
        ),
        ClaimSpec(
            key="low_when_lost",
            claim="without recovery, the reliability falls below 0.5 within 10 updates of the "
            "jump in trials more than 1 m off",
            unit="share of trials more than 1 m off at each of the 10 updates",
            criterion=_issue_target("a lost robot says so within 10 updates in 19 of 20"),
            control=_lost_control(small, recorded),
            measure="whether the reliability of a lost trial's none arm went below 0.5",
        ),
        ClaimSpec(
            key="high_when_tracking",
            claim="the reliability is above 0.9 while the error is under 0.3 m (and 10 deg)",
            unit="share of updates within 0.3 m and 10 deg (no recovery)",
            criterion=_issue_target("a tracking robot is not called lost in 1 update of 20"),
            control=Control(
                name="the learned estimate's odds divided by e^2",
                overrides=("odds_offset=-2", "recoveries=none", *small),
                runs=3,  # decides: hundreds of tracking updates a trial
                why="an estimate that underrates every update stays below 0.9 while tracking",
            ),
            measure="updates of the none arm within 0.3 m and 10 deg whose reliability > 0.9",
        ),
    )


SIM_CLAIMS = _claims()
# the controls on the Intel log alone (about 1 s a trial; Freiburg's 4,791 scans take 4 s)
CARMEN_CLAIMS = _claims(("logs=intel-corrected",), recorded=True)
