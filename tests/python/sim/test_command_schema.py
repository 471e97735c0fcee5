# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The command script's model (kiseki.sim.command_schema, read by kiseki.sim.run.read_commands):
a script reads to the numbers written in it (compared with numpy's own CSV reader), and every
problem is one line naming the file, the line, the column and the value; limits with the
limit."""

from __future__ import annotations

import numpy as np
import pytest

from kiseki.sim.command_schema import MAX_COMMAND_SECONDS, MAX_COMMANDS, read_command_rows
from kiseki.sim.run import read_commands

DIFF = "t,v,w\n0,0.5,0\n\n2.5,0.3,-0.25  # turn right\n4,0,0\n"
OMNI = "t,vx,vy,w\n0,0.3,0,0\n2,0, 1e-1 ,0.5\n"


@pytest.mark.parametrize("text", [DIFF, OMNI])
def test_a_script_reads_to_what_numpy_reads(tmp_path, text):
    path = tmp_path / "cmd.csv"
    path.write_text(text)
    reference = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)  # the reader before
    np.testing.assert_array_equal(read_command_rows(path), reference)
    commands = read_commands(path)  # t, vx, vy, w
    np.testing.assert_array_equal(commands[:, [0, 1, 3]], reference[:, [0, 1, -1]])
    assert commands.shape == (len(reference), 4)
    if reference.shape[1] == 3:
        assert not commands[:, 2].any()
    else:
        np.testing.assert_array_equal(commands[:, 2], reference[:, 2])


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("t,v,w\n0,nan,0\n", ":2: v: must be a finite number, got 'nan'"),
        ("t,v,w\n0,0,0\n1,fast,0\n", ":3: v: must be a number, got 'fast'"),
        ("t,vx,vy,w\n0,0,0,inf\n", ":2: w: must be a finite number, got 'inf'"),
        ("t,v,w\n-1,0,0\n", ":2: t: must be greater than or equal to 0, got '-1'"),
        ("t,v,w\n1,0.2,0\n0,0,0\n", ":3: t: must not decrease (the row before is at 1 s), got 0"),
        ("t,v,w\n0,0.2\n", ":2: a row is t,v,w (3 values), got '0,0.2'"),
        ("t,v\n0,0.2\n", ": header must be t,v,w or t,vx,vy,w, got 't,v'"),
        (f"t,v,w\n0,0,0\n{MAX_COMMAND_SECONDS + 1},0,0\n",
         f":3: t: must be less than or equal to {MAX_COMMAND_SECONDS:g}, got '86401.0'"),
    ],
)  # fmt: skip
def test_a_wrong_value_is_named_by_line_and_column(tmp_path, text, expected):
    path = tmp_path / "cmd.csv"
    path.write_text(text)
    with pytest.raises(ValueError) as err:
        read_commands(path)
    assert str(err.value) == f"{path}{expected}"


def test_the_row_limit_is_enforced_with_the_limit_in_the_message(tmp_path, monkeypatch):
    import kiseki.sim.command_schema as schema

    assert MAX_COMMANDS == 1_000_000  # 32 MB of (t, vx, vy, w); a day at 10 Hz is 864,000
    monkeypatch.setattr(schema, "MAX_COMMANDS", 3)  # the same check, on a small file
    path = tmp_path / "cmd.csv"
    path.write_text("t,v,w\n" + "".join(f"{i},0,0\n" for i in range(3)))
    assert len(read_command_rows(path)) == 3
    path.write_text("t,v,w\n" + "".join(f"{i},0,0\n" for i in range(4)))
    with pytest.raises(ValueError) as err:
        read_command_rows(path)
    assert str(err.value) == f"{path}:5: a command script holds at most 3 rows"
