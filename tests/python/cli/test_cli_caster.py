# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki localize --caster``: the beam model's two ray casters are exact, so they weigh every
particle alike and give the same trajectory byte for byte; the option is refused, in one line,
where no beam model casts rays."""

from __future__ import annotations

import pytest
import yaml

from _helpers.cli_main import kiseki
from _helpers.room_log import write_inputs
from kiseki.grid import RAY_CASTERS

FIRST = next(iter(RAY_CASTERS))


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    return write_inputs(tmp_path_factory.mktemp("room"))


def test_both_casters_give_the_same_trajectory(inputs, tmp_path, monkeypatch, capsys):
    assert len(RAY_CASTERS) == 2
    outputs = []
    for caster in RAY_CASTERS:
        out = tmp_path / f"{caster}.csv"
        status, _, err = kiseki(
            monkeypatch, capsys, "localize", inputs / "log.mcap", "--map", inputs / "room.yaml",
            "--method", "beam", "--caster", caster, "--particles", "300", "--seed", "3",
            "--odometry-noise", "0.1", "-o", out,
        )  # fmt: skip
        assert status == 0, err
        saved = yaml.safe_load(out.with_name(out.stem + ".config.yaml").read_text())
        assert saved["caster"] == caster  # the choice is saved with the run
        outputs.append(out.read_bytes())
    assert outputs[0] == outputs[1]


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        (["--method", "likelihood-field", "--caster", FIRST], "--caster does not apply"),
        (["--method", "beam", "--caster", FIRST, "--global"], "--caster does not apply"),
        (["--method", "beam", "--caster", "lidar"], "caster must be one of"),
    ],
)
def test_caster_is_refused_where_it_means_nothing(
    inputs, tmp_path, monkeypatch, capsys, extra, needle
):
    status, _, err = kiseki(
        monkeypatch, capsys, "localize", inputs / "log.mcap", "--map", inputs / "room.yaml",
        "-o", tmp_path / "t.csv", *extra,
    )  # fmt: skip
    assert status != 0 and needle in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "t.csv").exists()
