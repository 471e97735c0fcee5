# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Files a command writes beside its -o FILE (localize's OUT.config.yaml, OUT.json,
OUT.cost.json; speed limits' OUT.config.yaml; a map's image) were replaced without a word. One
already there while -o FILE is not is no earlier output of the command: refused, before any
work, and kept. Beside an earlier output it is replaced with it, as before."""

from __future__ import annotations

from pathlib import Path

import pytest

from _helpers.boundaries_cli import digests, one_error, run
from _helpers.room_log import room, write_log
from kiseki import save_map

LOCALIZE = ["localize", "log.mcap", "--map", "room.yaml", "-o", "run.csv", "--particles", "200"]
SPEED = ["speed", "limits", "log.mcap", "--map", "room.yaml", "-o", "run.csv"]


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    save_map(room(), tmp_path / "room.yaml")
    write_log(tmp_path / "log.mcap")
    return tmp_path


@pytest.mark.parametrize(
    ("args", "mine", "label"),
    [
        (LOCALIZE, "run.config.yaml", "its config"),
        ([*LOCALIZE, "--global"], "run.json", "its report"),
        (SPEED, "run.config.yaml", "the config"),
        (["map", "from-log", "log.mcap", "-o", "run.yaml"], "run.pgm", "--output's image"),
    ],
    ids=["localize-config", "localize-report", "speed-config", "map-image"],
)
def test_a_users_file_where_a_derived_output_goes_is_refused_and_kept(inputs, args, mine, label):
    (inputs / mine).write_text("the user's own\n")
    before = digests(inputs)
    output = args[args.index("-o") + 1]
    assert one_error(run(*args, cwd=inputs)) == (
        f"kiseki: error: {label} {mine} exists and --output {output} does not: it is no "
        f"earlier output of this command, and is not replaced: give another --output, or move "
        f"{mine}"
    )
    assert digests(inputs) == before


def test_beside_an_earlier_output_it_is_replaced_with_it(inputs):
    first = run(*SPEED, cwd=inputs)
    assert first.returncode == 0, first.stderr
    (inputs / "run.config.yaml").write_text("an earlier run's, edited\n")
    again = run(*SPEED, cwd=inputs)
    assert again.returncode == 0, again.stderr
    assert "edited" not in (inputs / "run.config.yaml").read_text()
