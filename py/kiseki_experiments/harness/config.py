# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Typed experiment configs: ``--set key=value`` overrides and the ``config:`` section of a
run's saved config.yaml, checked by a pydantic model built from the config dataclass's fields
(strict finite numbers, integers, booleans, strings and lists of them), and YAML round trips.

Every number field declares its range in its type, one of this module's (a bare ``int`` or
``float`` is refused when the model is built, so no field is left unbounded): a field that
sizes memory or time has a limit (:data:`Particles`, :data:`Runs`, :data:`Count`,
:data:`Scans`, :data:`Resolution`, :data:`Seconds`, ...; ``Field(le=...)``), which is then in
the message ("particles: must be less than or equal to 10000000, got ..."); a seed is
:data:`Seed`; a length, angle or share that sizes nothing is :data:`Real`,
:data:`PositiveReal`, :data:`NonNegativeReal` or :data:`Share`."""

from __future__ import annotations

import dataclasses
import functools
import typing
from typing import Annotated, Any

import yaml
from pydantic import Field, create_model

from kiseki._support.numbers_text import parse_float
from kiseki._support.options import PARTICLE_LIMIT
from kiseki._support.schema import (
    FileModel,
    FiniteFloat,
    NonNegativeFloat,
    PositiveFloat,
    SchemaError,
    Seed,
    parse,
)
from kiseki._support.yaml import safe_load_12

__all__ = [
    "Lag",
    "LIST_LIMIT",
    "NonEmpty",
    "PARTICLE_LIMIT",
    "RUN_LIMIT",
    "Boxes",
    "ConfigError",
    "Count",
    "Factor",
    "FitPoints",
    "Index",
    "NonNegativeReal",
    "Particles",
    "PositiveReal",
    "Rate",
    "Real",
    "Resolution",
    "Restarts",
    "Runs",
    "Scans",
    "Seconds",
    "Seed",
    "Share",
    "Spacing",
    "Speed",
    "Threads",
    "TimeStep",
    "Voxel",
    "apply_overrides",
    "config_from_dict",
    "config_to_dict",
]

NonEmpty = Field(min_length=1)
"""Marks a list field that needs at least one item (``methods: Annotated[list[str], NonEmpty]``):
``--set methods=`` ran a trial and failed with "list index out of range", leaving a half-written
results folder."""

# PARTICLE_LIMIT: the most particles an experiment's filter may take, the library's own
# (kiseki._support.options, as kiseki.filters.MclConfig takes)
RUN_LIMIT = 100_000
"""The most runs (repetitions of a setting) an experiment's config may ask for."""
LIST_LIMIT = 10_000
"""The most items of a list in a config (its lists name logs, settings, move counts)."""

Particles = Annotated[int, Field(strict=True, gt=0, le=PARTICLE_LIMIT)]
Runs = Annotated[int, Field(strict=True, gt=0, le=RUN_LIMIT)]

# Counts. Each limit guards what the count sizes; the defaults sit far below them.
# Things made and scored one by one in a trial (beams, offsets, free voxels scored, scans a
# claim waits for, moves of a formation, every k-th reading): a million is seconds of work
# and tens of MB of arrays per trial, orders above every experiment's use.
Count = Annotated[int, Field(strict=True, gt=0, le=1_000_000)]
# Readings a GP's hyperparameters are fitted on: the fit holds an n x n kernel matrix, 3.2 GB
# of float64 at 20 000 points (and O(n^3) time per step of the search).
FitPoints = Annotated[int, Field(strict=True, gt=0, le=20_000)]
# Random restarts of a hyperparameter search: each is a whole fit; 0 = the first start only.
Restarts = Annotated[int, Field(strict=True, ge=0, le=100)]
# Scans of a log or a run; 0 = all of them where the field says so. A million scans is over a
# day of a 10 Hz laser (CARMEN's logs hold tens of thousands).
Scans = Annotated[int, Field(strict=True, ge=0, le=1_000_000)]
# readings or steps a control shifts a stream by (0: none)
Lag = Annotated[int, Field(strict=True, ge=0, le=1_000_000)]
# Threads of one trial: beyond a large machine's cores they only add overhead and memory.
Threads = Annotated[int, Field(strict=True, gt=0, le=256)]
# Unknown boxes placed at random (without overlap) into a scene: each is drawn into every
# scan; 100 boxes of 0.4 m fill the scenes' free floor long before the placement runs out.
Boxes = Annotated[int, Field(strict=True, ge=0, le=100)]
# An index naming a data file or a setting (run 5 of a data set): sizes nothing.
Index = Annotated[int, Field(strict=True, ge=0, le=LIST_LIMIT)]

