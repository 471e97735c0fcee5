# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Experiment configs checked by the model built from their dataclass: overrides and saved
configs read to the same objects as built by hand, types are strict and finite, limits on
particles, runs, seeds and list lengths are enforced with the limit in the message, and
every message names the key, the value (and the file)."""

from __future__ import annotations

import dataclasses

import pytest

from kiseki_experiments.coop.coop_forms import CoopFormsConfig
from kiseki_experiments.gp.gp_aalto import GpAaltoConfig
from kiseki_experiments.gp.gp_mcl import MagneticMclExperimentConfig
from kiseki_experiments.harness.config import (
    LIST_LIMIT,
    PARTICLE_LIMIT,
    RUN_LIMIT,
    ConfigError,
    NonEmpty,
    apply_overrides,
    config_from_dict,
    config_to_dict,
)
from kiseki_experiments.harness.registry import all_experiments
from kiseki_experiments.mapping.corridor_scans import CorridorScansConfig


def _message(call, *args) -> str:
    with pytest.raises(ConfigError) as info:
        call(*args)
    return str(info.value)


def test_overrides_read_as_a_config_built_by_hand():
    got = apply_overrides(
        GpAaltoConfig(),
        ["sensors=nexus, invensense", "train_runs=1,3", "hilbert=false", "alphas=5e-2,1,0.5",
         "data_dir=123", "grid_resolution=2E-1", "gp_seed=18446744073709551615"],
    )  # fmt: skip
    want = dataclasses.replace(
        GpAaltoConfig(),
        sensors=["nexus", "invensense"],
        train_runs=[1, 3],
        hilbert=False,
        alphas=[0.05, 1.0, 0.5],
        data_dir="123",  # a string field takes the text as it is
        grid_resolution=0.2,
        gp_seed=2**64 - 1,
    )
    assert got == want
    assert isinstance(got.alphas[1], float)


def test_every_experiments_default_config_round_trips_through_its_dict():
    for name, experiment in all_experiments().items():
        config = experiment.config_type()
        assert config_from_dict(experiment.config_type, config_to_dict(config)) == config, name
    # only the keys given are set; the others keep their defaults
    assert config_from_dict(CoopFormsConfig, {"runs": 7}) == CoopFormsConfig(runs=7)


@pytest.mark.parametrize(
    ("setting", "message"),
    [
        ("particles=0", "particles: must be greater than 0, got 0"),
        (
            f"particles={PARTICLE_LIMIT + 1}",
            f"particles: must be less than or equal to {PARTICLE_LIMIT}, got {PARTICLE_LIMIT + 1}",
        ),
        (
            f"runs_per_route={RUN_LIMIT + 1}",
            f"runs_per_route: must be less than or equal to {RUN_LIMIT}, got {RUN_LIMIT + 1}",
        ),
        ("map_seed=-1", "map_seed: must be an integer in [0, 2**64), got -1"),
        (f"map_seed={2**64}", f"map_seed: must be an integer in [0, 2**64), got {2**64}"),
        ("speed=nan", "speed: must be a finite number, got nan"),
        ("speed=.inf", "speed: must be a finite number, got inf"),
        ("speed=fast", "speed: must be a valid number, got 'fast'"),
        ("particles=1e3", "particles: must be a valid integer, got 1000.0"),
        ("particles=true", "particles: must be a valid integer, got True"),
        ("bogus=1", "bogus: unknown config key (known: dt, hyper_points,"),
    ],
)
def test_a_bad_override_names_the_key_the_value_and_the_limit(setting, message):
    text = _message(apply_overrides, MagneticMclExperimentConfig(), [setting])
    assert text.startswith(f"--set: {message}")


def test_the_limits_themselves_are_accepted():
    config = apply_overrides(
        MagneticMclExperimentConfig(),
        [f"particles={PARTICLE_LIMIT}", f"runs_per_route={RUN_LIMIT}", "map_seed=0"],
    )
    assert (config.particles, config.runs_per_route, config.map_seed) == (
        PARTICLE_LIMIT,
        RUN_LIMIT,
        0,
    )
    moves = ",".join(["1"] * LIST_LIMIT)
    assert len(apply_overrides(CoopFormsConfig(), [f"form1_moves={moves}"]).form1_moves) == (
        LIST_LIMIT
    )
    text = _message(apply_overrides, CoopFormsConfig(), [f"form1_moves={moves},1"])
    assert f"form1_moves: list should have at most {LIST_LIMIT} items" in text


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ({"scan_spacing": "0.1"}, "config.scan_spacing: must be a valid number, got '0.1'"),
        ({"scan_spacing": True}, "config.scan_spacing: must be a valid number, got True"),
        ({"scan_spacing": float("nan")}, "config.scan_spacing: must be a finite number, got nan"),
        ({"map_file": 5}, "config.map_file: must be a valid string, got 5"),
        ({"noise": 1}, "config.noise: unknown key"),
    ],
)
def test_a_bad_saved_config_names_the_file_the_key_and_the_value(values, message):
    text = _message(config_from_dict, CorridorScansConfig, values, "run/config.yaml", ("config",))
    assert text == f"run/config.yaml: {message}"


def test_a_bad_list_item_is_named_with_its_index():
    text = _message(config_from_dict, GpAaltoConfig, {"train_runs": [1, 2, "3"]})
    assert text == "config: train_runs[2]: must be a valid integer, got '3'"


@pytest.mark.parametrize(
    ("experiment", "setting", "message"),
    [
        ("mcl-kidnapping", "threads=-4", "threads: must be greater than 0, got -4"),
        ("mcl-kidnapping", "threads=257", "threads: must be less than or equal to 256, got 257"),
        ("mcl-kidnapping", "after_scans=100000000000",
         "after_scans: must be less than or equal to 1000000, got 100000000000"),
        ("mcl-kidnapping", "before_scans=1000001",
         "before_scans: must be less than or equal to 1000000, got 1000001"),
        ("mcl-kld", "max_scans=-1", "max_scans: must be greater than or equal to 0, got -1"),
        ("mcl-excursions", "max_scans=1000001",
         "max_scans: must be less than or equal to 1000000, got 1000001"),
        ("mcl-relocalization", "scans=1000001",
         "scans: must be less than or equal to 1000000, got 1000001"),
        ("mcl-relocalization", "resolution=0.001",
         "resolution: must be greater than or equal to 0.01, got 0.001"),
        ("layouts-exp2-exp3", "boxes=100000000",
         "boxes: must be less than or equal to 100, got 100000000"),
        ("exp3-boxes", "boxes=101", "boxes: must be less than or equal to 100, got 101"),
        ("speed-pedestrian", "max_duration=1e300",
         "max_duration: must be less than or equal to 86400, got 1e+300"),
        ("speed-situations", "max_duration=0", "max_duration: must be greater than 0, got 0"),
        ("fig-3-14", "beams=1000001", "beams: must be less than or equal to 1000000, got 1000001"),
        ("fig-3-14", "offsets=0", "offsets: must be greater than 0, got 0"),
        ("gp-aalto", "max_points=20001",
         "max_points: must be less than or equal to 20000, got 20001"),
        ("gp-aalto", "restarts=101", "restarts: must be less than or equal to 100, got 101"),
        ("gp-aalto", "thinning=0", "thinning: must be greater than 0, got 0"),
        ("gp-floor-mapping", "truth_voxels=1000001",
         "truth_voxels: must be less than or equal to 1000000, got 1000001"),
        ("gp-floor-mapping", "voxel=0.001",
         "voxel: must be greater than or equal to 0.05, got 0.001"),
        ("gp-floor-mapping", "resolution=0.001",
         "resolution: must be greater than or equal to 0.01, got 0.001"),
        ("gp-mcl", "dt=1e-6", "dt: must be greater than or equal to 0.001, got 1e-06"),
        ("gp-mcl", "survey_step=0.001",
         "survey_step: must be greater than or equal to 0.01, got 0.001"),
        ("gp-mcl", "hyper_points=20001",
         "hyper_points: must be less than or equal to 20000, got 20001"),
    ],
)  # fmt: skip
def test_every_field_that_sizes_time_or_memory_has_its_limit(experiment, setting, message):
    config = all_experiments()[experiment].config_type()
    assert _message(apply_overrides, config, [setting]) == f"--set: {message}"


def test_every_registered_config_builds_its_model_and_a_bare_number_is_refused():
    from kiseki_experiments.harness import config as config_module

    for name, experiment in all_experiments().items():
        model = config_module._model(experiment.config_type, name)
        for field in dataclasses.fields(experiment.config_type):
            assert field.name in model.model_fields, (name, field.name)

    @dataclasses.dataclass(frozen=True)
    class Unbounded:
        beams: int = 3

    @dataclasses.dataclass(frozen=True)
    class UnboundedItems:
        sizes: list[float] = dataclasses.field(default_factory=list)

    with pytest.raises(TypeError) as err:  # the experiment is named by the caller
        apply_overrides(Unbounded(), ["beams=2"], "fake-exp")
    assert str(err.value).startswith(
        "experiment fake-exp (test_every_registered_config_builds_its_model_and_a_bare_number"
        "_is_refused.<locals>.Unbounded.beams): a bare int has no range"
    )
    with pytest.raises(TypeError, match=r"UnboundedItems\.sizes\): a bare float has no range"):
        config_from_dict(UnboundedItems, {})


def _non_empty_lists() -> list:
    import typing

    found = []
    for name, experiment in sorted(all_experiments().items()):
        hints = typing.get_type_hints(experiment.config_type, include_extras=True)
        for key, kind in hints.items():
            if typing.get_origin(kind) is typing.Annotated and NonEmpty in typing.get_args(kind):
                found.append(pytest.param(name, key, id=f"{name}.{key}"))
    return found


@pytest.mark.parametrize(("experiment", "key"), _non_empty_lists())
def test_a_list_that_needs_an_item_refuses_none(experiment, key):
    """--set methods= ran a trial of exp1-corridor that failed with "list index out of range"
    and left a half-written results folder; each such list now refuses to be empty."""
    config = all_experiments()[experiment].config_type()
    with pytest.raises(ConfigError, match=f"--set: {key}: list should have at least 1 item"):
        apply_overrides(config, [f"{key}="], experiment)


def test_lists_that_may_be_empty_still_may():
    """gp-aalto's walks= leaves out the walks (its negative control does so)."""
    assert len(_non_empty_lists()) >= 9
    assert apply_overrides(GpAaltoConfig(), ["walks="]).walks == []
