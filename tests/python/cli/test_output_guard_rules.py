# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 27, item 1: the output guard's rules (kiseki._support.guard, kiseki._support.outputs)
on their own, in this process: prefixes and files an input names, input and output folders,
hard links, where serve writes its route history, derived outputs and atomic writes."""

from __future__ import annotations

import os

import pytest

from _helpers.output_guard import _spec


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
