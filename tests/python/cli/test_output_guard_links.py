# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 27, item 1: the output guard (kiseki._support.guard) against links in output folders,
input YAML files larger than 1 MiB and outputs that are no regular file (a device, a FIFO, a
symlink)."""

from __future__ import annotations

import os

import pytest

from _helpers.output_guard import _spec, refused, run, sha256s


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
