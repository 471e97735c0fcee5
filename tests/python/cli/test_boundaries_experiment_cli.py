# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 17's nonsense experiment settings, run from the command line as a user would and in
this process: settings that make fig-3-14's claims meaningless, a hand-edited or out-of-range
run config read by --resume, and --runs and --seed outside the configs' limits. Each is one
line naming the file and the key, and leaves the run's folder as it was."""

from __future__ import annotations

import pytest

from _helpers.boundaries_cli import digests, one_error, run


def test_fig_3_14_refuses_settings_that_make_its_claims_meaningless(tmp_path):
    from kiseki_experiments.harness.config import ConfigError, apply_overrides
    from kiseki_experiments.teach.fig_3_14 import Fig314Config

    for setting, needle in (
        ("beams=0", "--set: beams: must be greater than 0, got 0"),  # the model's own limit
        ("beams=1", "beams must be >= 2, got 1"),
        ("offsets=1", "offsets must be >= 3"),
        ("max_offset=nan", "--set: max_offset: must be a finite number, got nan"),
        ("max_offset=1_0", "--set: max_offset: must be a valid number, got '1_0'"),  # was 10
        ("flat_ratio=2", "flat_ratio must be in (0, 1]"),
    ):
        with pytest.raises(ConfigError) as err:
            apply_overrides(Fig314Config(), [setting])
        assert needle in str(err.value)
    assert apply_overrides(Fig314Config(), ["beams=2"]).beams == 2  # the least that works
    line = one_error(run("experiment", "run", "fig-3-14", "--set", "beams=1", "--runs", "1",
                         "--out", "e", cwd=tmp_path))  # fmt: skip
    assert line == "kiseki: error: fig-3-14: beams must be >= 2, got 1"
    assert not (tmp_path / "e").exists()


def test_a_hand_edited_run_config_is_refused_naming_the_file_and_the_key(tmp_path):
    """--resume reads the run's config.yaml: random bytes gave a codec error without the file,
    a list or a missing 'config' a traceback, a bad key or value no file name."""
    import re
    import shutil

    from kiseki.errors import KisekiError
    from kiseki_experiments.harness.runner import run_experiment

    run_experiment("fig-3-14", runs=1, out=tmp_path / "run", progress=False)
    text = (tmp_path / "run" / "config.yaml").read_text()
    edits = {
        "bytes": (bytes(range(128, 256)), "not a run's config (not UTF-8 text)"),
        "list": (b"[1, 2]\n", "not a run's config (a mapping), got list"),
        "no-config": (re.sub(r"config:\n(  .*\n)+", "", text).encode(),
                      "config.yaml: config: missing"),
        "key": (text.replace("  beams: 60\n", "  beams: 60\n  bogus: 3\n").encode(),
                "config.yaml: config.bogus: unknown key"),
        "value": (text.replace("  beams: 60\n", "  beams: 1\n").encode(),
                  "fig-3-14: beams must be >= 2, got 1"),
    }  # fmt: skip
    for name, (content, needle) in edits.items():
        folder = tmp_path / name
        shutil.copytree(tmp_path / "run", folder)
        (folder / "config.yaml").write_bytes(content)
        before = digests(folder)
        with pytest.raises(KisekiError) as err:
            run_experiment("fig-3-14", out=folder, resume=True, progress=False)
        assert str(err.value).startswith(str(folder)) and "config.yaml: " in str(err.value)
        assert needle in str(err.value), (name, str(err.value))
        assert digests(folder) == before
    line = one_error(run("experiment", "run", "fig-3-14", "--out", "list", "--resume",
                         cwd=tmp_path))  # fmt: skip
    assert line == "kiseki: error: list/config.yaml: not a run's config (a mapping), got list"


@pytest.mark.parametrize(
    ("edit", "problem"),
    [
        ({"runs": -1}, "runs: must be greater than 0, got -1"),
        ({"runs": 10**12}, "runs: must be less than or equal to 100000, got 1000000000000"),
        ({"runs": 1e12}, "runs: must be a valid integer, got 1000000000000.0"),
        ({"runs": True}, "runs: must be a valid integer, got True"),
        ({"seed": 2**64}, f"seed: must be an integer in [0, 2**64), got {2**64}"),
        ({"seed": None}, "seed: missing"),
        ({"experiment": None}, "experiment: missing"),
        ({"config": [1]}, "config: must be a mapping, got [1]"),
        ({"extra": 1}, "extra: unknown key"),
    ],
)
def test_a_resumed_runs_config_yaml_is_checked_by_its_model(tmp_path, edit, problem):
    """--resume reads runs and seed from the run's config.yaml with the limits of --runs and
    --seed: one line naming the file and the field (runs and seed were unbounded before)."""
    import yaml

    from kiseki_experiments.harness.config import ConfigError
    from kiseki_experiments.harness.runner import run_experiment

    saved = {"experiment": "fig-3-14", "runs": 1, "seed": 0, "config": {}}
    saved = {k: v for k, v in {**saved, **edit}.items() if v is not None}
    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "config.yaml").write_text(yaml.safe_dump(saved))
    before = digests(folder)
    with pytest.raises(ConfigError) as err:
        run_experiment("fig-3-14", out=folder, resume=True, progress=False)
    text = str(err.value)
    assert text.startswith(f"{folder / 'config.yaml'}: {problem}") and "\n" not in text, text
    assert digests(folder) == before
    if edit == {"runs": -1}:  # the command line: the same line, exit status 1
        line = one_error(run("experiment", "run", "fig-3-14", "--out", "run", "--resume",
                             cwd=tmp_path))  # fmt: skip
        assert line == f"kiseki: error: run/config.yaml: {problem}"


def test_the_command_lines_runs_and_seed_have_the_configs_limits(tmp_path):
    from kiseki_experiments.harness.config import ConfigError
    from kiseki_experiments.harness.runner import run_experiment

    for runs, seed, message in (
        (0, 0, "--runs: must be greater than 0, got 0"),
        (10**12, 0, "--runs: must be less than or equal to 100000, got 1000000000000"),
        (1, -1, "--seed must be an integer in [0, 2**64), got -1"),  # as every --seed
        (1, 2**64, f"--seed must be an integer in [0, 2**64), got {2**64}"),
    ):
        with pytest.raises(ConfigError) as err:
            run_experiment("fig-3-14", runs, seed, out=tmp_path / "r", progress=False)
        assert str(err.value) == message
        assert not (tmp_path / "r").exists()
