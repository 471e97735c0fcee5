# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The kiseki command line, run as a user would (a real subprocess)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import yaml

import kiseki
from _helpers.pixels import largest_blob, rgb
from kiseki import OccupancyGrid, Pose2, save_map


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "kiseki.cli", *args], capture_output=True, text=True, cwd=cwd
    )


def test_version():
    done = run("--version")
    assert done.returncode == 0
    assert done.stdout.startswith(f"kiseki {kiseki.__version__} (")
    assert "octomap" in done.stdout and "pcl" in done.stdout


def test_map_info_and_render(tmp_path):
    cells = np.zeros((20, 30), dtype=np.int8)
    cells[5, 3:27] = 100  # a wall 2.4 m long, clear of the map edges (and the frame)
    cells[15:, :3] = -1
    path = save_map(OccupancyGrid(cells, 0.1, Pose2(1.0, 2.0, 0.0)), tmp_path / "m.yaml")
    done = run("map", "info", str(path))
    assert done.returncode == 0, done.stderr
    fields = dict(line.split("\t") for line in done.stdout.splitlines())  # piped: plain lines
    assert fields["width"] == "30" and fields["occupied"] == "24" and fields["unknown"] == "15"
    (tmp_path / "path.csv").write_text("t,x,y,theta\n0,1.5,3.0,0\n1,3.0,3.2,0.5\n")
    png = tmp_path / "m.png"
    done = run(
        "map", "render", str(path), "-o", str(png), "--trajectory", str(tmp_path / "path.csv")
    )
    assert done.returncode == 0, done.stderr
    # what is drawn: the wall (2.4 x 0.1 m, y 2.5-2.6) black, the unknown corner (x 1.0-1.3,
    # y 3.5-4.0) grey, both at one scale and the corner up and left of the wall's middle
    image = rgb(png)
    wall, wall_size = largest_blob(image, (0, 0, 0))
    corner, corner_size = largest_blob(image, (199, 199, 199), tol=3)
    scale = wall_size[0] / 2.4
    assert scale > 100 and wall_size[1] == pytest.approx(0.1 * scale, abs=2)
    np.testing.assert_allclose(corner_size, scale * np.array([0.3, 0.5]), atol=3)
    np.testing.assert_allclose(
        corner, wall + scale * np.array([1.15 - 2.5, -(3.75 - 2.55)]), atol=3
    )


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["map", "info", "missing.yaml"], "missing.yaml"),
        (["map", "info", "bad.yaml"], "bad.yaml"),
        (["map", "render", "good.yaml", "-o", "nodir/x.png"], "does not exist"),
        (["map", "render", "good.yaml", "-o", "x.png", "--trajectory", "bad.csv"], "bad.csv"),
        (["map", "from-log", "missing.log", "-o", "out.yaml"], "missing.log"),
        (["map", "from-log", "empty.log", "-o", "out.yaml"], "empty.log"),
        (["map", "from-log", "empty.log", "-o", "out.yaml", "--resolution", "-1"], "resolution"),
        (["map", "from-log", "empty.log", "-o", "out.yaml", "--rules", "bayes"], "--rules"),
        (["teach", "scene.yaml", "-o", "t", "--merge", "bayes"], "--merge"),
        (["demo", "--out", "d", "--merge", "bayes"], "--merge"),
        (["demo", "--out", "d", "--particles", "0"], "particles must be an integer in 1.."),
        (["demo", "--out", "d", "--particles", "2147483648"], "1..10,000,000, got 2147483648"),
        (
            ["sim", "run", "WORLDS/speed_corridor.yaml", "-o", "r.mcap", "--duration", "1e308"],
            "duration must be a finite number in (0, 86,400] s",
        ),
        (
            ["sim", "run", "WORLDS/speed_corridor.yaml", "-o", "r.mcap", "--duration", "nan"],
            "duration must be a finite number in",
        ),
        (
            [
                "sim",
                "show",
                "WORLDS/factory_turn.yaml",
                "-o",
                "r.png",
                "--octree",
                "r.bt",
                "--resolution",
                "0.001",
            ],
            "would fill about 2.05e+10 voxels",
        ),
    ],  # fmt: skip
)
def test_bad_input_prints_one_line_and_fails(tmp_path, project_root, args, needle):
    args = [a.replace("WORLDS", str(project_root / "data" / "worlds")) for a in args]
    (tmp_path / "bad.yaml").write_text(
        yaml.safe_dump({"image": "x.pgm", "resolution": -1, "origin": [0, 0, 0]})
    )
    save_map(OccupancyGrid(4, 4, 0.1), tmp_path / "good.yaml")
    (tmp_path / "bad.csv").write_text("a,b\n1,2\n")
    (tmp_path / "empty.log").write_text("")
    done = run(*args, cwd=tmp_path)
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kiseki: error: "), done.stderr
    assert needle in lines[0]
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "d").exists()  # demo: refused before anything is taught
    assert not (tmp_path / "r.mcap").exists()  # sim run: refused before the run
    assert not (tmp_path / "r.png").exists()  # sim show: refused before drawing


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["map", "render", "good.yaml", "-o", "good.pgm"], "the input MAP's image"),
        (["map", "render", "good.yaml", "-o", "link.png"], "the input MAP's image"),  # symlink
        (["map", "render", "sub/../good.yaml", "-o", "./good.yaml"], "the input MAP"),
        (["map", "convert", "good.yaml", "-o", "good.yaml"], "the input MAP"),
        (["map", "convert", "good.yaml", "-o", "other.yaml"], ""),  # writes other.pgm: allowed
        (["map", "from-log", "log.gz", "-o", "log.gz"], "the input LOG"),
        (["map", "from-log", "log.gz", "-o", "m.yaml", "--render", "m.pgm"], "same file"),
        (["map", "from-log", "log.gz", "-o", "m.yaml", "--render", "nodir/r.png"], "nodir"),
        (["sim", "run", "scene.yaml", "-o", "scene.yaml", "--overwrite"], "the input SCENE"),
        (["sim", "show", "scene.yaml", "-o", "x.png", "--octree", "scene.yaml"], "SCENE"),
        (["localize", "log.gz", "--map", "good.yaml", "-o", "good.pgm"], "--map's image"),
        (["localize", "log.gz", "--map", "good.yaml", "-o", "good.config.csv"], ""),
        (["localize", "log.gz", "--map", "m.config.yaml", "-o", "m.csv"], "its config"),
    ],
)
def test_outputs_never_overwrite_inputs(tmp_path, args, needle):
    save_map(OccupancyGrid(4, 4, 0.1), tmp_path / "good.yaml")
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.png").symlink_to(tmp_path / "good.pgm")
    (tmp_path / "log.gz").write_bytes(b"not a log")
    (tmp_path / "scene.yaml").write_text("name: x\n")
    save_map(OccupancyGrid(4, 4, 0.1), tmp_path / "m.config.yaml")  # a map named like a config
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    done = run(*args, cwd=tmp_path)
    after = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    for name, content in before.items():
        if name != "other.pgm":
            assert after[name] == content, f"{name} was changed"
    if needle:
        assert done.returncode == 1
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("kiseki: error: "), done.stderr
        assert needle in lines[0] and "Traceback" not in done.stderr
    else:  # not an input: refused for another reason (the log) or written
        assert "would overwrite" not in done.stderr


