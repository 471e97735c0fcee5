# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Typed experiment configs: ``--set key=value`` overrides checked against the dataclass's
field types, and YAML round trips."""

from __future__ import annotations

import dataclasses
import typing
from typing import Any

from kiseki.errors import KisekiError

__all__ = ["ConfigError", "apply_overrides", "config_from_dict", "config_to_dict"]

_TRUE = {"true", "yes", "on", "1"}
_FALSE = {"false", "no", "off", "0"}


class ConfigError(KisekiError, ValueError):
    """An unknown config key or a value of the wrong type."""


def _convert(key: str, text: str, kind: Any) -> Any:
    origin = typing.get_origin(kind)
    if origin in (list, tuple):
        (item,) = set(typing.get_args(kind)) - {Ellipsis} or {str}
        parts = [p.strip() for p in text.split(",") if p.strip()]
        values = [_convert(key, p, item) for p in parts]
        return values if origin is list else tuple(values)
    try:
        if kind is bool:
            if text.lower() in _TRUE:
                return True
            if text.lower() in _FALSE:
                return False
            raise ValueError
        if kind is int:
            return int(text)
        if kind is float:
            return float(text)
        if kind is str:
            return text
    except ValueError:
        raise ConfigError(f"{key}: expected {kind.__name__}, got {text!r}") from None
    raise ConfigError(f"{key}: unsupported config type {kind}")


def _hints(config_type: type) -> dict[str, Any]:
    return typing.get_type_hints(config_type)


def apply_overrides(config: Any, overrides: list[str] | tuple[str, ...]) -> Any:
    """Returns ``config`` with each ``key=value`` applied, converted to the field's type."""
    hints = _hints(type(config))
    changes: dict[str, Any] = {}
    for item in overrides:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise ConfigError(f"--set expects key=value, got {item!r}")
        if key not in hints:
            known = ", ".join(sorted(hints))
            raise ConfigError(f"unknown config key {key!r} (known: {known})")
        changes[key] = _convert(key, text.strip(), hints[key])
    return dataclasses.replace(config, **changes)


def config_to_dict(config: Any) -> dict[str, Any]:
    out = dataclasses.asdict(config)
    return {k: list(v) if isinstance(v, tuple) else v for k, v in out.items()}


def config_from_dict(config_type: type, values: dict[str, Any]) -> Any:
    """Builds a config from a dict (e.g. a saved config.yaml), checking keys and types."""
    hints = _hints(config_type)
    unknown = sorted(set(values) - set(hints))
    if unknown:
        raise ConfigError(f"unknown config key(s): {', '.join(unknown)}")
    checked = {}
    for key, value in values.items():
        kind = hints[key]
        if typing.get_origin(kind) in (list, tuple):
            text = ",".join(str(v) for v in value) if isinstance(value, list | tuple) else value
        else:
            text = str(value)
        checked[key] = _convert(key, str(text), kind)
    return config_type(**checked)
