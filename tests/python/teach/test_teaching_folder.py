# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The library's teaching keeps a user's files in its output folder as the command line does:
without ``overwrite``, a folder holding any file a teaching run writes is refused before
anything is written."""

from __future__ import annotations

import pytest
import yaml

from kiseki.apps.teach import teach
from kiseki.apps.teach.teaching import TEACHING_FILES
from kiseki.sim.scene import load_scene


@pytest.mark.parametrize("name", ["map_plane.yaml", "waypoints.yaml", "map_truth.json"])
def test_the_library_teaching_keeps_a_users_file_without_overwrite(tmp_path, project_root, name):
    """teach(overwrite=False) refused only an existing teach.mcap: the user's other files of
    the names it writes were replaced. The command line already refused them."""
    doc = yaml.safe_load((project_root / "data" / "worlds" / "factory_corridor.yaml").read_text())
    doc["route"] = {"waypoints": [[0.0, 0.0], [1.0, 0.0]], "names": ["P0", "P1"], "speed": 0.5}
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(doc))
    (tmp_path / "t").mkdir()
    (tmp_path / "t" / name).write_text("the user's own\n")
    with pytest.raises(FileExistsError) as err:
        teach(load_scene(path), tmp_path / "t")
    assert str(err.value) == (
        f"out {tmp_path / 't'} holds {name}, which this command would replace: give a new or "
        "empty folder, or overwrite=True"
    )
    assert [p.name for p in (tmp_path / "t").iterdir()] == [name]
    assert (tmp_path / "t" / name).read_text() == "the user's own\n"
    teach(load_scene(path), tmp_path / "t", overwrite=True)
    assert sorted(p.name for p in (tmp_path / "t").iterdir()) == sorted(TEACHING_FILES)
