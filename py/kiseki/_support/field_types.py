# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The kinds of a config's fields, checked from their annotations: a field annotated ``bool``
holds True or False (the string "no" is truthy and was read as True), one annotated ``int`` an
integer (True counted as 1 particle, 1000.7 as a particle count), one annotated ``float`` a
number. A numpy scalar of the right kind is taken and held as the Python bool, int or float
it is (``np.int64(60)`` beams as 60, ``np.float32(0.5)`` as 0.5, a long double rounded to a
float): a config is saved with its results as JSON or YAML, neither of which writes a numpy
scalar; so ``np.bool_`` switches and ``np.float32`` numbers pass the configs' own checks
that compare with Python's types. Other annotations (tuples, strings, optional values) are left to
each config's own checks, which run after this one and keep their messages for values of the
right kind."""

from __future__ import annotations

import dataclasses
import numbers

import numpy as np

__all__ = ["check_field_types"]


def _kind_ok(kind: str, value) -> bool:
    if kind == "bool":
        return isinstance(value, bool | np.bool_)
    if isinstance(value, bool | np.bool_):
        return False
    if kind == "int":
        return isinstance(value, numbers.Integral)
    return isinstance(value, numbers.Real)  # float: any real number


def check_field_types(config) -> None:
    """Raises ValueError naming the first field of the dataclass instance `config` whose value is
    not of its annotated kind (bool, int or float, each possibly ``| None``); replaces a numpy
    scalar field of such a kind by its Python number."""
    for f in dataclasses.fields(config):
        annotation = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", "")
        kind, _, rest = annotation.replace(" ", "").partition("|")
        optional = rest == "None"
        if kind not in ("bool", "int", "float") or rest not in ("", "None"):
            continue
        value = getattr(config, f.name)
        if optional and value is None:
            continue
        if not _kind_ok(kind, value):
            want = {"bool": "True or False", "int": "an integer", "float": "a number"}[kind]
            raise ValueError(f"{type(config).__name__}.{f.name} must be {want}, got {value!r}")
        if isinstance(value, np.generic):  # held as Python's own: saved configs are JSON / YAML
            python = {"bool": bool, "int": int}.get(kind, float)
            object.__setattr__(config, f.name, python(value))
