# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""A config type's default for a field, so that an option's default is written once: in the
config type the command builds."""

from __future__ import annotations

import dataclasses

__all__ = ["default_of"]


def default_of(config_type: type, field: str):
    """The default of ``field`` of a dataclass or a pydantic model."""
    if dataclasses.is_dataclass(config_type):
        for each in dataclasses.fields(config_type):
            if each.name == field:
                if each.default is not dataclasses.MISSING:
                    return each.default
                if each.default_factory is not dataclasses.MISSING:
                    return each.default_factory()
        raise KeyError(f"{config_type.__name__}.{field} has no default")
    return config_type.model_fields[field].get_default(call_default_factory=True)
