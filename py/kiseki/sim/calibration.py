# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Calibration marks: the scene parameters that were fitted to a paper's number.

A scene built to reproduce a paper's experiment sometimes has a value the paper does not print,
chosen so that one of the paper's *results* comes out (``magnetic_path.yaml``'s tyre radii give
odometry's 0.678 m travel-distance error of the thesis' Table 4.2). That result is then no
result of the reproduction: comparing a run with it checks the fit, not the method. A scene says
so in a top-level ``calibrated`` list, one entry per fitted parameter::

    calibrated:
      - {parameter: robot.odometry_errors.left_radius_error, fitted_to: 0.678, unit: m,
         source: "002, Table 4.2 (mean error without localization)"}

``parameter`` is the dotted key path of the value in the scene file (list items by their index:
``robots.0.route.speed``); the entries' types are :class:`kiseki.sim.scene_schema.Calibration`'s,
and :func:`check_marks` checks that each path names a value.
"""

from __future__ import annotations

from typing import Any

from kiseki._support.schema import SchemaError
from kiseki.sim.scene_schema import Calibration

__all__ = ["check_marks", "value_at"]


def value_at(doc: Any, parameter: str) -> Any:
    """The value at the dotted key path ``parameter`` of a parsed YAML document; a KeyError
    naming the first part that is not there."""
    here = doc
    for part in parameter.split("."):
        if isinstance(here, dict) and part in here:
            here = here[part]
        elif isinstance(here, list) and part.isdigit() and int(part) < len(here):
            here = here[int(part)]
        else:
            raise KeyError(part)
    return here


def check_marks(doc: dict, marks: list[Calibration], source: str) -> list[dict]:
    """The marks as plain mappings, after checking that each names a value of ``doc``."""
    for k, mark in enumerate(marks):
        try:
            value_at(doc, mark.parameter)
        except KeyError as missing:
            raise SchemaError(
                f"{source}: calibrated[{k}].parameter: {mark.parameter!r} names no value in "
                f"the scene (no {missing.args[0]!r})"
            ) from None
    return [mark.model_dump() for mark in marks]
