# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 17's remaining cases, run from the command line as a user would: a log without the
scan topic, a truncated log, options that do not apply, outputs without an extension, a map
that is not the log's building, nonsense experiment settings and cell values outside the ROS
range. Each is one line (an error and exit 1, or a warning) and leaves every input as it was.
The experiments' settings and run configs are in test_boundaries_experiment_cli.py."""

from __future__ import annotations

import gzip
import itertools
import json
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

from _helpers.boundaries_cli import digests, one_error, run
from _helpers.room_log import ANGLES, room, write_log
from kiseki import OccupancyGrid, Pose2, save_map
from kiseki._support.outputs import FIGURE_SUFFIXES


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    save_map(room(), tmp_path / "room.yaml")
    write_log(tmp_path / "log.mcap")
    write_log(tmp_path / "noscan.mcap", scan=False)
    return tmp_path


@pytest.mark.parametrize(
    "args",
    [
        ["map", "from-log", "noscan.mcap", "-o", "m.yaml"],
        ["localize", "noscan.mcap", "--map", "room.yaml", "-o", "t.csv"],
        ["localize", "noscan.mcap", "--map", "room.yaml", "-o", "t.csv", "--global"],
        ["speed", "limits", "noscan.mcap", "--map", "room.yaml", "-o", "t.csv"],
    ],
)
def test_a_run_without_a_scan_topic_is_one_line_naming_the_file(inputs, args):
    before = digests(inputs)
    line = one_error(run(*args, cwd=inputs))
    assert line.startswith("kiseki: error: noscan.mcap: no topic '/scan' (topics: ")
    assert "/ground_truth, /odom" in line
    assert digests(inputs) == before  # nothing written, nothing changed


@pytest.mark.parametrize(
    "args",
    [
        ["map", "from-log", "cut.mcap", "-o", "m.yaml"],
        ["localize", "cut.mcap", "--map", "room.yaml", "-o", "t.csv"],
        ["sim", "render", "cut.mcap", "--scene", "WORLD", "-o", "a.gif"],
    ],
)
def test_a_truncated_run_is_read_with_a_one_line_warning(inputs, project_root, args):
    world = project_root / "data" / "worlds" / "factory_corridor.yaml"
    args = [str(world) if a == "WORLD" else a for a in args]
    write_log(inputs / "full.mcap", chunk_size=2048)
    data = (inputs / "full.mcap").read_bytes()
    (inputs / "cut.mcap").write_bytes(data[: len(data) * 2 // 3])
    before = digests(inputs)
    done = run(*args, cwd=inputs)
    assert done.returncode == 0, done.stderr
    warning = [line for line in done.stderr.splitlines() if line.startswith("kiseki: warning:")]
    assert len(warning) == 1 and "cut.mcap: truncated MCAP" in warning[0], done.stderr
    assert "TruncatedRunWarning" not in done.stderr  # not Python's two-line format
    after = digests(inputs)
    assert {k: after[k] for k in before} == before


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--tracking-particles", "500"], "--tracking-particles applies only with --global"),
        (["--plot", "p.png"], "--plot applies only with --global"),
        (["--one-scan"], "--one-scan applies only with --global"),
    ],
)
def test_options_of_global_localization_are_errors_without_it(inputs, args, needle):
    before = digests(inputs)
    line = one_error(run("localize", "log.mcap", "--map", "room.yaml", "-o", "t.csv", *args,
                         cwd=inputs))  # fmt: skip
    assert line == f"kiseki: error: {needle}"
    assert digests(inputs) == before


@pytest.mark.parametrize("target", ["log.mcap", "room.yaml", "room.pgm"])
def test_localize_never_writes_over_its_log_or_map(inputs, target):
    before = digests(inputs)
    line = one_error(run("localize", "log.mcap", "--map", "room.yaml", "-o", target, cwd=inputs))
    assert line.startswith(f"kiseki: error: --output {target} would overwrite the input")
    assert digests(inputs) == before


FIG = FIGURE_SUFFIXES
MAP = (".yaml", ".yml")