# Quantities. A lower limit on a step guards the number of steps (memory and time).
# Simulated seconds of a run: a day of simulated time at the simulators' 10-100 Hz steps.
Seconds = Annotated[float, Field(strict=True, gt=0, le=86_400.0, allow_inf_nan=False)]
# A simulation's time step (s): at least 1 ms (a minute of motion is then 60 000 steps).
TimeStep = Annotated[float, Field(strict=True, ge=0.001, le=10.0, allow_inf_nan=False)]
# A 2-D grid's cell (m): 1 cm cells over a 100 m x 100 m scene are 10^8 cells (800 MB of
# float64); 10 m cells hold no detail of any scene.
Resolution = Annotated[float, Field(strict=True, ge=0.01, le=10.0, allow_inf_nan=False)]
# A 3-D grid's voxel (m): 5 cm voxels over a 100 m x 100 m x 3 m floor are 2.4 x 10^8.
Voxel = Annotated[float, Field(strict=True, ge=0.05, le=10.0, allow_inf_nan=False)]
# Metres of travel between readings, updates or scans: 1 cm = 100 per metre of route.
Spacing = Annotated[float, Field(strict=True, ge=0.01, le=100.0, allow_inf_nan=False)]
# A speed (m/s) that sets how long a run lasts: 1 cm/s crosses a 100 m scene in 3 hours.
Speed = Annotated[float, Field(strict=True, ge=0.01, le=100.0, allow_inf_nan=False)]
# A sensor rate (Hz): readings per second of a run; 1 kHz is above any sensor simulated.
Rate = Annotated[float, Field(strict=True, gt=0, le=1000.0, allow_inf_nan=False)]
# Numbers that size nothing (lengths, angles, noise SDs, thresholds): finite, and signed as
# their meaning says.
Real = FiniteFloat
PositiveReal = PositiveFloat
NonNegativeReal = NonNegativeFloat
# A share or probability.
Share = Annotated[float, Field(strict=True, ge=0, le=1, allow_inf_nan=False)]
# A factor applied to a sensor's readings (a calibration): a tenth to ten times.
Factor = Annotated[float, Field(strict=True, ge=0.1, le=10.0, allow_inf_nan=False)]

# the strict base of an annotated number (its range comes with its annotation)
_BOUNDED: dict[Any, Any] = {
    float: FiniteFloat,
    int: Annotated[int, Field(strict=True)],
}
_SCALARS: dict[Any, Any] = {
    bool: Annotated[bool, Field(strict=True)],
    str: Annotated[str, Field(strict=True)],
}


class ConfigError(SchemaError):
    """An unknown config key or a value of the wrong type or out of its limits: the message
    names the key and the value (and the file when the config was read from one)."""


def _strict(kind: Any) -> Any:
    """The model type of a dataclass field's type: strict, finite, lists of bounded length; a
    bare ``int`` or ``float`` (no range) is a TypeError."""
    if typing.get_origin(kind) is Annotated:
        base, *meta = typing.get_args(kind)
        return Annotated[(_BOUNDED.get(base) or _strict(base), *meta)]
    origin = typing.get_origin(kind)
    if origin in (list, tuple):
        (item,) = set(typing.get_args(kind)) - {Ellipsis} or {str}
        item = _strict(item)
        items = list[item] if origin is list else tuple[item, ...]
        return Annotated[items, Field(max_length=LIST_LIMIT)]
    if kind in (int, float):
        raise TypeError(
            f"a bare {kind.__name__} has no range: type it with one of "
            "kiseki_experiments.harness.config's types "
            "(Count, Scans, Seconds, Resolution, Real, ...)"
        )
    if kind in _SCALARS:
        return _SCALARS[kind]
    raise TypeError(f"unsupported config field type {kind!r}")


