# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 27, item 1: one output guard that every command goes through (kiseki._support.guard).

Every command of the typer app, found by walking it (25 today, and any added later), carries
the guard, and each of its path parameters is declared as an input, an output or an output
folder: a new output option without a declaration fails here. Then the defects a user found,
run as a user would (``python -m kiseki.cli``), inputs compared by SHA-256 before and after:
each is one line ``kiseki: error: ...`` naming the option and the file, exit status 1, before
any work. Last, the guard's rules on their own, in this process."""

from __future__ import annotations

import hashlib
import os
import pathlib
import subprocess
import sys
import typing
from pathlib import Path

import numpy as np
import pytest

from _helpers.room_log import room, write_log

CLI = [sys.executable, "-m", "kiseki.cli"]


def run(*args, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*CLI, *map(str, args)], capture_output=True, text=True, cwd=cwd)


def sha256s(root: Path) -> dict[str, str]:
    """SHA-256 of every file below ``root`` (symlinks followed), by relative name."""
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def refused(done: subprocess.CompletedProcess, *needles: str) -> str:
    """The one error line of a refused command, holding every needle."""
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kiseki: error: "), done.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


# --- every command is guarded ---


def _commands(group=None, path=()):
    import typer.main

    from kiseki.cli import app

    group = typer.main.get_command(app) if group is None else group
    ctx = typer.Context(group)  # the root loads its groups on request: asked through click's API
    for name in sorted(group.list_commands(ctx)):
        sub = group.get_command(ctx, name)
        if hasattr(sub, "commands"):
            yield from _commands(sub, (*path, name))
        else:
            yield " ".join((*path, name)), sub


def _is_path(param) -> bool:
    """Whether a click parameter takes paths (Path, Path | None, list[Path]): typer's own
    descriptor of the annotation, or click's Path type."""
    descriptor = getattr(param, "type_descriptor", None)
    if descriptor is None:
        import click

        return isinstance(getattr(param, "type", None), click.Path)
    kinds = typing.get_args(descriptor.annotation) or (descriptor.annotation,)
    return any(isinstance(k, type) and issubclass(k, pathlib.PurePath) for k in kinds)


def test_every_command_is_guarded_and_declares_each_path_parameter():
    from kiseki._support.guard import guard_of

    problems, seen = [], 0
    for words, command in _commands():
        seen += 1
        spec = guard_of(command.callback)
        if spec is None:
            problems.append(f"kiseki {words}: no @guarded(...) (kiseki._support.guard)")
            continue
        paths = {p.name for p in command.params if _is_path(p)}
        roles = {r: spec.params(r) for r in ("inputs", "outputs", "output_folders")}
        declared = set().union(*roles.values())
        for name in sorted(paths - declared):
            problems.append(f"kiseki {words}: path parameter {name!r} is not declared")
        for name in sorted(declared - paths):
            problems.append(f"kiseki {words}: {name!r} is declared but takes no path")
        twice = [n for n in declared if sum(n in names for names in roles.values()) > 1]
        problems += [f"kiseki {words}: {n!r} has two roles" for n in twice]
    assert seen >= 25, seen  # the walk reaches every group (map, sim, magnetic, terrain, ...)
    assert not problems, "\n".join(problems)


# --- the defects, as a user meets them ---


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    from kiseki import save_map

    save_map(room(), tmp_path / "room.yaml")
    write_log(tmp_path / "log.mcap")
    return tmp_path


def test_terrain_planes_never_writes_its_csv_over_the_cloud(tmp_path):
    from kiseki import _core

    rng = np.random.default_rng(0)
    floor = np.column_stack([rng.uniform(-2, 2, (600, 2)), np.zeros(600)])
    box = rng.uniform([0.5, 0.5, 0.0], [1.0, 1.0, 0.5], (200, 3))
    _core.write_pcd(str(tmp_path / "cloud.pcd"), np.vstack([floor, box]))
    before = sha256s(tmp_path)
    done = run("terrain", "planes", "cloud.pcd", "-o", "p.png", "--csv", "cloud.pcd", cwd=tmp_path)
    refused(done, "--csv cloud.pcd would overwrite the input CLOUD cloud.pcd")
    assert sha256s(tmp_path) == before  # no picture either: refused before the work


