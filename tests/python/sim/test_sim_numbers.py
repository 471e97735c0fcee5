# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The simulator's single numbers (a run's time step and limits, a gyro's SDs and times, a
survey's noise and steps, a footprint, a grid's resolution) are finite numbers in their ranges,
each refused in one line naming it; True is no 1 m and the text "0.1" no resolution."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from kiseki import _core
from kiseki.sim.gyro import Gyro, error_sd
from kiseki.sim.magnetic import MagneticWorld
from kiseki.sim.magnetic_survey import MeasurementGrid, hand_survey, route_stops
from kiseki.sim.pose6 import terrain_pose
from kiseki.sim.primitives import BoxList
from kiseki.sim.run import SimConfig
from kiseki.sim.scene import load_scene
from kiseki.sim.setup import build_robot, build_sensors
from kiseki.sim.terrain_moves import terrain_stops

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"


def _floor() -> _core.BoxWorld:
    boxes = BoxList.empty()
    boxes.add([0.0, 0.0, -0.05], [10.0, 10.0, 0.1])
    return _core.BoxWorld(*boxes.arrays())


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: SimConfig(dt=0.0), "dt must be a finite number > 0 s, got 0.0"),
        (
            lambda: SimConfig(duration=1e6),
            "duration must be a finite number in (0, 86,400] s, got 1000000.0",
        ),
        (
            lambda: SimConfig(max_duration=math.nan),
            "max_duration must be a finite number in (0, 86,400] s, got nan",
        ),
        (lambda: SimConfig(lookahead=math.inf), "lookahead must be a finite number > 0 m, got inf"),
        (
            lambda: Gyro(reading_sd_deg=-0.5),
            "gyro: reading_sd_deg must be a finite number >= 0, got -0.5",
        ),
        (lambda: Gyro().error_deg(math.nan), "gyro: t must be a finite number >= 0 s, got nan"),
        (
            lambda: error_sd(-1.0, 0.5, 0.01, 0.005),
            "gyro: t must be a finite number >= 0 s, got -1.0",
        ),
        (
            lambda: MeasurementGrid((0, 0, 0), (1, 1, 0), 0.0, where="grid"),
            "grid: spacing must be a finite number > 0 m, got 0.0",
        ),
        (
            lambda: hand_survey(MagneticWorld(), [[0.0, 0.0, 0.0]], noise_sd=math.inf),
            "noise_sd must be a finite number >= 0 G, got inf",  # was the core's 'stddev'
        ),
        (
            lambda: route_stops([[0, 0], [1, 0]], step=True),
            "step must be a finite number > 0 m, got True",
        ),
        (
            lambda: route_stops([[0, 0], [1, 0]], step=math.inf),
            "step must be a finite number > 0 m, got inf",
        ),
        (
            lambda: terrain_pose(_floor(), 1.0, 1.0, 0.0, True, 0.4, from_z=1.0),
            "terrain_pose: length must be a finite number > 0 m, got True",  # was 1 m
        ),
        (
            lambda: terrain_pose(_floor(), 1.0, 1.0, 0.0, 0.6, 0.0, from_z=1.0),
            "terrain_pose: width must be a finite number > 0 m, got 0.0",
        ),
        (
            lambda: terrain_pose(_floor(), 1.0, math.nan, 0.0, 0.6, 0.4, from_z=1.0),
            "terrain_pose: y must be a finite number, got nan",
        ),
        (
            lambda: terrain_stops(WORLDS / "rubble_a.yaml", 3, 0, step=0.7),
            "step must be a finite number in [0.02, 0.6] m, got 0.7",
        ),
    ],
)
def test_a_bad_number_is_named_in_one_line(call, message):
    with pytest.raises(ValueError) as caught:
        call()
    assert str(caught.value) == message


@pytest.mark.parametrize("bad", [0.0, "0.1", True])  # float() took the text and True (1 m)
def test_a_ground_truth_resolution_is_a_positive_number(bad):
    scene = load_scene(WORLDS / "speed_corridor.yaml")
    with pytest.raises(ValueError) as caught:
        scene.ground_truth(0.3, 0.5, resolution=bad)
    assert str(caught.value) == f"resolution must be a finite number > 0 m, got {bad!r}"


def test_the_sensors_time_step_is_a_positive_number():
    scene = load_scene(WORLDS / "speed_corridor.yaml")
    robot = build_robot(scene, 0)
    with pytest.raises(ValueError) as caught:
        build_sensors(scene, robot, 0, math.nan)
    assert str(caught.value) == f"{scene.path}: dt must be a finite number > 0 s, got nan"
