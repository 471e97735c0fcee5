# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 17's command-line conventions: what prints a table takes --json (the same numbers as
the table, checked against values computed here independently), plain lines when piped,
every command's --help shows an example, and the exit codes (0 ok, 1 bad input, 2 usage,
3 internal error) with no traceback for a user's mistake."""

from __future__ import annotations

import json
import os
import pty
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import typer.main
from typer.testing import CliRunner

from _helpers.room_log import STEPS, room, write_log
from kiseki import OccupancyGrid, Pose2, load_map, save_map
from kiseki.cli import app, main


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
    )


def run_on_terminal(*args: str) -> str:
    """What a command prints when its stdout is a terminal."""
    main_fd, child = pty.openpty()
    with subprocess.Popen(
        [sys.executable, "-m", "kiseki.cli", *args], stdout=child, stderr=child
    ) as proc:
        os.close(child)
        out = b""
        while True:
            try:
                chunk = os.read(main_fd, 65536)
            except OSError:
                break
            if not chunk:
                break
            out += chunk
        assert proc.wait() == 0, out
    os.close(main_fd)
    return out.decode("utf-8")


def commands(group=None, path=()) -> list[tuple[tuple[str, ...], object]]:
    """Every leaf command of the app, as (its words, its click command)."""
    group = typer.main.get_command(app) if group is None else group
    ctx = typer.Context(group)  # the root loads its groups on request: asked through click's API
    found = []
    for name in sorted(group.list_commands(ctx)):
        sub = group.get_command(ctx, name)
        if hasattr(sub, "commands"):
            found += commands(sub, (*path, name))
        else:
            found.append(((*path, name), sub))
    return found


def test_every_commands_help_shows_an_example_of_that_command():
    leaves = commands()
    assert len(leaves) >= 20  # the walk reaches the nested groups (map, sim, magnetic, ...)
    runner = CliRunner()
    for words, _ in leaves:
        done = runner.invoke(app, [*words, "--help"], terminal_width=200)
        assert done.exit_code == 0, (words, done.output)
        examples = [x.strip() for x in done.output.splitlines() if "Example:" in x]
        assert examples, f"kiseki {' '.join(words)} --help shows no example"
        # the example runs this very command
        assert examples[0].split("Example:")[1].split()[: 1 + len(words)] == ["kiseki", *words]


@pytest.fixture
def grid_file(tmp_path: Path) -> Path:
    rng = np.random.default_rng(17)
    cells = rng.choice(np.array([-1, 0, 100], np.int8), size=(23, 41), p=[0.2, 0.6, 0.2])
    return save_map(OccupancyGrid(cells, 0.1, Pose2(1.0, -2.0, 0.0)), tmp_path / "m.yaml")


def test_map_info_json_and_plain_lines_hold_the_grids_own_counts(grid_file: Path):
    cells = load_map(grid_file).cells  # counted here with numpy, not with grid_summary
    expected = {
        "width": 41,
        "height": 23,
        "free": int((cells == 0).sum()),
        "occupied": int((cells == 100).sum()),
        "unknown": int((cells == -1).sum()),
        "intermediate": int(((cells > 0) & (cells < 100)).sum()),
    }
    assert sum(expected[k] for k in ("free", "occupied", "unknown", "intermediate")) == 41 * 23
    assert min(expected[k] for k in ("free", "occupied", "unknown")) > 0  # all three counted
    done = run("map", "info", grid_file, "--json")
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    assert {k: doc[k] for k in expected} == expected
    assert doc["resolution"] == pytest.approx(0.1) and doc["origin_x"] == pytest.approx(1.0)
    assert doc["size_x_m"] == pytest.approx(4.1)
    done = run("map", "info", grid_file)  # piped: a header, then one field a line
    lines = [line.split("\t") for line in done.stdout.splitlines()]
    assert lines[0] == ["field", "value"] and all(len(x) == 2 for x in lines)
    assert {k: int(v) for k, v in lines[1:] if k in expected} == expected
    assert "┃" in run_on_terminal("map", "info", str(grid_file))


def write_result(results: Path, name: str, verdicts: list[str]) -> None:
    latest = results / name / "latest"
    latest.mkdir(parents=True)
    head = "claim,paper_value,measured_value,ci_low,ci_high,unit,criterion,verdict,trials,"
    head += "trials_to_decide,control,note,holds\n"
    rows = [
        f"claim {i},1,{i},0,2,m,>= 1 (why),{v},5,,c,note,{v == 'holds'}"
        for i, v in enumerate(verdicts)
    ]
    (latest / "claims.csv").write_text(head + "\n".join(rows) + "\n")
    manifest = {"trials": 3, "trials_failed": 0, "git": {"commit": "abc"}}
    (latest / "manifest.json").write_text(json.dumps(manifest))


