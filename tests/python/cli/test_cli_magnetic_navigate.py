# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""``kiseki magnetic teach`` and ``kiseki magnetic navigate`` on the first 16 m of the magnetic
path: the taught folder's maps and runs, the navigation's CSV against its own run log (the
cross-track error of a route along x is the true y), and bad input in one line, exit 1."""

from __future__ import annotations

import csv
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from kiseki.errors import KisekiError
from kiseki.magnetic import load_linear_map, path_identity

SHORT = [[0.0, 0.0], [16.0, 0.0]]


def run(*args) -> subprocess.CompletedProcess:
    """The installed CLI in a process of its own: exit status and stderr as a user sees them."""
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", "magnetic", *map(str, args)],
        capture_output=True,
        text=True,
    )


def invoke(*args):
    """The same command in this process (no interpreter start-up): (exit code, output,
    exception)."""
    from typer.testing import CliRunner

    from kiseki.cli import app

    done = CliRunner().invoke(app, ["magnetic", *map(str, args)])
    return done.exit_code, done.output, done.exception


@pytest.fixture(scope="module")
def taught(tmp_path_factory, project_data):
    folder = tmp_path_factory.mktemp("nav")
    text = (project_data / "worlds" / "magnetic_path.yaml").read_text(encoding="utf-8")
    scene = folder / "short.yaml"
    scene.write_text(text.replace("[[0.0, 0.0], [118.0, 0.0]]", str(SHORT)), encoding="utf-8")
    code, output, error = invoke("teach", scene, "-o", folder / "taught", "--seed", 3)
    assert code == 0, (output, error)
    return scene, folder / "taught"


def test_teach_writes_the_three_maps_and_runs(taught):
    scene, folder = taught
    path_id = path_identity(SHORT)
    maps = {side: load_linear_map(folder / side, path_id) for side in ("", "left", "right")}
    assert len(maps[""]) == 161  # 0.0 .. 16.0 m every 0.1 m
    # the parallel paths were driven 1 m to the left and right of the route
    for side, y in (("", 0.0), ("left", 1.0), ("right", -1.0)):
        np.testing.assert_allclose(maps[side].position[:, 1], y, atol=0.02)
    assert sorted(p.name for p in (folder / "runs").iterdir()) == [
        "teach_center.mcap",
        "teach_left.mcap",
        "teach_right.mcap",
    ]


def test_navigate_writes_a_run_csv_and_plot(taught, tmp_path):
    from kiseki.io.runlog import read_run

    scene, folder = taught
    out = tmp_path / "nav"
    code, output, error = invoke(
        "navigate", scene, "--map", folder, "--navigator", "multi", "-o", out
    )
    assert code == 0, (output, error)
    assert "multi reached the goal" in output
    with open(out / "navigation.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    times, poses = read_run(out / "run.mcap").poses("/ground_truth")
    truth = {round(t, 6): p for t, p in zip(times, poses, strict=True)}
    assert len(rows) >= 16.0 / 0.6 / 0.1 * 0.9
    for row in rows:
        x, y, _ = truth[round(float(row["t"]), 6)]
        assert float(row["x"]) == pytest.approx(x, abs=1e-6)
        assert float(row["cross_track"]) == pytest.approx(y, abs=1e-6)  # the route is y = 0
        assert float(row["along_track"]) == pytest.approx(min(max(x, 0.0), 16.0), abs=1e-6)
    drove = {row["drove"] for row in rows}
    assert drove <= {"magnetic-geometric", "magnetic", "geometric", "odometry", ""}
    assert (out / "navigation.png").stat().st_size > 10_000


def test_navigate_refuses_to_replace_its_outputs_unless_told_to_overwrite(taught, tmp_path):
    """navigate replaced an existing navigation.csv, navigation.png and run.mcap without a
    word; now only with --overwrite, and the refusal comes before the run."""
    from kiseki.io.runlog import read_run

    scene, folder = taught
    out = tmp_path / "F"
    out.mkdir()
    (out / "navigation.csv").write_text("my table\n", encoding="utf-8")
    (out / "notes.txt").write_text("my notes\n", encoding="utf-8")
    done = run("navigate", scene, "--map", folder, "-o", out)
    assert done.returncode == 1
    assert done.stderr.splitlines() == [
        f"kiseki: error: -o {out} holds navigation.csv, which this command would replace: give "
        "--overwrite, or another folder"
    ]
    assert sorted(p.name for p in out.iterdir()) == ["navigation.csv", "notes.txt"]
    assert (out / "navigation.csv").read_text(encoding="utf-8") == "my table\n"
    (out / "run.mcap").write_bytes(b"my run")
    assert refused("navigate", scene, "--map", folder, "-o", out) == (
        f"-o {out} holds run.mcap (and 1 more), which this command would replace: give "
        "--overwrite, or another folder"
    )
    assert (out / "run.mcap").read_bytes() == b"my run"
    code, output, error = invoke("navigate", scene, "--map", folder, "-o", out, "--overwrite")
    assert code == 0, (output, error)
    header = (out / "navigation.csv").read_text(encoding="utf-8").splitlines()[0]
    assert header.startswith("t,x,y,theta,")
    assert len(read_run(out / "run.mcap").poses("/ground_truth")[0]) > 100
    assert (out / "navigation.png").stat().st_size > 10_000
    assert (out / "notes.txt").read_text(encoding="utf-8") == "my notes\n"  # not an output


def test_navigate_refuses_another_path_in_one_line(taught, tmp_path, project_data):
    _, folder = taught
    other = run("navigate", project_data / "worlds" / "magnetic_path.yaml", "--map", folder,
                "-o", tmp_path / "o")  # fmt: skip
    assert other.returncode == 1
    assert "not of this path" in other.stderr and len(other.stderr.splitlines()) == 1


def refused(*args) -> str:
    code, output, error = invoke(*args)
    assert code == 1 and isinstance(error, ValueError | OSError | KisekiError), (
        code,
        output,
        error,
    )
    return str(error)


def test_bad_input_is_refused(taught, tmp_path):
    scene, folder = taught
    assert "--navigator must be one of" in refused(
        "navigate", scene, "--map", folder, "--navigator", "lidar", "-o", tmp_path / "o"
    )
    empty = tmp_path / "empty"
    empty.mkdir()
    assert "empty" in refused("navigate", scene, "--map", empty, "-o", tmp_path / "o")
    afile = tmp_path / "a.txt"
    afile.write_text("x", encoding="utf-8")
    # a folder holding a.txt is not a map folder: refused before any run
    assert "not a linear magnetic map" in refused("teach", scene, "-o", tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "empty"]
    assert "not a folder" in refused("teach", scene, "-o", afile)
    assert "--seed must be an integer" in refused(
        "teach", scene, "-o", tmp_path / "t", "--seed", -1
    )
    copy = tmp_path / "center_only"
    shutil.copytree(folder, copy, ignore=shutil.ignore_patterns("left", "runs"))
    line = refused("navigate", scene, "--map", copy, "--navigator", "rahok", "-o", tmp_path / "o")
    assert line.endswith(  # it named no folder, and came after the run's start
        f"--map {copy}: Rahok's method needs the maps of the left and right parallel paths "
        "(left/ and right/ in a folder of kiseki magnetic teach)"
    )
    assert not (tmp_path / "o").exists()  # refused before the run


def test_teach_refuses_a_route_it_cannot_map_and_a_robot_without_a_magnetometer(taught, tmp_path):
    """A teaching run that hit a wall wrote the map of the part it drove (exit 0, "114 nodes
    over 11.3 m" of a 19 m route); a 0.05 m route wrote one node that navigate then failed on (now
    refused by its length, before the three teaching runs);
    a robot without a magnetometer named a deleted temporary run (teach) or drove past the goal
    with no reading (navigate, exit 0)."""
    scene, folder = taught
    text = scene.read_text(encoding="utf-8")
    turn = tmp_path / "turn.yaml"  # the route turns into the corridor's wall
    turn.write_text(text.replace(str(SHORT), "[[0.0, 0.0], [7.0, 0.0], [7.0, 5.0], [0.0, 5.0]]"))
    message = refused("teach", turn, "-o", tmp_path / "t1")
    assert message.startswith(f"{turn}: the teaching run along the route did not reach its end")
    assert "hit " in message and message.endswith(": no map")
    short = tmp_path / "short.yaml"
    short.write_text(text.replace(str(SHORT), "[[0.0, 0.0], [0.05, 0.0]]"))
    assert refused("teach", short, "-o", tmp_path / "t2") == (
        f"{short}: the route is 0.05 m long, shorter than the linear map's node spacing "
        "(0.1 m): too short to navigate"
    )
    blind = tmp_path / "blind.yaml"
    lines = text.splitlines(keepends=True)
    blind.write_text("".join(line for line in lines if "type: magnetometer" not in line))
    assert len(blind.read_text().splitlines()) == len(lines) - 1
    want = f"{blind}: the robot has no sensor of type magnetometer"
    assert refused("teach", blind, "-o", tmp_path / "t3") == want
    assert refused("navigate", blind, "--map", folder, "-o", tmp_path / "n3") == want
    assert not any((tmp_path / name).exists() for name in ("t1", "t2", "t3", "n3"))


def test_gp_map_folder_is_refused(taught, tmp_path):
    scene, _ = taught
    gp = tmp_path / "gp"
    gp.mkdir()
    (gp / "magnetic_map.yaml").write_text("kind: magnetic_field_map\n", encoding="utf-8")
    assert "GP magnetic map" in refused("navigate", scene, "--map", gp, "-o", tmp_path / "o")
    assert Path(tmp_path / "o").exists() is False


def test_sensor_gates_keep_the_magnetic_navigators_valid_where_the_thesis_gate_drops_them(
    taught, tmp_path
):
    """The same playback (seed 1) with the thesis' 0.002 G gate and with the gate from the
    sensor's noise (0.01 G per reading in the scene): on the thesis' gate the magnetic
    navigators drive few steps (noise alone fails it), on kiseki's most of them."""
    scene, folder = taught
    shares = {}
    for gates in ("thesis", "sensor"):
        out = tmp_path / gates
        code, output, error = invoke(
            "navigate", scene, "--map", folder, "-o", out, "--gates", gates
        )
        assert code == 0, (output, error)
        with open(out / "navigation.csv", encoding="utf-8") as f:
            drove = [row["drove"] for row in csv.DictReader(f)]
        shares[gates] = np.mean([d.startswith("magnetic") for d in drove if d])
    # measured: 0.08 and 0.62 of the steps that a navigator drove
    assert shares["thesis"] < 0.2 < 0.5 < shares["sensor"]
    assert "--gates must be one of" in refused(
        "navigate", scene, "--map", folder, "-o", tmp_path / "o", "--gates", "loose"
    )