@pytest.mark.parametrize(
    ("args", "label", "path", "wanted"),
    [
        (["map", "render", "room.yaml", "-o", "out"], "--output", "out", FIG),
        (["map", "from-log", "log.mcap", "-o", "m.yaml", "--render", "r"], "--render", "r", FIG),
        (["map", "from-log", "log.mcap", "-o", "m"], "--output", "m", MAP),
        (["map", "convert", "room.yaml", "-o", "m"], "--output", "m", MAP),
        (["sim", "show", "WORLD", "-o", "out"], "--output", "out", FIG),
        (["sim", "render", "log.mcap", "--scene", "WORLD", "-o", "a.png"], "--output", "a.png",
         (".gif",)),
        (["localize", "log.mcap", "--map", "room.yaml", "-o", "t.csv", "--global", "--plot", "p"],
         "--plot", "p", FIG),
        (["speed", "limits", "log.mcap", "--map", "room.yaml", "-o", "s.csv", "--plot", "p"],
         "--plot", "p", FIG),
        (["coop", "simulate", "--runs", "2", "--plot", "p.foo"], "--plot", "p.foo", FIG),
    ],
)  # fmt: skip
def test_an_output_without_a_known_extension_is_refused_before_any_work(
    inputs, project_root, args, label, path, wanted
):
    """The writers choose the format by extension: the old error named a temporary file
    ('Format 'p1zzedcf' is not supported'), after the work."""
    world = project_root / "data" / "worlds" / "factory_corridor.yaml"
    before = digests(inputs)
    line = one_error(run(*[str(world) if a == "WORLD" else a for a in args], cwd=inputs))
    got = f"extension '{Path(path).suffix}'" if Path(path).suffix else "no extension"
    assert line == (
        f"kiseki: error: {label} {path}: {got}; give a file ending in {', '.join(wanted)}"
    )
    assert digests(inputs) == before  # refused before anything was written


def test_a_figure_takes_every_extension_matplotlib_writes(inputs):
    """The list is matplotlib's own (the hand-written one refused .svgz, .pgf, .raw, .rgba), read
    on first use: importing the CLI does not import matplotlib."""
    assert {".png", ".pdf", ".svgz", ".pgf", ".raw", ".rgba"} <= set(FIGURE_SUFFIXES)
    assert ".foo" not in FIGURE_SUFFIXES and ".yaml" not in FIGURE_SUFFIXES
    done = run("map", "render", "room.yaml", "-o", "room.svgz", cwd=inputs)
    assert done.returncode == 0, done.stderr
    assert gzip.decompress((inputs / "room.svgz").read_bytes()).lstrip().startswith(b"<?xml")
    probe = "import sys, kiseki.cli; print('matplotlib' in sys.modules)"
    imported = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert imported.stdout.split() == ["False"], imported.stderr


def test_a_map_that_is_not_the_logs_building_warns(inputs):
    save_map(OccupancyGrid(np.zeros((1, 1), np.int8), 0.05), inputs / "one.yaml")
    cells = np.zeros((80, 120), np.int8)
    cells[10, :] = 100  # one wall only: not the room
    save_map(OccupancyGrid(cells, 0.05, Pose2(-1.0, -2.0, 0.0)), inputs / "other.yaml")
    before = digests(inputs)
    commands = {"localize": ["localize"], "speed": ["speed", "limits"]}
    warnings = {}
    for command, name in itertools.product(commands, ("room", "one", "other")):
        done = run(*commands[command], "log.mcap", "--map", f"{name}.yaml", "-o",
                   f"{command}-{name}.csv", cwd=inputs)  # fmt: skip
        assert done.returncode == 0, done.stderr
        warnings[command, name] = [
            x for x in done.stderr.splitlines() if x.startswith("kiseki: warning")
        ]
    # the speed limits read the log's reference poses, which cannot be lost: no "lost" there
    poses = {"localize": "estimated poses", "speed": "reference poses"}
    for command in commands:
        assert warnings[command, "room"] == []
        for name in ("one", "other"):
            assert len(warnings[command, name]) == 1, warnings
            line = warnings[command, name][0]
            assert (
                f"of the scan endpoints fall on or next to an occupied cell of {name}.yaml "
                f"at the {poses[command]}: the map is probably not the log's building"
            ) in line
            assert ("localization is lost" in line) == (command == "localize")
        # the 1x1 map: every endpoint off the map
        assert "only 0.0 %" in warnings[command, "one"][0]
    after = digests(inputs)
    assert {k: after[k] for k in before} == before