def test_report_json_counts_the_claims_written(tmp_path: Path):
    from kiseki_experiments.harness.registry import all_experiments

    names = sorted(all_experiments())
    write_result(tmp_path / "results", names[0], ["holds", "fails", "holds"])
    write_result(tmp_path / "results", names[-1], ["inconclusive", "fails"])
    done = run("experiment", "report", "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    assert (doc["claims"], doc["hold"], doc["fail"], doc["inconclusive"]) == (5, 2, 2, 1)
    assert doc["decided_share"] == 0.8
    assert doc["missing"] == names[1:-1] and doc["output"] == "REPRODUCTION.md"
    text = (tmp_path / "REPRODUCTION.md").read_text()
    assert "5 claims: 2 hold, 2 fail, 1 inconclusive, 0 not yet migrated" in text
    assert "decided: 80 %" in text
    done = run("experiment", "report", "-o", "R2.md", cwd=tmp_path)
    fields = dict(line.split("\t") for line in done.stdout.splitlines()[1:])
    assert (fields["claims"], fields["hold"]) == ("5", "2")
    assert fields["missing"] == ", ".join(names[1:-1])


def test_localize_json_holds_the_errors_of_its_csv(tmp_path: Path):
    save_map(room(), tmp_path / "room.yaml")
    write_log(tmp_path / "log.mcap")
    done = run("localize", "log.mcap", "--map", "room.yaml", "-o", "t.csv", "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    track = np.loadtxt(tmp_path / "t.csv", delimiter=",", skiprows=1)
    truth_x = np.linspace(0.0, 2.0, STEPS)  # the log's reference poses: y = -1, heading 0
    error = np.hypot(track[:, 1] - truth_x, track[:, 2] + 1.0)
    heading = np.degrees(np.angle(np.exp(1j * track[:, 3])))
    assert doc["poses"] == STEPS and doc["method"] == "likelihood-field"
    assert doc["position_rmse_m"] == pytest.approx(np.sqrt(np.mean(error**2)), abs=1e-5)
    assert doc["position_max_m"] == pytest.approx(error.max(), abs=1e-5)
    assert doc["heading_rmse_deg"] == pytest.approx(np.sqrt(np.mean(heading**2)), abs=1e-3)
    assert doc["position_rmse_m"] > 0  # a real error, not a default
    done = run("localize", "log.mcap", "--map", "room.yaml", "-o", "u.csv", cwd=tmp_path)
    assert done.stdout.splitlines() == [
        f"u.csv: {STEPS} poses; likelihood-field: position RMSE {doc['position_rmse_m']:.3f} m "
        f"(max {doc['position_max_m']:.3f} m), heading RMSE {doc['heading_rmse_deg']:.2f} deg"
        f"; {doc['invalid_ranges']} invalid range readings skipped"
    ]  # one line, not wrapped at 80 columns when piped
    done = run("map", "from-log", "log.mcap", "-o", "rebuilt.yaml", cwd=tmp_path)
    lines = done.stdout.splitlines()  # a sentence longer than 80 columns stays one line
    assert len(lines) == 1 and len(lines[0]) > 80 and lines[0].endswith("occupied cells")
    done = run("localize", "log.mcap", "--map", "room.yaml", "-o", "g.csv", "--global",
               "--particles", "3000", "--json", cwd=tmp_path)  # fmt: skip
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    saved = json.loads((tmp_path / "g.json").read_text())["report"]
    assert doc["convergence"] == saved and doc["report_file"] == "g.json"


@pytest.mark.parametrize(
    ("args", "code"),
    [
        (["map", "info"], 2),  # missing argument
        (["map", "info", "m.yaml", "--bogus", "x"], 2),  # unknown option
        (["localize", "log.mcap", "-o", "t.csv"], 2),  # missing --map
        (["map", "info", "m.yaml", "--json", "3"], 2),  # extra argument
        (["teleport"], 2),  # unknown command
        (["map", "info", "missing.yaml"], 1),  # bad input
        (["map", "info", "m.yaml"], 0),
    ],
)
def test_exit_codes_and_no_traceback(grid_file: Path, args, code):
    done = run(*args, cwd=grid_file.parent)
    assert done.returncode == code, done.stderr
    assert "Traceback" not in done.stderr
    if code == 1:
        assert done.stderr.strip().splitlines() == [
            "kiseki: error: missing.yaml: map YAML file not found"
        ]


def test_an_internal_error_exits_3_with_its_traceback(grid_file, monkeypatch, capsys):
    import kiseki.cli.map_info  # the module of `kiseki map info`: grid_summary imported at its top

    def broken(grid):
        raise KeyError("a bug")

    monkeypatch.setattr(kiseki.cli.map_info, "grid_summary", broken)
    monkeypatch.setattr(sys, "argv", ["kiseki", "map", "info", str(grid_file)])
    with pytest.raises(SystemExit) as exit_info:
        main()
    assert exit_info.value.code == 3
    err = capsys.readouterr().err
    assert "Traceback" in err and "KeyError: 'a bug'" in err
    assert err.strip().splitlines()[-1].startswith("kiseki: internal error: KeyError")


def test_experiment_run_prints_its_claims_as_plain_lines_when_piped(tmp_path: Path):
    import pandas as pd

    done = run("experiment", "run", "speed-fig4", "--seed", "0", "--out", "r", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = [line.split("\t") for line in done.stdout.splitlines() if "\t" in line]
    assert lines[0] == ["claim", "paper", "kiseki [95 % CI]", "unit", "verdict"]
    claims = pd.read_csv(tmp_path / "r" / "claims.csv", keep_default_na=False)
    assert [row[0] for row in lines[1:]] == list(claims["claim"])
    assert [row[4] for row in lines[1:]] == list(claims["verdict"])
    assert "│" not in done.stdout and "━" not in done.stdout