def _hints(config_type: type) -> dict[str, Any]:
    return typing.get_type_hints(config_type, include_extras=True)


def _field_name(config_type: type, name: str, experiment: str) -> str:
    """``"experiment mcl-kidnapping (KidnapConfig.threads)"``: the experiment the caller named
    (or the config's module when none was named), and the field."""
    what = f"experiment {experiment}" if experiment else f"config {config_type.__module__}"
    return f"{what} ({config_type.__qualname__}.{name})"


@functools.cache
def _model(config_type: type, experiment: str = "") -> type[FileModel]:
    """The model of ``config_type``'s fields: each optional, so only the keys given are
    checked (and set); the dataclass gives the defaults. ``experiment`` names the experiment
    in the message of a field that has no range."""
    hints = _hints(config_type)
    fields = {}
    for f in dataclasses.fields(config_type):
        try:
            fields[f.name] = (_strict(hints[f.name]), None)
        except TypeError as err:
            raise TypeError(f"{_field_name(config_type, f.name, experiment)}: {err}") from None
    return create_model(f"{config_type.__name__}Model", __base__=FileModel, **fields)


def _check(
    config_type: type, values: Any, source: str, at: tuple, experiment: str
) -> dict[str, Any]:
    try:
        checked = parse(_model(config_type, experiment), values, source, at=at)
    except SchemaError as err:
        raise ConfigError(str(err), err.errors) from None
    return {k: getattr(checked, k) for k in checked.model_fields_set}


def _base(kind: Any) -> Any:
    return typing.get_args(kind)[0] if typing.get_origin(kind) is Annotated else kind


def _value(text: str, kind: Any) -> Any:
    """An override's text as the value its field's type reads it: a string field takes the
    text; a list field takes comma-separated items; anything else is read as a YAML scalar
    (YAML 1.2 numbers: ``5e-2``; ``true``/``false``), so the model can name a bad one."""
    kind = _base(kind)
    if typing.get_origin(kind) in (list, tuple):
        (item,) = set(typing.get_args(kind)) - {Ellipsis} or {str}
        return [_value(p.strip(), item) for p in text.split(",") if p.strip()]
    if kind is str:
        return text
    try:
        value = safe_load_12(text)
    except yaml.YAMLError:
        value = text
    if isinstance(value, int | float | bool):
        return value
    try:  # "nan", "inf": numbers the model refuses as not finite; "1_0" is not 10
        return parse_float(text)
    except ValueError:
        return text


def apply_overrides(
    config: Any, overrides: list[str] | tuple[str, ...], experiment: str = ""
) -> Any:
    """Returns ``config`` with each ``key=value`` applied, checked against the field's type
    and limit; a :class:`ConfigError` ``"--set: key: problem, got VALUE"`` otherwise.
    ``experiment`` (its name) is named when the config type itself is at fault."""
    hints = _hints(type(config))
    values: dict[str, Any] = {}
    for item in overrides:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ConfigError(f"--set expects key=value, got {item!r}")
        if key not in hints:
            known = ", ".join(sorted(hints))
            raise ConfigError(f"--set: {key}: unknown config key (known: {known})")
        values[key] = _value(text.strip(), hints[key])
    checked = _check(type(config), values, "--set", (), experiment)
    return dataclasses.replace(config, **checked)


def config_to_dict(config: Any) -> dict[str, Any]:
    out = dataclasses.asdict(config)
    return {k: list(v) if isinstance(v, tuple) else v for k, v in out.items()}


def config_from_dict(
    config_type: type,
    values: dict[str, Any],
    source: str = "config",
    at: tuple[str | int, ...] = (),
    experiment: str = "",
) -> Any:
    """Builds a config from a dict (e.g. a saved config.yaml's ``config:`` section, with
    ``source`` the file and ``at=("config",)``), checking keys, types and limits;
    ``experiment`` (its name) is named when the config type itself is at fault."""
    return config_type(**_check(config_type, values, str(source), at, experiment))