@pytest.mark.parametrize("seed", ["-1", str(2**64)])
@pytest.mark.parametrize(
    "command",
    [
        ["sim", "run", "scene.yaml", "-o", "r.mcap"],
        ["teach", "scene.yaml", "-o", "t"],
        ["demo", "--out", "d"],
        ["playback", "scene.yaml", "--route", "P0,G", "--taught", "t"],
        ["localize", "log.gz", "--map", "good.yaml", "-o", "o.csv"],
        ["coop", "simulate"],
    ],
)
def test_bad_seeds_are_one_line_before_any_work(tmp_path, command, seed):
    done = run(*command, "--seed", seed, cwd=tmp_path)
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert lines == [f"kiseki: error: --seed must be an integer in [0, 2**64), got {seed}"]
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_unknown_command_fails():
    done = run("teleport")
    assert done.returncode != 0 and "teleport" in done.stderr


def test_check_seed_takes_exactly_the_unsigned_64_bit_integers():
    from kiseki.core import check_seed
    from kiseki.sim.run import SimConfig

    assert check_seed(0) == 0 and check_seed(2**64 - 1) == 2**64 - 1
    assert check_seed(np.uint64(7)) == 7
    for bad in (-1, 2**64, 1.0, True, "3", None):
        with pytest.raises(ValueError, match="seed must be an integer"):
            check_seed(bad)
    with pytest.raises(ValueError, match="seed must be an integer"):
        SimConfig(seed=-1)


def test_experiment_list_is_plain_lines_when_piped_json_with_json_and_a_table_on_a_terminal():
    import json
    import os
    import pty

    from kiseki_experiments.harness.registry import all_experiments

    names = sorted(all_experiments())
    done = run("experiment", "list")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    header = ["name", "paper", "table/figure", "description", "default trials"]
    assert lines[0].split("\t") == header
    rows = [line.split("\t") for line in lines[1:]]
    assert [r[0] for r in rows] == names and all(len(r) == 5 for r in rows)  # no wrapping
    assert "┃" not in done.stdout
    done = run("experiment", "list", "--json")
    assert done.returncode == 0, done.stderr
    items = json.loads(done.stdout)
    assert [i["name"] for i in items] == names
    assert items[0]["default_runs"] == all_experiments()[names[0]].default_runs
    main, child = pty.openpty()  # a terminal: the rich table
    with subprocess.Popen(
        [sys.executable, "-m", "kiseki.cli", "experiment", "list"], stdout=child, stderr=child
    ) as proc:
        os.close(child)
        out = b""
        while True:
            try:
                chunk = os.read(main, 65536)
            except OSError:
                break
            if not chunk:
                break
            out += chunk
        assert proc.wait() == 0
    os.close(main)
    assert "┃" in out.decode("utf-8") and "\t" not in out.decode("utf-8")