def test_the_off_map_check_skips_only_what_it_cannot_measure(capsys):
    """No estimate, or no endpoint below max_range: no share, no warning. Any other error of
    endpoint_agreement (here ranges one column short) is raised: it was swallowed with them."""
    from kiseki.cli._off_map import warn_if_off_the_map

    grid, poses = room(), np.array([[0.0, -1.0, 0.0], [0.5, -1.0, 0.0]])

    def scans(ranges):
        return SimpleNamespace(ranges=np.asarray(ranges, np.float32), angles=ANGLES, max_range=8.0)

    seen = scans(grid.cast_scans(poses, ANGLES, max_range=8.0))
    warn_if_off_the_map(grid, poses, seen, Path("room.yaml"))  # on the walls: no warning
    warn_if_off_the_map(grid, np.full_like(poses, np.nan), seen, Path("room.yaml"))
    warn_if_off_the_map(grid, poses, scans(np.full((2, ANGLES.size), 8.0)), Path("room.yaml"))
    assert capsys.readouterr().err == ""
    empty = OccupancyGrid(np.zeros_like(grid.cells), grid.resolution, grid.origin)
    warn_if_off_the_map(empty, poses, seen, Path("empty.yaml"))
    assert "only 0.0 % of the scan endpoints" in capsys.readouterr().err
    with pytest.raises(ValueError, match="ranges"):
        warn_if_off_the_map(grid, poses, scans(np.ones((2, ANGLES.size - 1))), Path("room.yaml"))
    with pytest.raises(ValueError, match="poses must be 'estimated' or 'reference', got 'true'"):
        warn_if_off_the_map(grid, poses, seen, Path("room.yaml"), poses="true")


def test_an_endpoint_is_what_the_core_counts():
    """A reading stored as float32 and compared in double, as the core does: float32(0.7) is
    below a max range of 0.7 (in float32 they are equal); a scan at a NaN pose has none."""
    from kiseki.cli._off_map import has_endpoints

    at, nowhere = np.zeros((1, 3)), np.full((1, 3), np.nan)
    assert has_endpoints(at, np.array([[0.7, np.nan]], np.float32), 0.7)
    assert not has_endpoints(at, np.array([[0.7000001, 0.0, -1.0]], np.float32), 0.7)
    assert not has_endpoints(nowhere, np.array([[0.5]], np.float32), 0.7)


def test_global_localization_on_another_map_warns_and_prints_no_nan(inputs):
    cells = np.zeros((80, 120), np.int8)
    cells[10, :] = 100
    cells[:, 30] = 100
    save_map(OccupancyGrid(cells, 0.05, Pose2(-1.0, -2.0, 0.0)), inputs / "other.yaml")
    outs = {}
    for name in ("room", "other"):
        outs[name] = run("localize", "log.mcap", "--map", f"{name}.yaml", "-o", f"{name}.csv",
                         "--global", "--particles", "3000", cwd=inputs)  # fmt: skip
        assert outs[name].returncode == 0, outs[name].stderr
        assert "nan" not in (outs[name].stdout + outs[name].stderr).lower()
    assert "kiseki: warning" not in outs["room"].stderr
    assert "kiseki: warning: only" in outs["other"].stderr
    assert "other.yaml" in outs["other"].stderr