def test_terrain_run_never_writes_over_the_octree_it_reads(tmp_path, project_root):
    from kiseki import _core
    from kiseki.sim.scene import load_scene

    scene = load_scene(project_root / "data" / "worlds" / "factory_corridor.yaml")
    (tmp_path / "OUT").mkdir()
    _core.OctreeWorld.from_boxes(scene.world, 0.2).write_binary(
        str(tmp_path / "OUT" / "global_map.bt")
    )
    before = sha256s(tmp_path)
    done = run("terrain", "run", "OUT/global_map.bt", "--moves", "1", "-o", "OUT", cwd=tmp_path)
    refused(
        done,
        "--output OUT would overwrite the input WORLD OUT/global_map.bt",
        "(the command writes global_map.bt there)",
    )
    assert sha256s(tmp_path) == before


@pytest.fixture
def bag(tmp_path: Path) -> Path:
    """A ROS 2 bag folder (sqlite3) of the room's log, with reference poses."""
    from kiseki import save_map
    from kiseki.datasets import open_scans, write_bag

    write_log(tmp_path / "log.mcap")
    scans = open_scans(tmp_path / "log.mcap")
    (tmp_path / "log.mcap").unlink()
    save_map(room(), tmp_path / "room.yaml")
    return write_bag(scans, tmp_path / "bag", "ros2-sqlite3")


LOCALIZE_BAG = ["localize", "bag", "--map", "room.yaml", "--reference-topic", "/ground_truth"]
METADATA = ("exists inside the input folder LOG bag", "would overwrite the input")


@pytest.mark.parametrize(
    ("command", "output", "needles"),
    [
        (LOCALIZE_BAG, "bag/metadata.yaml", METADATA),
        (["map", "from-log", "bag", "--reference-topic", "/ground_truth"], "bag/metadata.yaml",
         METADATA),
        (LOCALIZE_BAG, "bag/new.csv", ("is inside the input folder LOG bag",)),  # a new file
    ],
)  # fmt: skip
def test_an_output_inside_a_ros2_bag_folder_is_refused(bag, command, output, needles):
    assert (bag / "metadata.yaml").is_file()
    before = sha256s(bag.parent)
    refused(run(*command, "-o", output, cwd=bag.parent), f"--output {output} ", *needles)
    assert sha256s(bag.parent) == before


def test_an_existing_folder_as_the_output_file_is_refused_before_the_work(inputs):
    """It failed after the work, naming a temporary file: [Errno 21] Is a directory:
    '.outdir.zb7lp2zf' -> 'outdir'. As every file output of every command (speed limits' here,
    in this process)."""
    from kiseki.cli.speed import speed_limits

    (inputs / "outdir").mkdir()
    (inputs / "outdir" / "keep.txt").write_text("mine")
    before = sha256s(inputs)
    done = run("localize", "log.mcap", "--map", "room.yaml", "-o", "outdir", cwd=inputs)
    line = refused(done, "--output outdir is a folder")
    assert ".outdir." not in line
    assert sha256s(inputs) == before and sorted(os.listdir(inputs / "outdir")) == ["keep.txt"]
    with pytest.raises(IsADirectoryError, match="--plot .*outdir is a folder"):
        _spec(speed_limits).check(
            {"log": inputs / "log.mcap", "map_file": inputs / "room.yaml",
             "output": inputs / "s.csv", "plot": inputs / "outdir"}
        )  # fmt: skip


