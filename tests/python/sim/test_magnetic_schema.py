# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The model of a scene's ``magnetic:`` section: the thesis scenes read to the same field as
the objects built by hand from their YAML, the dipole limits (a line's length / spacing, a
lattice's volume / spacing^3, the whole section) are enforced with the limit in the message,
and a bad type, NaN or unknown key is named with the file and its whole key path."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from kiseki._support.yaml import safe_load_12
from kiseki.sim.magnetic import (
    Dipole,
    DipoleLine,
    MagneticWorld,
    default_earth_field,
    earth_field_from_angles,
)
from kiseki.sim.magnetic_lattice import MAX_LATTICE_DIPOLES, DipoleLattice
from kiseki.sim.magnetic_schema import MAX_LINE_DIPOLES, MAX_WORLD_DIPOLES

WORLDS = Path(__file__).resolve().parents[3] / "data" / "worlds"


def _by_hand(section: dict, variant: str = "teach") -> MagneticWorld:
    """The world built from the YAML's values with the constructors, without the model: the
    sources marked ``only_in`` the other variant left out."""

    def here(key: str) -> list[dict]:
        items = section.get(key, [])
        kept = [x for x in items if x.get("only_in", variant) == variant]
        return [{k: v for k, v in x.items() if k != "only_in"} for x in kept]

    earth = section.get("earth_field")
    if isinstance(earth, dict):
        earth = earth_field_from_angles(
            earth["total"], earth["inclination_deg"], earth.get("declination_deg", 0.0)
        )
    drift = section.get("drift", {})
    return MagneticWorld(
        earth_field=earth,
        dipoles=[Dipole(**d) for d in here("dipoles")],
        lines=[DipoleLine(**ln) for ln in here("lines")],
        lattices=[DipoleLattice(**lat) for lat in here("lattices")],
        gradient=section.get("gradient"),
        gradient_origin=section.get("gradient_origin", (0.0, 0.0, 0.0)),
        **{f"drift_{k}": v for k, v in drift.items()},
    )


@pytest.mark.parametrize("name", ["magnetic_floor", "magnetic_hall", "magnetic_path"])
def test_the_thesis_scenes_read_to_the_field_of_the_objects_built_by_hand(name):
    section = safe_load_12((WORLDS / f"{name}.yaml").read_text())["magnetic"]
    world = MagneticWorld.from_dict(section, f"{name}.yaml")
    reference = _by_hand(section)
    points = np.random.default_rng(3).uniform([-2, -2, 0], [30, 15, 2.5], (200, 3))
    np.testing.assert_array_equal(
        world.field_at(points, 5000.0), reference.field_at(points, 5000.0)
    )
    assert len(world._positions) == len(reference._positions) > 0
    assert world.drift_period == reference.drift_period


def test_unset_keys_keep_the_constructors_defaults():
    world = MagneticWorld.from_dict({"drift": {"phase": 1.0}}, "s.yaml")
    np.testing.assert_array_equal(world.earth_field, default_earth_field())
    assert (world.drift_amplitude, world.drift_period, world.drift_phase) == (
        MagneticWorld().drift_amplitude,
        MagneticWorld().drift_period,
        1.0,
    )


def _line(length: float, spacing: float) -> dict:
    return {"start": [0, 0, 0], "end": [length, 0, 0], "moment_per_metre": [0, 0, 1],
            "spacing": spacing}  # fmt: skip


def _lattice(side: float, spacing: float) -> dict:
    return {"lower": [0, 0, 0], "upper": [side, side, 0], "spacing": spacing,
            "moment_sd": [1, 1, 1]}  # fmt: skip


def _error(section: dict) -> str:
    with pytest.raises(ValueError) as info:
        MagneticWorld.from_dict(section, "scene.yaml", at=("magnetic",))
    return str(info.value)


def test_a_line_of_more_dipoles_than_the_limit_is_refused_with_the_limit():
    assert len(MagneticWorld.from_dict({"lines": [_line(100.0, 0.002)]}).lines[0].positions) == (
        MAX_LINE_DIPOLES
    )
    assert _error({"lines": [_line(100.0, 0.0019)]}) == (
        f"scene.yaml: magnetic.lines[0].spacing: makes 52632 dipoles over the line's 100 m, "
        f"more than the limit of {MAX_LINE_DIPOLES} (spacing >= 0.002 m), got 0.0019"
    )


def test_a_lattice_of_more_dipoles_than_the_limit_is_refused_with_the_limit():
    # 100 x 100 m at 0.5 m: 200 x 200 = 40,000 dipoles; at 0.4 m: 250 x 250 = 62,500
    assert len(MagneticWorld.from_dict({"lattices": [_lattice(100, 0.5)]})._positions) == 40_000
    text = _error({"lattices": [{}, _lattice(100, 0.4)]})
    assert text.startswith("scene.yaml: magnetic.lattices[0].lower: missing (and ")
    text = _error({"lattices": [_lattice(100, 0.4)]})
    assert text.startswith("scene.yaml: magnetic.lattices[0].spacing: makes 62500 dipoles")
    assert text.endswith(f"more than the limit of {MAX_LATTICE_DIPOLES}, got 0.4")


def test_a_section_of_more_dipoles_than_the_limit_is_refused_with_the_limit():
    # four lattices of 40,000 and a line of 40,001 make 200,001
    section = {"lines": [_line(40_001 * 0.1, 0.1)], "lattices": [_lattice(100, 0.5)] * 4}
    assert _error(section).startswith(
        f"scene.yaml: magnetic.lattices: with the dipoles and lines: 200001 dipoles in all, "
        f"more than the limit of {MAX_WORLD_DIPOLES}, got ["
    )
    section["lines"] = [_line(40_000 * 0.1, 0.1)]
    assert len(MagneticWorld.from_dict(section)._positions) == MAX_WORLD_DIPOLES


@pytest.mark.parametrize(
    ("section", "message"),
    [
        ({"dipoles": [{"position": [0, 0, "1"], "moment": [0, 0, 1]}]},
         "dipoles[0].position[2]: must be a valid number, got '1'"),
        ({"dipoles": [{"position": [0, 0, 0], "moment": [0, 0, 1], "radius": 0}]},
         "dipoles[0].radius: must be greater than 0, got 0"),
        ({"dipoles": [5]},
         "dipoles[0]: must be a mapping of position, moment, radius, only_in, got 5"),
        ({"lines": [{**_line(1, 0.1), "spacing": float("nan")}]},
         "lines[0].spacing: must be a finite number, got nan"),
        ({"lines": [{**_line(1, 0.1), "colour": "red"}]}, "lines[0].colour: unknown key"),
        ({"lattices": [{**_lattice(1, 0.1), "seed": 2**64}]},
         "lattices[0].seed: must be an integer in [0, 2**64), got 18446744073709551616"),
        ({"lattices": [{**_lattice(1, 0.1), "moment_sd": [1, 1, -1]}]},
         "lattices[0].moment_sd[2]: must be greater than or equal to 0, got -1"),
        ({"earth_field": {"total": -1, "inclination_deg": 0}},
         "earth_field.total: must be greater than or equal to 0, got -1"),
        ({"earth_field": {"total": 0.4, "inclination_deg": -91}},
         "earth_field.inclination_deg: must be greater than or equal to -90, got -91"),
        ({"earth_field": "north"},
         "earth_field: must be a list of 3 numbers [x, y, z], got 'north'"),
        ({"gradient": [[0, 0, 0], [0, 0, 0], [0, float("inf"), 0]]},
         "gradient[2][1]: must be a finite number, got inf"),
        ({"gradient_origin": [0, 0, None]}, "gradient_origin[2]: must be a valid number, got None"),
        ({"drift": [1]}, "drift: must be a mapping of amplitude, period, phase, got [1]"),
        ({"drift": {"period": True}}, "drift.period: must be a valid number, got True"),
    ],
)  # fmt: skip
def test_a_bad_value_is_named_with_the_file_and_its_whole_key_path(section, message):
    assert _error(section) == f"scene.yaml: magnetic.{message}"


def test_the_round_trip_of_to_dict_keeps_every_source_gradient_and_drift():
    """to_dict then from_dict gives the field of the objects built by hand from the section
    (a key dropped on either way would change it: every kind of key is set here)."""
    section = safe_load_12((WORLDS / "magnetic_hall.yaml").read_text())["magnetic"]
    section = dict(
        section,
        dipoles=[{"position": [1.0, 2.0, 0.5], "moment": [0.0, 5.0, -20.0], "radius": 0.2}],
        gradient=[[0.001, 0.0, 0.0], [0.0, -0.002, 0.0], [0.0, 0.0, 0.001]],
        gradient_origin=[1.0, 1.0, 0.0],
        drift={"amplitude": 0.01, "period": 30.0, "phase": 0.4},
    )
    again = MagneticWorld.from_dict(MagneticWorld.from_dict(section, "hall").to_dict(), "again")
    points = np.random.default_rng(4).uniform(0, 10, (50, 3))
    expected = _by_hand(section).field_at(points, 10.0)
    np.testing.assert_allclose(again.field_at(points, 10.0), expected, rtol=0, atol=1e-15)
    assert set(MagneticWorld.from_dict(section, "hall").to_dict()) == {
        "earth_field", "dipoles", "lines", "lattices", "gradient", "gradient_origin", "drift",
    }  # fmt: skip


_BAR = {"inner": 0.35, "sensors_apart": 0.6, "heights": [0.1, 2.0], "period": 20.0,
        "yaw_deg": [-20.0, 20.0], "yaw_period": 60.0}  # fmt: skip


def test_an_arm_mapping_reads_to_the_arm_built_by_hand():
    from kiseki.sim.magnetic_arm import ArmMagnetometers, arm_sensor_from_spec

    world = MagneticWorld()
    pivot = (0.4, 0.0, 1.05)
    reference = ArmMagnetometers(world, pivot, 0.35, 0.6, (0.1, 2.0), 20.0, (-20, 20), 60.0)
    far = arm_sensor_from_spec({**_BAR, "sensor": "far"}, world, pivot, where="s.yaml: arm")
    poses, times = np.zeros((7, 3)), np.linspace(0.0, 90.0, 7)
    np.testing.assert_array_equal(
        far.sensor_positions(poses, times), reference.sensor_positions(poses, times)[:, 1]
    )


@pytest.mark.parametrize(
    ("arm", "message"),
    [
        ({**_BAR, "sensor": "far", "heights": [2.0, 0.1]},
         "heights: must be [zmin, zmax] m with 0 <= zmin < zmax, got [2.0, 0.1]"),
        ({**_BAR, "sensor": "far", "yaw_period": None},
         "yaw_period: must be a valid number, got None"),
        ({k: v for k, v in _BAR.items() if k != "yaw_period"} | {"sensor": "near"},
         "yaw_deg: sweeps (lo != hi): yaw_period is needed, got [-20.0, 20.0]"),
        ({**_BAR, "sensor": "far", "period": float("nan")},
         "period: must be a finite number, got nan"),
        (_BAR, "sensor: missing (near or far)"),
    ],
)  # fmt: skip
def test_a_bad_arm_is_named_with_the_file_and_its_key_path(arm, message):
    from kiseki.sim.magnetic_arm import arm_sensor_from_spec

    with pytest.raises(ValueError) as info:
        arm_sensor_from_spec(arm, MagneticWorld(), (0.4, 0.0, 1.05), where="s.yaml: robots[1].arm")
    assert str(info.value).startswith(f"s.yaml: robots[1].arm.{message}")


def test_a_scene_file_names_its_bad_magnetic_key_at_load_and_when_sensors_are_built(tmp_path):
    """A bad magnetic section is refused by load_scene even when no magnetometer would build the
    field, and the message has the section's prefix when the sensors build it."""
    from kiseki.sim.scene import load_scene
    from kiseki.sim.setup import build_robot, build_sensors

    doc = yaml.safe_load((WORLDS / "magnetic_path.yaml").read_text())
    doc["magnetic"]["lines"][0]["moment_per_metre"] = [0.0, float("nan"), 1.0]
    no_magnetometer = dict(doc, sensors=[s for s in doc["sensors"] if s["type"] == "laser"])
    (tmp_path / "a.yaml").write_text(yaml.safe_dump(no_magnetometer))
    expected = r"magnetic\.lines\[0\]\.moment_per_metre\[1\]: must be a finite number, got nan"
    with pytest.raises(ValueError, match=r"a\.yaml: " + expected):
        load_scene(tmp_path / "a.yaml")
    good = yaml.safe_load((WORLDS / "magnetic_path.yaml").read_text())
    (tmp_path / "b.yaml").write_text(yaml.safe_dump(good))
    scene = load_scene(tmp_path / "b.yaml")
    scene.magnetic["lines"][0]["moment_per_metre"] = [0.0, float("nan"), 1.0]  # past the loader
    with pytest.raises(ValueError, match=r"b\.yaml: " + expected):
        build_sensors(scene, build_robot(scene, seed=0), seed=0, dt=0.1)