def test_map_from_log_with_a_render_in_a_missing_folder_leaves_no_map(inputs):
    before = digests(inputs)
    line = one_error(run("map", "from-log", "log.mcap", "-o", "new.yaml", "--render",
                         "/nodir/r.png", cwd=inputs))  # fmt: skip
    assert line == "kiseki: error: --render /nodir/r.png: folder /nodir does not exist"
    assert digests(inputs) == before and not (inputs / "new.yaml").exists()


def test_a_grid_refuses_cell_values_outside_the_ros_range():
    """-1 unknown, 0..100 occupancy: 120 or -2 were taken (only save_map refused them)."""
    for bad in (120, -2):
        with pytest.raises(ValueError, match=rf"values must lie in -1\.\.100.*got {bad}"):
            OccupancyGrid(np.array([[0, 100], [bad, -1]], np.int8), 0.1)
        with pytest.raises(ValueError, match="cell values must lie in -1..100"):
            OccupancyGrid(2, 2, 0.1, Pose2(), bad)
    grid = OccupancyGrid(np.array([[0, 100], [50, -1]], np.int8), 0.1)
    assert grid.cells.tolist() == [[0, 100], [50, -1]]


def test_sim_run_names_the_option_that_replaces_an_existing_output(inputs, project_root):
    world = project_root / "data" / "worlds" / "factory_corridor.yaml"
    before = digests(inputs)
    line = one_error(run("sim", "run", world, "-o", "log.mcap", cwd=inputs))
    assert line == "kiseki: error: --output log.mcap exists: give --overwrite to replace it"
    assert digests(inputs) == before  # the old message named a Python argument (overwrite=True)


def test_a_playback_to_a_waypoint_without_truth_reports_its_stop():
    """'truth' is optional in a waypoint file: the summary printed after the whole playback
    raised KeyError: 'truth' (a traceback after the work)."""
    from types import SimpleNamespace

    from kiseki.cli.playback import _stop_summary

    result = SimpleNamespace(
        steps=120, stop_true=(7.43, 0.04, 0.0), stop_estimate=(7.38, 0.0, 0.0), reached=True,
        duration=12.0,
    )  # fmt: skip
    goal = {"name": "P1", "x": 7.4, "y": 0.0, "theta": 0.0}
    text = _stop_summary("proposal2", result, goal)
    assert "0.020 m from P1" in text and "no true pose recorded for where P1 was taught" in text
    goal["truth"] = [7.4, 0.0, 0.0]
    text = _stop_summary("proposal2", result, goal)
    assert f"{np.hypot(0.03, 0.04):.3f} m from where P1 was taught" in text  # 0.050


@pytest.mark.parametrize("keep", [0.5, 0.99])
def test_a_truncated_pgm_is_one_line_naming_the_map_and_its_image(inputs, keep):
    """OpenCV printed its own "imread_(...): can't read data" line before kiseki's error."""
    image = (inputs / "room.pgm").read_bytes()
    (inputs / "cut.pgm").write_bytes(image[: int(len(image) * keep)])
    meta = (inputs / "room.yaml").read_text().replace("room.pgm", "cut.pgm")
    (inputs / "cut.yaml").write_text(meta)
    before = digests(inputs)
    line = one_error(run("map", "info", "cut.yaml", cwd=inputs))
    have = int(len(image) * keep) - (len(image) - 120 * 80)  # the header is what is not pixels
    assert line == (
        f"kiseki: error: cut.yaml: cannot decode image cut.pgm: a truncated PGM ({have} of the "
        "9600 pixel bytes of 120 x 80)"
    )
    assert digests(inputs) == before


def test_a_map_yaml_of_random_bytes_is_named_without_a_codec_message(inputs):
    (inputs / "junk.yaml").write_bytes(bytes(range(128, 256)) * 4)
    before = digests(inputs)
    line = one_error(run("map", "info", "junk.yaml", cwd=inputs))
    assert line == "kiseki: error: junk.yaml: not a map YAML file (not UTF-8 text: byte 0 is 0x80)"
    assert digests(inputs) == before  # the old line quoted "'utf-8' codec can't decode byte"


