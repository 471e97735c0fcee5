# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""No claim compares a result with the number its scene was calibrated to: every scene's
``calibrated:`` marks (data/worlds/README.md) against the declared claims of every experiment
that uses the scene; and the reader itself, on a scene made for the test."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from kiseki.sim.scene import load_scene
from kiseki_experiments.harness.calibration import (
    calibration_conflicts,
    calibrations,
    scenes_of,
)
from kiseki_experiments.harness.paths import WORLDS
from kiseki_experiments.harness.registry import all_experiments, get_experiment
from kiseki_experiments.harness.verdict import ClaimSpec, Criterion

SCENE = """\
name: calibrated test scene
bounds: {min: [-1, -1, 0], max: [3, 3, 3]}
objects:
  - {type: wall, from: [0, 0], to: [2, 0], height: 2.0}
robot:
  type: diff_drive
  start: [0.5, 1.0, 0.0]
  odometry_errors: {left_radius_error: 0.004}
calibrated:
  - {parameter: robot.odometry_errors.left_radius_error, fitted_to: 0.678, unit: m,
     source: "thesis, Table 4.2"}
"""


def test_every_scene_loads_and_its_marks_name_a_parameter_of_it():
    for scene in sorted(WORLDS.glob("*.yaml")):
        for mark in calibrations(scene):  # raises when a parameter is not in the file
            assert {"parameter", "fitted_to", "unit", "source"} <= set(mark), scene.name


def test_no_claim_compares_with_a_number_its_scene_was_calibrated_to():
    problems = [p for e in all_experiments().values() for p in calibration_conflicts(e)]
    assert not problems, "\n".join(problems)


def test_experiments_name_the_scenes_they_use():
    assert [p.name for p in scenes_of(get_experiment("speed-situations"))] == [
        "speed_corridor.yaml",
        "speed_crossroad.yaml",
    ]
    assert [p.name for p in scenes_of(get_experiment("speed-fig4"))] == ["speed_corner.yaml"]


def _with_scene(tmp_path: Path, monkeypatch, paper_number):
    import kiseki_experiments.harness.calibration as calibration  # noqa: PLC0415 (patched here)

    (tmp_path / "calibrated.yaml").write_text(SCENE)
    monkeypatch.setattr(calibration, "WORLDS", tmp_path)
    base = get_experiment("speed-fig4")
    spec = ClaimSpec(
        "end",
        "odometry's end error",
        "m",
        Criterion("0.678 m", "within", 0.678, "the thesis' value", 0.05, (0, 1), paper_number),
        None,
    )
    return dataclasses.replace(base, claims=(spec,), scenes=("calibrated.yaml",))


@pytest.mark.parametrize("paper_number", [0.678, 0.6800])  # equal, and within 0.5 %
def test_a_claim_against_the_calibrated_number_is_caught(tmp_path, monkeypatch, paper_number):
    experiment = _with_scene(tmp_path, monkeypatch, paper_number)
    problems = calibration_conflicts(experiment)
    assert problems and "calibrated.yaml's robot.odometry_errors.left_radius_error" in problems[0]


def test_a_scene_with_marks_loads_and_a_bad_mark_is_refused(tmp_path):
    path = tmp_path / "calibrated.yaml"
    path.write_text(SCENE)
    assert load_scene(path).name == "calibrated test scene"
    path.write_text(SCENE.replace("fitted_to: 0.678", "fitted_to: many"))
    with pytest.raises(ValueError, match="fitted_to"):
        load_scene(path)
    path.write_text(SCENE.replace("left_radius_error, fitted", "tyre, fitted"))
    with pytest.raises(ValueError, match="no 'tyre' in the scene"):
        calibrations(path)
