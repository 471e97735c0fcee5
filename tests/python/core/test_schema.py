# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki._support.schema: the messages of the one validation layer name the file, the whole field
path and the value; numbers are strict and finite; seeds are integers in [0, 2**64)."""

from __future__ import annotations

from typing import Annotated

import pytest
from pydantic import Field

from kiseki._support.schema import FileModel, FiniteFloat, PositiveFloat, SchemaError, Seed, parse


class _Sensor(FileModel):
    name: str
    rate_hz: PositiveFloat = 10.0
    beams: Annotated[int, Field(strict=True, gt=0, le=10_000)] = 5
    seed: Seed = 0


class _Robot(FileModel):
    sensors: list[_Sensor]
    start: tuple[FiniteFloat, FiniteFloat, FiniteFloat]


def _error(doc) -> SchemaError:
    with pytest.raises(SchemaError) as info:
        parse(_Robot, doc, "scene.yaml", at=("robots", 2))
    return info.value


@pytest.mark.parametrize(
    ("sensor", "message"),
    [
        ({"name": "a", "rate_hz": -1}, "rate_hz: must be greater than 0, got -1"),
        ({"name": "a", "rate_hz": True}, "rate_hz: must be a valid number, got True"),
        ({"name": "a", "rate_hz": "1.5"}, "rate_hz: must be a valid number, got '1.5'"),
        ({"name": "a", "beams": 20_000}, "beams: must be less than or equal to 10000, got 20000"),
        ({"name": "a", "beams": 3.5}, "beams: must be a valid integer, got 3.5"),
        (
            {"name": "a", "seed": 2**64},
            "seed: must be an integer in [0, 2**64), got 18446744073709551616",
        ),
        ({"name": "a", "seed": -1}, "seed: must be an integer in [0, 2**64), got -1"),
        ({"name": "a", "bogus": 1}, "bogus: unknown key"),
        ({}, "name: missing"),
    ],
)
def test_a_bad_field_is_named_with_its_whole_path_and_value(sensor, message):
    err = _error({"sensors": [{"name": "ok"}, sensor], "start": [0, 0, 0]})
    assert str(err) == f"scene.yaml: robots[2].sensors[1].{message}"
    assert len(err.errors) == 1


def test_every_problem_is_kept_and_the_message_counts_the_rest():
    err = _error({"sensors": [{"name": "a", "rate_hz": 0}], "start": [0, float("nan"), 0]})
    assert str(err).endswith("(and 1 more)")
    assert err.errors == [
        "robots[2].sensors[0].rate_hz: must be greater than 0, got 0",
        "robots[2].start[1]: must be a finite number, got nan",
    ]
    assert isinstance(err, ValueError)


def test_a_valid_document_reads_with_yaml_lists_as_tuples_and_ints_as_floats():
    robot = parse(_Robot, {"sensors": [{"name": "a", "seed": 2**64 - 1}], "start": [1, 2, 3]}, "s")
    assert robot.start == (1.0, 2.0, 3.0) and all(isinstance(v, float) for v in robot.start)
    assert robot.sensors[0].seed == 2**64 - 1 and robot.sensors[0].rate_hz == 10.0


def test_a_list_where_a_mapping_belongs_says_mapping_not_a_python_class():
    err = _error({"sensors": [["name", "a"]], "start": [0, 0, 0]})
    assert str(err) == "scene.yaml: robots[2].sensors[0]: must be a mapping, got ['name', 'a']"


def test_an_integer_written_as_a_float_is_told_how_to_write_it():
    err = _error({"sensors": [{"name": "a", "beams": 1e3}], "start": [0, 0, 0]})
    assert str(err) == (
        "scene.yaml: robots[2].sensors[0].beams: must be a valid integer, got 1000.0 "
        "(write it as 1000, without a point or an exponent)"
    )
