# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki localize``'s options that the chosen method, start or recovery does not use: each
is an error naming it, never silently ignored (and never written to the run's config as if it
had been in effect)."""

from __future__ import annotations

import typer

from kiseki._support.options import refuse_given
from kiseki.filters import LocalizeConfig

RESET_OPTIONS = [
    "reset_proposal",
    "search_every",
    "reset_look_elsewhere",
    "reset_unchecked",
    "intrusion_tolerant",
]


def refuse_unused_by_localize(
    ctx: typer.Context, method: str, global_start: bool, recovery: str | None, proposal: str | None
) -> None:
    """Refuses the options given that this run would not use (module text)."""
    if method == "odometry":  # the odometry alone: no filter, no sensor model, no start
        refuse_given(
            ctx,
            ["particles", "kld", "beams", "recovery", "threads", "global_start"]
            + ["reliability_estimate", *RESET_OPTIONS],
            "to --method odometry (the odometry alone: no particle filter)",
        )
    elif method == "space-observation":  # a local map of the whole scan: no beam selection
        refuse_given(ctx, ["beams"], "to --method space-observation (it weighs the whole scan)")
    if method != "likelihood-field":
        refuse_given(ctx, ["beam_skip"], f"to --method {method} (a likelihood-field option)")
    if method != "beam":
        refuse_given(ctx, ["caster"], f"to --method {method} (a beam-model option)")
    if method != "ray-space-observation":
        refuse_given(
            ctx, ["intrusion_tolerant"], f"to --method {method} (a ray-space-observation option)"
        )
    if global_start:
        refuse_given(ctx, ["odometry_noise"], "with --global (it is for logs with reference poses)")
        refuse_given(
            ctx,
            RESET_OPTIONS,
            "with --global (its start is --one-scan; its resets are the uniform ones)",
        )
        refuse_given(
            ctx, ["budget_ms", "cost_model", "beam_skip", "caster"], "with --global (tracking only)"
        )
    elif (recovery or LocalizeConfig.recovery) != "resetting":
        refuse_given(
            ctx,
            RESET_OPTIONS,
            f"with --recovery {recovery or LocalizeConfig.recovery} (sensor resets are made only "
            "with --recovery resetting)",
        )
    if (proposal or LocalizeConfig.sensor_reset_proposal) != "matcher":
        refuse_given(ctx, ["search_every"], "without --reset-proposal matcher")
