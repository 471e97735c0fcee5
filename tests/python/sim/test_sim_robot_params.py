# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The simulated robots' and odometry errors' parameters: the papers' numbers, dictionaries and
ranges."""

from __future__ import annotations

import dataclasses
import math

import pytest

from _helpers.sim_robot import NONE
from kiseki.sim.motion import WheelMotion
from kiseki.sim.odometry import WheelOdometry
from kiseki.sim.robot_params import (
    DiffDriveParams,
    OdometryErrorParams,
    OmniOdometryErrorParams,
    OmniParams,
)

# ------------------------------------------------------------------------------- parameters


def test_defaults_carry_the_papers_numbers():
    p = DiffDriveParams()
    assert (p.length, p.width, p.height) == (1.05, 0.58, 0.99)
    assert (p.encoder_counts_per_rev, p.gear_ratio) == (500, 70.0)
    assert p.track_width < p.width  # wheels inside the body
    o = OmniParams()
    assert (o.width, o.max_speed, o.max_accel) == (0.70, 0.5, 0.5)


def test_counts_per_wheel_revolution():
    assert DiffDriveParams().counts_per_wheel_rev == 500 * 70 * 4
    x1 = DiffDriveParams(quadrature=False)
    assert x1.counts_per_wheel_rev == 500 * 70
    # Behaviour, not just the property: 10.5 wheel revolutions (plus a quarter count, clear of
    # the edge) give exactly 10.5 x 35000 counts, in one step or in 1000 small ones.
    travel = 2 * math.pi * x1.wheel_radius * 10.5 + 0.25 * x1.distance_per_count
    one = WheelOdometry(x1, NONE, seed=1)
    one.update(WheelMotion(travel, travel, 1.0))
    assert one.counts == (367500, 367500)
    many = WheelOdometry(x1, NONE, seed=1)
    for _ in range(1000):
        many.update(WheelMotion(travel / 1000, -travel / 1000, 0.01))
    assert many.counts[0] == 367500
    assert many.counts[1] == -367501  # floor: backwards travel reaches the next lower count


def test_from_dict_round_trip_and_defaults():
    p = DiffDriveParams.from_dict({"wheel_radius": 0.1, "encoder_counts_per_rev": 1024}, "a")
    assert p.wheel_radius == 0.1 and p.encoder_counts_per_rev == 1024
    assert isinstance(p.encoder_counts_per_rev, int) and p.track_width == 0.50
    assert isinstance(DiffDriveParams.from_dict({"max_speed": 2}).max_speed, float)  # int -> float
    for cls in (DiffDriveParams, OmniParams, OdometryErrorParams, OmniOdometryErrorParams):
        q = cls()
        assert cls.from_dict(q.to_dict(), "round trip") == q
        new = {"Flag": False, "PositiveInt": 7}  # every other field takes 0.5
        changed = {f.name: new.get(str(f.type), 0.5) for f in dataclasses.fields(cls)}
        assert cls.from_dict(changed).to_dict() == {**q.to_dict(), **changed}


@pytest.mark.parametrize(
    ("cls", "key", "value", "needle"),
    [
        (DiffDriveParams, "wheel_radiuss", 0.1, "wheel_radiuss: unknown key"),
        (DiffDriveParams, "wheel_radius", 0.0, "wheel_radius: must be greater than 0, got 0.0"),
        (DiffDriveParams, "track_width", -0.5, "track_width: must be greater than 0, got -0.5"),
        (DiffDriveParams, "max_speed", float("nan"), "max_speed: must be a finite number, got nan"),
        (DiffDriveParams, "max_accel", float("inf"), "max_accel: must be a finite number, got inf"),
        (DiffDriveParams, "length", "1.05", "length: must be a valid number, got '1.05'"),
        (DiffDriveParams, "height", True, "height: must be a valid number, got True"),
        (DiffDriveParams, "encoder_counts_per_rev", 500.5, "encoder_counts_per_rev: must be a"),
        (DiffDriveParams, "encoder_counts_per_rev", 500.0, "encoder_counts_per_rev: must be a"),
        (DiffDriveParams, "encoder_counts_per_rev", 0, "encoder_counts_per_rev: must be greater"),
        (DiffDriveParams, "quadrature", 1, "quadrature: must be a valid boolean, got 1"),
        (OmniParams, "max_yaw_rate", 0, "max_yaw_rate: must be greater than 0, got 0"),
        (OmniParams, "v_max", 0.5, "v_max: unknown key"),
        (
            OdometryErrorParams,
            "left_radius_error",
            -1.0,
            "left_radius_error: must be greater than -1",
        ),
        (OdometryErrorParams, "track_width_error", 1.0, "track_width_error: must be less than 1"),
        (OdometryErrorParams, "slip_distance_coeff", -1e-6, "slip_distance_coeff: must be greater"),
        (
            OdometryErrorParams,
            "initial_heading_offset",
            float("nan"),
            "initial_heading_offset: must",
        ),
        (OmniOdometryErrorParams, "translation_coeff", -1.0, "translation_coeff: must be greater"),
    ],
)
def test_from_dict_rejects_bad_input_naming_source_and_key(cls, key, value, needle):
    with pytest.raises(ValueError) as info:
        cls.from_dict({key: value}, "robots/agv.yaml")
    message = str(info.value)
    assert message.startswith("robots/agv.yaml: ") and needle in message
    # a section inside a bigger file: the whole path
    with pytest.raises(ValueError, match=rf"^scene\.yaml: robots\[1\]\.params\.{key}: "):
        cls.from_dict({key: value}, "scene.yaml", at=("robots", 1, "params"))


# the range of every parameter, written out here (not read from the classes)
SIZES = ["length", "width", "max_speed", "max_accel", "max_yaw_rate", "max_yaw_accel"]
KINDS = {
    DiffDriveParams: {
        **dict.fromkeys([*SIZES, "height", "wheel_radius", "track_width", "gear_ratio"], "size"),
        "encoder_counts_per_rev": "count",
        "quadrature": "flag",
    },
    OmniParams: dict.fromkeys(SIZES, "size"),
    OdometryErrorParams: {
        **dict.fromkeys(["left_radius_error", "right_radius_error", "track_width_error"], "rel"),
        "initial_heading_offset": "finite",
        **dict.fromkeys(["initial_heading_sd", "slip_distance_coeff", "slip_rotation_coeff"], "sd"),
    },
    OmniOdometryErrorParams: dict.fromkeys(
        ["translation_coeff", "heading_distance_coeff", "heading_rotation_coeff"], "sd"
    ),
}
EDGES = {  # a value just outside the range, one just inside
    "size": [(0.0, 1e-9)],
    "count": [(0, 1), (2.0, 2)],
    "sd": [(-1e-12, 0.0)],
    "rel": [(-1.0, -0.999), (1.0, 0.999)],
    # finite and within kiseki._support.schema.MAGNITUDE_LIMIT (1e9)
    "finite": [(float("-inf"), -1e9), (-2e9, 0.0), (float("nan"), 0.0)],
    "flag": [(0, False), ("yes", True)],
}


@pytest.mark.parametrize("cls", list(KINDS))
def test_every_field_has_its_range(cls):
    assert {f.name for f in dataclasses.fields(cls)} == set(KINDS[cls])
    for name, kind in KINDS[cls].items():
        for bad, good in EDGES[kind]:
            assert getattr(cls.from_dict({name: good}), name) == good
            # an integral float given for an integer is told how to write it
            hint = r"( \(write it as -?\d+, without a point or an exponent\))?"
            with pytest.raises(ValueError, match=rf"^s\.yaml: {name}: .*, got {bad!r}{hint}$"):
                cls.from_dict({name: bad}, "s.yaml")


def test_direct_construction_is_validated_too():
    with pytest.raises(ValueError, match=r"DiffDriveParams\nwheel_radius\n.*finite number"):
        DiffDriveParams(wheel_radius=float("nan"))
    with pytest.raises(ValueError, match=r"OdometryErrorParams\nslip_rotation_coeff"):
        dataclasses.replace(OdometryErrorParams(), slip_rotation_coeff=-1.0)
    with pytest.raises(ValueError, match="^x.yaml: must be a mapping"):
        OmniParams.from_dict([("width", 1.0)], "x.yaml")  # type: ignore[arg-type]
