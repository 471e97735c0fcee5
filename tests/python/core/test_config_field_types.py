# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Every typed config refuses a value of the wrong kind for its bool, int and float fields,
naming the field: LocalizeConfig(global_start="no") ran a global start (a non-empty string is
truthy), MclConfig(particles=True) ran one particle, GlobalConfig(shrink_after=1.5) was taken."""

from __future__ import annotations

import dataclasses
import importlib
import json
import math

import numpy as np
import pytest

from kiseki.filters.engine import MclConfig
from kiseki.magnetic.travel_distance import TravelDistanceConfig

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
    """The default as the numpy scalar a user's array would give: np.bool_, np.int64, and
    np.float32 where it holds the value exactly (0.5), np.float64 elsewhere (0.1)."""
    if isinstance(value, bool):
        return np.bool_(value)
    if isinstance(value, int):
        return np.int64(value)
    return np.float32(value) if float(np.float32(value)) == value else np.float64(value)


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
        assert type(getattr(config, field)) is type(getattr(default, field)), field
    json.dumps(dataclasses.asdict(config))  # numpy's scalars are not JSON


def test_a_float32_or_a_numpy_bool_passes_checks_written_for_python_types():
    """TravelDistanceConfig checked its numbers as int | float (np.float32 is neither: 'gain a
    must be a number, got np.float32(0.5)') and MclConfig its switches as bool (np.True_ is
    none): both are taken now, as the Python values they are."""
    config = TravelDistanceConfig(gain=np.float32(0.5), window=np.float32(2.0))
    assert config == TravelDistanceConfig(gain=0.5, window=2.0) and type(config.gain) is float
    switched = MclConfig(reset_look_elsewhere=np.bool_(True))
    assert switched.reset_look_elsewhere is True
    long_double = TravelDistanceConfig(gain=np.longdouble(0.5))
    assert type(long_double.gain) is float and long_double.gain == 0.5


FLOAT_FIELDS = [
    pytest.param(cls, f.name, id=f"{cls.__name__}.{f.name}")
    for cls in (getattr(importlib.import_module(m), n) for m, n in CONFIGS)
    for f in dataclasses.fields(cls)
    if str(f.type).replace(" ", "").split("|")[0] == "float"
]


@pytest.mark.parametrize(("cls", "field"), FLOAT_FIELDS)
def test_no_float_field_takes_a_nan_or_an_infinity(cls, field):
    """PlaybackConfig took goal_tolerance = inf (the goal 'reached' before the first step) and a
    NaN max_duration, SimConfig an infinite lookahead and goal_tolerance (refused later by the
    route follower, once the robot was built). The message names the field: MclConfig's KLD
    err and z and its expansion radii were refused in the engine's words, two fields in one
    message ('KLD sampling: err must lie in (0, 1] and z in [0, 10]')."""
    for bad in (math.nan, math.inf, -math.inf):
        with pytest.raises(ValueError, match=rf"\b{field}\b"):
            cls(**{field: bad})