def test_a_magnetic_map_folder_takes_no_new_file_either(tmp_path):
    """predict compared its output with the map folder's files only: a new file went in."""
    (tmp_path / "d.csv").write_text("x,y,mx,my,mz\n0,0,1,2,3\n1,0,1,2,4\n0,1,1,3,3\n1,1,2,2,3\n")
    (tmp_path / "p.csv").write_text("x,y\n0.5,0.5\n")
    from typer.testing import CliRunner

    from kiseki.cli import app

    fit = ["magnetic", "fit", str(tmp_path / "d.csv"), "-o", str(tmp_path / "m")]
    done = CliRunner().invoke(app, [*fit, "--kernel", "3,1,40,0.1"])  # in this process: faster
    assert done.exit_code == 0, done.output
    before = sha256s(tmp_path)
    done = run("magnetic", "predict", "m", "--at", "p.csv", "-o", "m/field.csv", cwd=tmp_path)
    refused(done, "--output m/field.csv is inside the input folder MAP m")
    assert sha256s(tmp_path) == before


# --- the rules, in this process ---


def _spec(function):
    from kiseki._support.guard import guard_of

    spec = guard_of(function)
    assert spec is not None
    return spec


def test_an_aalto_prefix_stands_for_its_files(tmp_path):
    from kiseki._support.outputs import check_outputs

    runs = tmp_path / "runs"
    runs.mkdir()
    for part in ("loc", "mag", "time"):
        (runs / f"1-{part}.csv").write_text("0,0\n")
    with pytest.raises(ValueError, match=r"would overwrite the input DATA's run file .*1-mag\.csv"):
        check_outputs({"--output": runs / "1-mag.csv"}, {"DATA": runs / "1"})
    check_outputs({"--output": runs / "2-mag.csv"}, {"DATA": runs / "1"})  # another run: fine
    from kiseki.cli.magnetic_fit import fit

    with pytest.raises(ValueError, match="would overwrite the folder holding the input DATA"):
        _spec(fit).check({"data": [runs / "1"], "output": runs})


def test_files_an_input_names_are_inputs(tmp_path, project_root):
    """A scene's octomap, a waypoint file's maps and their images."""
    from kiseki import OccupancyGrid, save_map
    from kiseki.cli.playback import playback_command
    from kiseki.cli.sim import sim_show

    (tmp_path / "world.bt").write_bytes(b"octree")
    (tmp_path / "scene.yaml").write_text("name: s\noctomap: world.bt\n")
    with pytest.raises(ValueError, match="--octree .* would overwrite the input SCENE's octomap"):
        _spec(sim_show).check(
            {"scene_file": tmp_path / "scene.yaml", "output": tmp_path / "s.png",
             "octree": tmp_path / "world.bt"}
        )  # fmt: skip
    taught = tmp_path / "maps"
    taught.mkdir()
    save_map(OccupancyGrid(4, 4, 0.1), taught / "map_band.yaml")
    (tmp_path / "w.yaml").write_text("maps:\n  band: {file: maps/map_band.yaml}\nwaypoints: []\n")
    arguments = {"scene_file": tmp_path / "scene.yaml", "waypoints": tmp_path / "w.yaml",
                 "taught": None, "map_file": None}  # fmt: skip
    with pytest.raises(ValueError, match="the input --waypoints's map's image"):
        _spec(playback_command).check({**arguments, "log": taught / "map_band.pgm"})
    _spec(playback_command).check({**arguments, "log": tmp_path / "run.mcap"})


def test_an_input_in_an_output_folder_is_refused_only_where_the_command_writes(tmp_path):
    from kiseki.cli.terrain import terrain_run

    out = tmp_path / "OUT"
    out.mkdir()
    for name in ("scene.yaml", "sdem_003.pcd"):
        (out / name).write_text("x")
    spec = _spec(terrain_run)
    spec.check({"world": out / "scene.yaml", "output": out})  # not a file the run writes
    with pytest.raises(ValueError, match=r"the command writes sdem_\*\.pcd there"):
        spec.check({"world": out / "sdem_003.pcd", "output": out})
    link = tmp_path / "elsewhere.yaml"
    link.symlink_to(out / "config.yaml")  # a link to a file the run writes, named elsewhere
    (out / "config.yaml").write_text("x")
    with pytest.raises(ValueError, match="the command writes config.yaml there"):
        spec.check({"world": link, "output": out})
    with pytest.raises(NotADirectoryError, match="--output .*scene.yaml: not a folder"):
        spec.check({"world": tmp_path / "w.bt", "output": out / "scene.yaml"})


