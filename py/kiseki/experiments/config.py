# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Typed experiment configs: ``--set key=value`` overrides and the ``config:`` section of a
run's saved config.yaml, checked by a pydantic model built from the config dataclass's fields
(strict finite numbers, integers, booleans, strings and lists of them), and YAML round trips.

A field that sizes time declares its limit in its type: :data:`Particles`, :data:`Runs`
(``Annotated[int, Field(strict=True, gt=0, le=...)]``), and a seed is :data:`Seed`; a limit
is then in the message ("particles: must be less than or equal to 10000000, got ...")."""

from __future__ import annotations

import dataclasses
import functools
import typing
from typing import Annotated, Any

import yaml
from pydantic import Field, create_model

from kiseki._schema import FileModel, FiniteFloat, SchemaError, Seed, parse
from kiseki._yaml import safe_load_12

__all__ = [
    "LIST_LIMIT",
    "PARTICLE_LIMIT",
    "RUN_LIMIT",
    "ConfigError",
    "Particles",
    "Runs",
    "Seed",
    "apply_overrides",
    "config_from_dict",
    "config_to_dict",
]

PARTICLE_LIMIT = 10_000_000
"""The most particles an experiment's filter may take (as ``kiseki.localization.MclConfig``)."""
RUN_LIMIT = 100_000
"""The most runs (repetitions of a setting) an experiment's config may ask for."""
LIST_LIMIT = 10_000
"""The most items of a list in a config (its lists name logs, settings, move counts)."""

Particles = Annotated[int, Field(strict=True, gt=0, le=PARTICLE_LIMIT)]
Runs = Annotated[int, Field(strict=True, gt=0, le=RUN_LIMIT)]

_SCALARS: dict[Any, Any] = {
    float: FiniteFloat,
    int: Annotated[int, Field(strict=True)],
    bool: Annotated[bool, Field(strict=True)],
    str: Annotated[str, Field(strict=True)],
}


class ConfigError(SchemaError):
    """An unknown config key or a value of the wrong type or out of its limits: the message
    names the key and the value (and the file when the config was read from one)."""


def _strict(kind: Any) -> Any:
    """The model type of a dataclass field's type: strict, finite, lists of bounded length."""
    if typing.get_origin(kind) is Annotated:
        base, *meta = typing.get_args(kind)
        return Annotated[(_strict(base), *meta)]
    origin = typing.get_origin(kind)
    if origin in (list, tuple):
        (item,) = set(typing.get_args(kind)) - {Ellipsis} or {str}
        items = list[_strict(item)] if origin is list else tuple[_strict(item), ...]
        return Annotated[items, Field(max_length=LIST_LIMIT)]
    if kind in _SCALARS:
        return _SCALARS[kind]
    raise TypeError(f"unsupported config field type {kind!r}")


def _hints(config_type: type) -> dict[str, Any]:
    return typing.get_type_hints(config_type, include_extras=True)


@functools.cache
def _model(config_type: type) -> type[FileModel]:
    """The model of ``config_type``'s fields: each optional, so only the keys given are
    checked (and set); the dataclass gives the defaults."""
    hints = _hints(config_type)
    fields = {f.name: (_strict(hints[f.name]), None) for f in dataclasses.fields(config_type)}
    return create_model(f"{config_type.__name__}Model", __base__=FileModel, **fields)


def _check(config_type: type, values: Any, source: str, at: tuple) -> dict[str, Any]:
    try:
        checked = parse(_model(config_type), values, source, at=at)
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
    try:  # "nan", "inf": numbers the model refuses as not finite
        return float(text)
    except ValueError:
        return text


def apply_overrides(config: Any, overrides: list[str] | tuple[str, ...]) -> Any:
    """Returns ``config`` with each ``key=value`` applied, checked against the field's type
    and limit; a :class:`ConfigError` ``"--set: key: problem, got VALUE"`` otherwise."""
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
    return dataclasses.replace(config, **_check(type(config), values, "--set", ()))


def config_to_dict(config: Any) -> dict[str, Any]:
    out = dataclasses.asdict(config)
    return {k: list(v) if isinstance(v, tuple) else v for k, v in out.items()}


def config_from_dict(
    config_type: type,
    values: dict[str, Any],
    source: str = "config",
    at: tuple[str | int, ...] = (),
) -> Any:
    """Builds a config from a dict (e.g. a saved config.yaml's ``config:`` section, with
    ``source`` the file and ``at=("config",)``), checking keys, types and limits."""
    return config_type(**_check(config_type, values, str(source), at))
