# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Every typed config refuses a value of the wrong kind for its bool, int and float fields,
naming the field: LocalizeConfig(global_start="no") ran a global start (a non-empty string is
truthy), MclConfig(particles=True) ran one particle, GlobalConfig(shrink_after=1.5) was taken."""

from __future__ import annotations

import dataclasses
import importlib
import json

import numpy as np
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


def _numpy_twin(value):
    """The default as the numpy scalar a user's array would give (np.int64 60, np.float32 ...)."""
    if isinstance(value, bool):
        return np.bool_(value)
    return np.int64(value) if isinstance(value, int) else np.float64(value)


@pytest.mark.parametrize(("module", "name"), CONFIGS, ids=[name for _, name in CONFIGS])
def test_numpy_scalars_are_held_as_python_numbers_and_saved_as_json(module, name):
    """np.int64(60) beams were kept as numpy's: the config compared equal but saving it with the
    results (JSON, YAML) failed after the run (GlobalConfig(beams=np.int64(60)) in
    ``write_report``); GlobalConfig refused np.int64 particles outright."""
    cls = getattr(importlib.import_module(module), name)
    default = cls()
    scalar = {
        f.name: _numpy_twin(getattr(default, f.name))
        for f in dataclasses.fields(cls)
        if str(f.type) in ("bool", "int", "float")
        and isinstance(getattr(default, f.name), bool | int | float)
    }
    assert scalar, f"{name} has no numeric field"
    config = cls(**scalar)
    assert config == default
    for field in scalar:
        value, want = getattr(config, field), getattr(default, field)
        assert type(value) is type(want) or (type(value), type(want)) == (float, int), field
    json.dumps(dataclasses.asdict(config))  # numpy's scalars are not JSON
