# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Calibrated scenes: a scene file's top-level ``calibrated:`` list names the parameters fitted
to a paper's number ({parameter: dotted key path, fitted_to: number, unit, source}; the scene
model is kiseki.sim.scene_schema.Calibration). No claim of an experiment that uses the scene may
compare a result with such a number: a claim whose paper number or threshold is within 0.5 % of
a ``fitted_to`` is a conflict."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from kiseki._support.yaml import read_yaml_file
from kiseki.sim.calibration import value_at
from kiseki_experiments.harness.base import Experiment
from kiseki_experiments.harness.paths import WORLDS

__all__ = ["RELATIVE", "calibration_conflicts", "calibrations", "scenes_of"]

RELATIVE = 0.005
"""Numbers within 0.5 % of each other count as the same number."""


def calibrations(scene: str | Path) -> list[dict[str, Any]]:
    """A scene file's calibration marks, each checked: its parameter is in the scene."""
    doc = read_yaml_file(Path(scene), "scene")
    marks = (doc or {}).get("calibrated") or []
    if not isinstance(marks, list):
        raise ValueError(f"{scene}: calibrated must be a list of marks")
    for mark in marks:
        try:
            value_at(doc, str(mark["parameter"]))
        except KeyError as missing:
            raise ValueError(
                f"{scene}: calibrated: {mark['parameter']}: no {missing.args[0]!r} in the scene"
            ) from None
    return marks


def scenes_of(experiment: Experiment) -> list[Path]:
    """The scene files an experiment uses: those it declares (``Experiment.scenes``, names in
    data/worlds) and any its default config names (a path to a data/worlds/*.yaml)."""
    found = {WORLDS / name for name in experiment.scenes}
    config = experiment.config_type()
    for f in dataclasses.fields(config):
        value = getattr(config, f.name)
        for item in value if isinstance(value, list | tuple) else [value]:
            if isinstance(item, str) and item.endswith(".yaml"):
                path = Path(item)
                if path.parent.resolve() == WORLDS.resolve():
                    found.add(WORLDS / path.name)
    return sorted(found)


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= RELATIVE * max(abs(a), abs(b))


def calibration_conflicts(experiment: Experiment) -> list[str]:
    """Each declared claim of ``experiment`` whose paper number or threshold equals (within
    0.5 %) a number one of its scenes was calibrated to."""
    out = []
    for scene in scenes_of(experiment):
        for mark in calibrations(scene):
            fitted = float(mark["fitted_to"])
            for spec in experiment.claims:
                c = spec.criterion
                for what, number in (("paper number", c.paper_number), ("threshold", c.threshold)):
                    if number is not None and _close(float(number), fitted):
                        out.append(
                            f"{experiment.name}: {spec.key}'s {what} {number:g} is the "
                            f"{fitted:g} {mark.get('unit', '')} that {scene.name}'s "
                            f"{mark['parameter']} was fitted to ({mark.get('source', '')})"
                        )
    return out
