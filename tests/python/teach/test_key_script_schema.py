# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The key script's model (kiseki.teach.key_script_schema): a script reads to the (time, key)
events written in it, and its length is limited, with the limit in the message naming the file
and the line."""

from __future__ import annotations

import pytest

from kiseki.teach.key_script_schema import MAX_KEYS, MAX_SCRIPT_SECONDS, read_key_script


def test_a_script_reads_to_its_events(tmp_path):
    path = tmp_path / "keys.txt"
    path.write_text(
        "# time keys\n0.0 w W up # three presses\n\n5e0 m SPACE\n5.0 a\n1e1 Left q\n"
    )  # YAML-like numbers, upper case, comments and blank lines
    assert read_key_script(path) == [
        (0.0, "w"), (0.0, "w"), (0.0, "up"), (5.0, "m"), (5.0, "space"), (5.0, "a"),
        (10.0, "left"), (10.0, "q"),
    ]  # fmt: skip


def test_the_limits_themselves_are_accepted(tmp_path):
    path = tmp_path / "keys.txt"
    path.write_text("0 " + "w " * (MAX_KEYS - 1) + f"\n{MAX_SCRIPT_SECONDS} q\n")
    events = read_key_script(path)
    assert len(events) == MAX_KEYS and events[-1] == (MAX_SCRIPT_SECONDS, "q")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("0 " + "w " * MAX_KEYS + "q\n", f":1: keys: list should have at most {MAX_KEYS} items"),
        ("0 " + "w " * (MAX_KEYS // 2) + "\n1 " + "a " * (MAX_KEYS // 2) + "q\n",
         f":2: a key script holds at most {MAX_KEYS:,} keys"),
        (f"0 w\n{MAX_SCRIPT_SECONDS + 0.1} q\n",
         f":2: time: must be less than or equal to {MAX_SCRIPT_SECONDS:g}, got"),
        ("0 w\n1_0 q\n", ":2: time: must be a number of seconds"),  # read as 10 s
    ],
)  # fmt: skip
def test_limits_are_enforced_with_the_limit_in_the_message(tmp_path, text, expected):
    path = tmp_path / "keys.txt"
    path.write_text(text)
    with pytest.raises(ValueError) as err:
        read_key_script(path)
    assert str(err.value).startswith(f"{path}{expected}")
