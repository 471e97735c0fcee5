# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Every typed config refuses a value of the wrong kind for its bool, int and float fields,
naming the field: LocalizeConfig(global_start="no") ran a global start (a non-empty string is
truthy), MclConfig(particles=True) ran one particle, GlobalConfig(shrink_after=1.5) was taken."""

from __future__ import annotations

import dataclasses
import importlib

import pytest

CONFIGS = [
    ("kiseki.filters.localize_config", "LocalizeConfig"),
    ("kiseki.filters.engine", "MclConfig"),
    ("kiseki.filters.global_localization", "GlobalConfig"),
    ("kiseki.filters.relocalization", "RelocalizeConfig"),
    ("kiseki.magnetic.lidar_mcl", "LidarMclConfig"),
    ("kiseki.magnetic.travel_distance", "TravelDistanceConfig"),
    ("kiseki.magnetic.loop_travel_distance", "LoopTravelConfig"),
    ("kiseki.magnetic.localization", "MagneticMclConfig"),
    ("kiseki.sim.run", "SimConfig"),
    ("kiseki.control.fuzzy_potential", "FuzzyPotentialConfig"),
    ("kiseki.terrain.mapper", "MapperConfig"),
    ("kiseki.apps.teach.playback", "PlaybackConfig"),
    ("kiseki.speed.limiter", "SpeedLimiterConfig"),
    ("kiseki.speed.baselines", "DistanceLimiterConfig"),
    ("kiseki.speed.baselines", "PolygonLimiterConfig"),
]
WRONG = {"bool": ["no", 1], "int": [True, 1.5, "3"], "float": [True, "0.5", None]}


def _cases():
    for module, name in CONFIGS:
        cls = getattr(importlib.import_module(module), name)
        for f in dataclasses.fields(cls):
            kind, _, rest = str(f.type).replace(" ", "").partition("|")
            if kind in WRONG and rest in ("", "None"):
                for value in WRONG[kind]:
                    if value is None and rest == "None":
                        continue
                    yield pytest.param(cls, f.name, kind, value, id=f"{name}.{f.name}={value!r}")


CASES = list(_cases())


def test_every_config_has_fields_of_each_checked_kind_and_valid_defaults():
    assert len(CASES) > 300  # the configs' typed fields, each with its wrong values
    for module, name in CONFIGS:
        getattr(importlib.import_module(module), name)()  # the defaults pass


@pytest.mark.parametrize(("cls", "field", "kind", "value"), CASES)
def test_a_value_of_the_wrong_kind_is_refused_naming_the_field(cls, field, kind, value):
    want = {"bool": "True or False", "int": "an integer", "float": "a number"}[kind]
    with pytest.raises(ValueError) as caught:
        cls(**{field: value})
    assert str(caught.value) == f"{cls.__name__}.{field} must be {want}, got {value!r}"