def test_an_output_folder_inside_an_input_folder_is_refused(tmp_path):
    from kiseki.cli.magnetic import navigate

    (tmp_path / "taught").mkdir()
    spec = _spec(navigate)
    arguments = {"scene": tmp_path / "s.yaml", "map_folder": tmp_path / "taught"}
    for out in (tmp_path / "taught", tmp_path / "taught" / "nav"):
        with pytest.raises(ValueError, match="the input folder --map"):
            spec.check({**arguments, "output": out})
    spec.check({**arguments, "output": tmp_path / "nav"})


def test_a_hard_link_to_a_file_of_an_input_folder_is_that_file(tmp_path):
    from kiseki.cli.localize import localize_command

    (tmp_path / "bag").mkdir()
    (tmp_path / "bag" / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    os.link(tmp_path / "bag" / "metadata.yaml", tmp_path / "linked.csv")
    with pytest.raises(ValueError, match="is a file of the input folder LOG .*bag"):
        _spec(localize_command).check(
            {"log": tmp_path / "bag", "map_file": None, "output": tmp_path / "linked.csv",
             "plot": None, "global_start": False}
        )  # fmt: skip


def test_serve_writes_its_route_history_in_the_taught_folder_and_nothing_else_there(tmp_path):
    from kiseki.cli.serve import serve_command

    taught = tmp_path / "taught"
    taught.mkdir()
    for name in ("waypoints.yaml", "route_history.json"):
        (taught / name).write_text("{}")
    (tmp_path / "scene.yaml").write_text("name: s\n")
    spec, arguments = _spec(serve_command), {"taught": taught, "scene": tmp_path / "scene.yaml"}
    spec.check({**arguments, "history": taught / "route_history.json"})  # its default
    spec.check({**arguments, "history": tmp_path / "routes.json"})
    with pytest.raises(ValueError, match="exists inside the input folder --taught"):
        spec.check({**arguments, "history": taught / "waypoints.yaml"})
    with pytest.raises(ValueError, match="--history .* would overwrite the input --scene"):
        spec.check({**arguments, "history": tmp_path / "scene.yaml"})


def test_derived_outputs_are_declared(tmp_path):
    """localize's OUTPUT-STEM.config.yaml and, with --global, OUTPUT.json; a map's image."""
    from kiseki.cli.localize import localize_command
    from kiseki.cli.map_convert import map_convert

    (tmp_path / "t.json").write_text("{}")
    localize = _spec(localize_command)
    arguments = {"log": tmp_path / "t.json", "map_file": None, "output": tmp_path / "t.csv",
                 "plot": None}  # fmt: skip
    localize.check({**arguments, "global_start": False})
    with pytest.raises(ValueError, match="its report .*t.json would overwrite the input LOG"):
        localize.check({**arguments, "global_start": True})
    (tmp_path / "t.config.yaml").write_text("{}")
    with pytest.raises(ValueError, match="its config .* would overwrite the input --map"):
        localize.check({**arguments, "map_file": tmp_path / "t.config.yaml"})
    (tmp_path / "m.pgm").write_bytes(b"P5")
    with pytest.raises(ValueError, match="--output's image .*m.pgm would overwrite the input MAP"):
        _spec(map_convert).check({"map_file": tmp_path / "m.pgm", "output": tmp_path / "m.yaml"})


def test_the_octree_of_sim_show_is_written_atomically(tmp_path, project_root):
    """sim show's --octree went straight to its file; now through kiseki._support.atomic
    (recorded as written whole), as terrain run's .bt and PCD files."""
    from typer.testing import CliRunner

    from kiseki._support.atomic import written_files
    from kiseki.cli import app

    scene = project_root / "data" / "worlds" / "factory_corridor.yaml"
    before = len(written_files())
    args = ["sim", "show", scene, "-o", tmp_path / "s.png", "--octree", tmp_path / "w.bt"]
    done = CliRunner().invoke(app, [*map(str, args), "--resolution", "0.2"])
    assert done.exit_code == 0, done.output
    assert tmp_path / "w.bt" in written_files()[before:]
    assert not [p for p in os.listdir(tmp_path) if p.startswith(".")]  # no temporary left


# --- links in output folders, large YAML inputs, outputs that are no regular file ---


def test_a_link_to_an_input_in_a_folder_written_whole_is_refused(tmp_path, project_root):
    """``teach -o tt`` with tt/teach.mcap a hard link to the scene wrote its MCAP log into the
    scene (exit 0); ``demo`` with DM/teach/teach.mcap a symlink to it replaced the scene before
    an error: only file names written without wildcards were compared with the inputs."""
    scene = tmp_path / "scene.yaml"
    scene.write_bytes((project_root / "data" / "worlds" / "factory_corridor.yaml").read_bytes())
    (tmp_path / "tt").mkdir()
    os.link(scene, tmp_path / "tt" / "teach.mcap")
    (tmp_path / "dm" / "teach").mkdir(parents=True)
    (tmp_path / "dm" / "teach" / "teach.mcap").symlink_to("../../scene.yaml")
    before = sha256s(tmp_path)
    done = run("teach", "scene.yaml", "-o", "tt", "--overwrite", cwd=tmp_path)
    refused(done, "--out tt would overwrite the input SCENE scene.yaml: tt/teach.mcap is the same")
    done = run("demo", "--scene", "scene.yaml", "--out", "dm", "--particles", "10", cwd=tmp_path)
    refused(done, "--out dm would overwrite the input --scene scene.yaml: dm/teach/teach.mcap ")
    assert sha256s(tmp_path) == before


def test_links_in_an_output_folder_are_refused_where_the_command_writes(tmp_path):
    """A symlink, a symlinked folder holding the input; with patterns, only the entries the
    command writes."""
    from kiseki.cli.teach import teach_command
    from kiseki.cli.terrain import terrain_run

    scene = tmp_path / "scene.yaml"
    scene.write_text("name: s\n")
    out = tmp_path / "out"
    out.mkdir()
    teach, arguments = _spec(teach_command), {"scene_file": scene, "keys": None, "out": out}
    (out / "teach.mcap").symlink_to(scene)
    with pytest.raises(ValueError, match=r"out/teach\.mcap is the same file \(a link\)$"):
        teach.check(arguments)
    (out / "teach.mcap").unlink()
    (out / "up").symlink_to(tmp_path, target_is_directory=True)  # a loop, too: listed once
    with pytest.raises(ValueError, match=r"out/up/scene\.yaml is the same file"):
        teach.check(arguments)
    (out / "up").unlink()
    teach.check(arguments)
    world = tmp_path / "w.bt"
    world.write_bytes(b"octree")
    os.link(world, out / "notes.bt")  # not a file terrain run writes
    spec = _spec(terrain_run)
    spec.check({"world": world, "output": out})
    os.link(world, out / "sdem_001.pcd")
    with pytest.raises(ValueError, match=r"out/sdem_001\.pcd is the same file .*sdem_\*\.pcd"):
        spec.check({"world": world, "output": out})


PADDING = "# " + "x" * 1_100_000 + "\n"  # more than the 1 MiB beyond which it was not looked into


def test_an_input_yaml_larger_than_1_mib_still_protects_the_files_it_names(tmp_path):
    """``map convert big/m.yaml -o big/m.yml`` (m.yaml padded by a 1.1 MB comment) replaced
    the map's image; ``sim run`` a scene as large overwrote its octomap. Every YAML file the
    readers accept (up to kiseki._support.inputs.YAML_LIMIT) is looked into."""
    from kiseki import OccupancyGrid, save_map
    from kiseki._support.inputs import YAML_LIMIT
    from kiseki.cli.playback import playback_command
    from kiseki.cli.sim import sim_run

    assert 2 * len(PADDING) < YAML_LIMIT  # the file is one the readers accept
    (tmp_path / "big").mkdir()
    save_map(OccupancyGrid(4, 4, 0.1), tmp_path / "big" / "m.yaml")
    with open(tmp_path / "big" / "m.yaml", "a") as f:
        f.write(PADDING)
    before = sha256s(tmp_path)
    done = run("map", "convert", "big/m.yaml", "-o", "big/m.yml", cwd=tmp_path)
    refused(done, "--output's image big/m.pgm would overwrite the input MAP's image big/m.pgm")
    assert sha256s(tmp_path) == before
    (tmp_path / "world.bt").write_bytes(b"octree")
    scene = tmp_path / "scene.yaml"
    scene.write_text(f"name: s\noctomap: world.bt\n{PADDING}")
    with pytest.raises(ValueError, match="--output .*world.bt would overwrite the input SCENE's"):
        _spec(sim_run).check({"scene_file": scene, "output": tmp_path / "world.bt"})
    # a waypoint file's maps, named through an alias (loaded whole, as the readers load it)
    waypoints = tmp_path / "w.yaml"
    waypoints.write_text(f"f: &f big/m.yaml\nmaps:\n  band: {{file: *f}}\n{PADDING}")
    with pytest.raises(ValueError, match="the input --waypoints's map's image"):
        _spec(playback_command).check(
            {"scene_file": scene, "waypoints": waypoints, "taught": None, "map_file": None,
             "log": tmp_path / "big" / "m.pgm"}
        )  # fmt: skip


def test_an_output_that_is_a_device_a_fifo_or_a_symlink_is_refused(tmp_path):
    """``-o /dev/null`` (as root) replaced the device by a regular file through the atomic
    rename, ``-o /dev/stdout`` the symlink; here a FIFO, a fake character device (``os.mknod``,
    root only: the same numbers as /dev/null) and a symlink, never the real ones."""
    import stat

    from kiseki import OccupancyGrid, save_map
    from kiseki.cli.map_render import map_render

    save_map(OccupancyGrid(4, 4, 0.1), tmp_path / "m.yaml")
    os.mkfifo(tmp_path / "fifo.png")
    (tmp_path / "target.png").write_bytes(b"mine")
    (tmp_path / "link.png").symlink_to("target.png")
    before = sha256s(tmp_path)
    done = run("map", "render", "m.yaml", "-o", "fifo.png", cwd=tmp_path)
    refused(done, "--output fifo.png: a FIFO (named pipe), not a regular file: kiseki writes "
            "files by replacing them")  # fmt: skip
    done = run("map", "render", "m.yaml", "-o", "link.png", cwd=tmp_path)
    refused(done, "--output link.png: a symlink (to target.png), not a regular file")
    assert stat.S_ISFIFO(os.lstat(tmp_path / "fifo.png").st_mode)
    assert os.readlink(tmp_path / "link.png") == "target.png"
    assert sha256s(tmp_path) == before
    spec = _spec(map_render)
    arguments = {"map_file": tmp_path / "m.yaml", "trajectory": None}
    (tmp_path / "stdout").symlink_to("fifo.png")  # as /dev/stdout to a pipe
    with pytest.raises(ValueError, match=r"stdout: a FIFO .*\(through a symlink to fifo.png\)"):
        spec.check({**arguments, "output": tmp_path / "stdout"})
    (tmp_path / "dangling.png").symlink_to("nothing.png")
    with pytest.raises(ValueError, match="a symlink"):
        spec.check({**arguments, "output": tmp_path / "dangling.png"})
    if os.geteuid() == 0:
        os.mknod(tmp_path / "null.png", 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        with pytest.raises(ValueError, match="null.png: a character device, not a regular"):
            spec.check({**arguments, "output": tmp_path / "null.png"})
        assert stat.S_ISCHR(os.lstat(tmp_path / "null.png").st_mode)
