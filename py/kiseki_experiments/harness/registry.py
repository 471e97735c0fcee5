# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The registry of experiments: an explicit dict, one entry per paper table or figure.

The registry is the one harness module that imports the papers' packages (the runner and the
report reach them through it); the papers import only the harness modules below it (base,
config, paths, records, ...), so nothing imports back up here."""

from __future__ import annotations

from kiseki.errors import KisekiError
from kiseki_experiments.coop import coop_forms
from kiseki_experiments.gp import (
    gp_aalto,
    gp_aalto_defaults,
    gp_aalto_sensors,
    gp_floor_mapping,
    gp_mcl,
    gp_table_6_2,
)
from kiseki_experiments.harness.base import Experiment
from kiseki_experiments.magnav import (
    magnav_fig_5_4,
    magnav_navigators,
    magnav_table_4_2,
    magnav_walks,
)
from kiseki_experiments.mapping import carmen_maps, corridor_scans
from kiseki_experiments.mcl import (
    mcl_excursions,
    mcl_kidnapping,
    mcl_kld,
    mcl_relocalization,
    mcl_unknown_obstacles,
)
from kiseki_experiments.speed import speed_fig4, speed_pedestrian, speed_situations
from kiseki_experiments.teach import fig_3_14, layouts, merge_rules, teach_playback
from kiseki_experiments.terrain import terrain_corridor, terrain_envs, terrain_global_map

__all__ = ["all_experiments", "get_experiment"]


def _registry() -> dict[str, Experiment]:
    experiments = [
        carmen_maps.EXPERIMENT,
        coop_forms.EXPERIMENT,
        corridor_scans.EXPERIMENT,
        fig_3_14.EXPERIMENT,
        gp_aalto.EXPERIMENT,
        gp_aalto_defaults.EXPERIMENT,
        gp_aalto_sensors.EXPERIMENT,
        gp_floor_mapping.EXPERIMENT,
        gp_mcl.EXPERIMENT,
        gp_table_6_2.EXPERIMENT,
        layouts.EXPERIMENT,
        magnav_fig_5_4.EXPERIMENT,
        magnav_navigators.EXPERIMENT,
        magnav_table_4_2.EXPERIMENT,
        magnav_walks.EXPERIMENT,
        mcl_excursions.EXPERIMENT,
        mcl_kidnapping.SIM,
        mcl_kidnapping.CARMEN,
        mcl_kld.EXPERIMENT,
        mcl_relocalization.EXPERIMENT,
        mcl_unknown_obstacles.EXPERIMENT,
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
