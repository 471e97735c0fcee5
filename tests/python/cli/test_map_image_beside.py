# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``map convert`` and ``map from-log`` write the map's image beside ``-o X.yaml`` as X.pgm. An
X.pgm of the user's own there was replaced without a word; it is refused now, before any work,
and an earlier map saved as X.yaml (whose image X.pgm is) is still replaced whole."""

from __future__ import annotations

from pathlib import Path

import pytest

from _helpers.boundaries_cli import digests, one_error, run
from _helpers.room_log import room, write_log
from kiseki import save_map
from kiseki.io.ros_map import load_map

COMMANDS = [
    ["map", "convert", "room.yaml", "-o", "out.yaml"],
    ["map", "from-log", "log.mcap", "-o", "out.yaml"],
]


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    save_map(room(), tmp_path / "room.yaml")
    write_log(tmp_path / "log.mcap")
    return tmp_path


@pytest.mark.parametrize("args", COMMANDS, ids=["convert", "from-log"])
@pytest.mark.parametrize("yaml_text", ["a note of the user's\n", "image: other.pgm\n"])
def test_a_user_image_under_the_maps_image_name_is_refused_and_kept(inputs, args, yaml_text):
    """Beside a YAML that is no map, or a map naming another image (no YAML at all: the guard's
    rule for every derived output, tests/python/cli/test_derived_outputs.py)."""
    (inputs / "out.pgm").write_bytes(b"the user's own picture")
    (inputs / "out.yaml").write_text(yaml_text)
    before = digests(inputs)
    line = one_error(run(*args, cwd=inputs))
    assert line == (
        "kiseki: error: --output's image out.pgm exists and is not the image of the map "
        "out.yaml: give another --output name, or move out.pgm"
    )
    assert digests(inputs) == before


@pytest.mark.parametrize("args", COMMANDS, ids=["convert", "from-log"])
def test_an_earlier_map_saved_there_is_replaced_whole(inputs, args):
    save_map(room(), inputs / "out.yaml")  # out.yaml names out.pgm
    done = run(*args, cwd=inputs)
    assert done.returncode == 0, done.stderr
    assert load_map(inputs / "out.yaml").width > 0