SEED = "kiseki: error: --seed must be an integer in [0, 2**64), got -1"


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["serve", "--taught", ".", "--seed", "-1"], SEED),
        (["magnetic", "fit", "mag.csv", "-o", "mm", "--seed", "-1"], SEED),
        (["sim", "run", "WORLD", "-o", "r.mcap", "--controller", "commands", "--commands",
          "nan.csv"], "kiseki: error: nan.csv:2: v: must be a finite number, got 'nan'"),
        (["sim", "run", "WORLD", "-o", "r.mcap", "--controller", "commands", "--commands",
          "back.csv"],
         "kiseki: error: back.csv:3: t: must not decrease (the row before is at 1 s), got 0"),
        (["map", "render", "room.yaml", "-o", "x.png", "--trajectory", "nan.csv"],
         "kiseki: error: nan.csv:2: x: must be a finite number, got 'nan'"),
        (["map", "info", "self.yaml"], "kiseki: error: self.yaml: self.yaml: cannot decode image"),
        (["localize", "log.mcap", "--map", "room.yaml", "-o", "t.csv", "--beams", "-3"],
         "kiseki: error: --beams must be an integer in 0..100,000 (0 = every beam), got -3"),
    ],
)  # fmt: skip
def test_more_bad_inputs_are_one_line_and_change_nothing(inputs, project_root, args, expected):
    (inputs / "mag.csv").write_text("x,y,mx,my,mz\n0,0,1,2,3\n1,0,1,2,3\n0,1,1,2,3\n")
    (inputs / "nan.csv").write_text("t,v,w\n0,nan,0\n1,0,0\n" if "sim" in args else "x,y\nnan,1\n")
    (inputs / "back.csv").write_text("t,v,w\n1,0.2,0\n0,0,0\n")
    (inputs / "self.yaml").write_text("image: self.yaml\nresolution: 0.05\norigin: [0, 0, 0]\n")
    world = project_root / "data" / "worlds" / "factory_corridor.yaml"
    before = digests(inputs)
    assert one_error(run(*[str(world) if a == "WORLD" else a for a in args], cwd=inputs)) == (
        expected
    )
    assert digests(inputs) == before


def test_global_localization_from_one_scan_is_run_and_saved_as_such(inputs):
    done = run("localize", "log.mcap", "--map", "room.yaml", "-o", "one.csv", "--global",
               "--one-scan", "--particles", "300", "--json", cwd=inputs)  # fmt: skip
    assert done.returncode == 0, done.stderr
    saved = yaml.safe_load((inputs / "one.config.yaml").read_text())
    assert saved["start"] == "one-scan" and saved["particles"] == 300
    report = json.loads(done.stdout)["convergence"]
    # the saved start ran: the cloud converged where the scans fit the map, better than 1 m off
    assert report["converged"]
    assert report["fit"]["within_1_cell"] > 2 * report["fit_shifted_1m"]["within_1_cell"]


@pytest.mark.parametrize(
    ("x", "needle"), [(1e11, "the poses reach 1e+11 m, beyond +-1e+09"), (3e8, "cells")]
)
def test_a_map_from_a_log_with_far_poses_names_the_log(tmp_path, x, needle):
    """A CARMEN pose of 1e11 m said "resolution 0.05 m makes a map of 2000000000545 x 606
    cells" naming no file; poses past +-1e9 m made a map that the output's YAML then refused,
    naming the output."""
    line = "FLASER 3 1.0 1.5 2.0 {x} 0.0 0.0 {odom} 0.0 0.0 {t} host {t}"  # odometry smooth
    rows = [(0.0, 0.0, 1.0), (0.5, 0.5, 1.1), (x, 1.0, 1.2)]
    log = tmp_path / "far.log"
    log.write_text("\n".join(line.format(x=a, odom=b, t=t) for a, b, t in rows) + "\n")
    message = one_error(run("map", "from-log", "far.log", "-o", "m.yaml", cwd=tmp_path))
    assert message.startswith("kiseki: error: far.log: ") and needle in message, message
    assert not (tmp_path / "m.yaml").exists()
