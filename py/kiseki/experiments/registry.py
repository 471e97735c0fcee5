# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The registry of experiments: an explicit dict, one entry per paper table or figure."""

from __future__ import annotations

from kiseki.errors import KisekiError
from kiseki.experiments.base import Experiment

__all__ = ["all_experiments", "get_experiment"]


def _registry() -> dict[str, Experiment]:
    from kiseki.experiments import (
        carmen_maps,
        coop_forms,
        corridor_scans,
        fig_3_14,
        gp_aalto,
        gp_floor_mapping,
        gp_mcl,
        gp_table_6_2,
        layouts,
        magnav_fig_5_4,
        magnav_navigators,
        magnav_table_4_2,
        mcl_excursions,
        mcl_kidnapping,
        mcl_kld,
        merge_rules,
        speed_fig4,
        speed_pedestrian,
        speed_situations,
        teach_playback,
        terrain_corridor,
        terrain_envs,
        terrain_global_map,
    )

    experiments = [
        carmen_maps.EXPERIMENT,
        coop_forms.EXPERIMENT,
        corridor_scans.EXPERIMENT,
        fig_3_14.EXPERIMENT,
        gp_aalto.EXPERIMENT,
        gp_floor_mapping.EXPERIMENT,
        gp_mcl.EXPERIMENT,
        gp_table_6_2.EXPERIMENT,
        layouts.EXPERIMENT,
        magnav_fig_5_4.EXPERIMENT,
        magnav_navigators.EXPERIMENT,
        magnav_table_4_2.EXPERIMENT,
        mcl_excursions.EXPERIMENT,
        mcl_kidnapping.SIM,
        mcl_kidnapping.CARMEN,
        mcl_kld.EXPERIMENT,
        merge_rules.EXPERIMENT,
        speed_fig4.EXPERIMENT,
        speed_pedestrian.EXPERIMENT,
        speed_situations.EXPERIMENT,
        teach_playback.EXP1,
        teach_playback.EXP2,
        teach_playback.EXP3,
        terrain_envs.ENV_A,
        terrain_envs.ENV_B,
        terrain_corridor.CORRIDOR,
        terrain_global_map.GLOBAL_MAP,
    ]
    return {e.name: e for e in experiments}


def all_experiments() -> dict[str, Experiment]:
    return _registry()


def get_experiment(name: str) -> Experiment:
    registry = _registry()
    if name not in registry:
        known = ", ".join(sorted(registry))
        raise KisekiError(f"unknown experiment {name!r} (known: {known})")
    return registry[name]
