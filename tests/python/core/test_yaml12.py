# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""kiseki._support.yaml types plain scalars as YAML 1.2's core schema does (YAML 1.2.2, sec. 10.3.2
and its example 10.9), not as PyYAML's YAML 1.1 resolver does: checked scalar by scalar against the
spec's table, and against PyYAML on the scalars where both specs agree."""

from __future__ import annotations

import math

import pytest
import yaml

from kiseki._support.yaml import safe_load_12

# (plain scalar, what YAML 1.2's core schema makes of it)
CORE_12 = [
    ("null", None), ("Null", None), ("NULL", None), ("~", None), ("", None),
    ("true", True), ("True", True), ("TRUE", True), ("false", False), ("FALSE", False),
    ("0", 0), ("-19", -19), ("+12", 12), ("0o14", 12), ("0x1F", 31), ("010", 10),
    ("1.", 1.0), ("-1.5", -1.5), (".5", 0.5), ("+12e03", 12000.0), ("-2E+05", -200000.0),
    ("5e-2", 0.05), ("1e3", 1000.0),
    # YAML 1.1 only: strings in 1.2
    ("yes", "yes"), ("No", "No"), ("on", "on"), ("OFF", "OFF"), ("y", "y"),
    ("1:30", "1:30"), ("1_000", "1_000"), ("0b101", "0b101"), ("2001-12-14", "2001-12-14"),
    ("0o19", "0o19"), ("0xG", "0xG"), ("1.2.3", "1.2.3"), ("e3", "e3"),
]  # fmt: skip


@pytest.mark.parametrize(("text", "value"), CORE_12)
def test_plain_scalars_are_typed_as_the_yaml_1_2_core_schema_says(text, value):
    got = safe_load_12(f"v: {text}\n")["v"]
    assert got == value and type(got) is type(value), (text, got)


@pytest.mark.parametrize(("text", "sign"), [(".inf", 1), ("-.Inf", -1), ("+.INF", 1)])
def test_infinities_and_nan(text, sign):
    assert safe_load_12(f"v: {text}")["v"] == sign * math.inf
    assert math.isnan(safe_load_12("v: .NaN")["v"])


@pytest.mark.parametrize("text", ["0", "-19", "3.25", "-1.5e+3", "true", "false", "null", "abc"])
def test_where_the_specs_agree_it_reads_as_pyyaml(text):
    assert safe_load_12(f"v: {text}") == yaml.safe_load(f"v: {text}")


def test_quoted_scalars_stay_strings_and_structure_is_pyyamls():
    doc = "a: '5e-2'\nb: \"010\"\nc: [1, {d: yes}]\n"
    assert safe_load_12(doc) == {"a": "5e-2", "b": "010", "c": [1, {"d": "yes"}]}


def test_a_key_given_twice_is_refused_and_a_merge_may_override():
    """PyYAML kept the last of two equal keys: a scene's floor: true then floor: false read as
    false without a word (YAML 1.2 requires unique keys)."""
    with pytest.raises(yaml.YAMLError) as caught:
        safe_load_12("floor: true\nobjects: []\nfloor: false\n")
    first = str(caught.value).splitlines()[0]
    assert first == "found the key 'floor' twice in one mapping (line 3)"
    with pytest.raises(yaml.YAMLError, match="found the key 'x' twice"):
        safe_load_12("a:\n  - {x: 1, x: 2}\n")
    with pytest.raises(yaml.YAMLError, match="found the key '0x1' twice"):  # both the integer 1
        safe_load_12("1: a\n0x1: b\n")
    merged = safe_load_12("base: &b {x: 1, y: 2}\nuse:\n  <<: *b\n  x: 3\n")
    assert merged["use"] == {"x": 3, "y": 2}  # as PyYAML's merge: the explicit key wins
    assert yaml.safe_load("floor: true\nfloor: false\n") == {"floor": False}  # PyYAML's way


def test_a_scene_or_map_with_a_key_twice_is_one_whole_line(tmp_path):
    """The readers put PyYAML's whole text in their message, and the command line showed its
    first line only: "... (line 3)" without the closing parenthesis."""
    from kiseki.io.ros_map import load_map
    from kiseki.sim.scene import load_scene

    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.05\nresolution: 0.1\n")
    with pytest.raises(ValueError) as caught:
        load_map(tmp_path / "m.yaml")
    assert str(caught.value) == (
        f"{tmp_path / 'm.yaml'}: invalid YAML (found the key 'resolution' twice in one mapping "
        "(line 3))"
    )
    (tmp_path / "s.yaml").write_text("floor: true\nfloor: false\n")
    with pytest.raises(ValueError) as caught:
        load_scene(tmp_path / "s.yaml")
    assert "\n" not in str(caught.value) and str(caught.value).endswith("(line 2))")
