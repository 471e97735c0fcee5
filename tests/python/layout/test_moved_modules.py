# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The public modules that moved in the house layout still import by their old names for one
release: the same module object as the new name, and one DeprecationWarning naming the new
module (kiseki._support.moved)."""

from __future__ import annotations

import importlib
import json
import subprocess
import sys

import pytest

from kiseki._support.moved import MOVED

# Runs each import in a fresh interpreter (an old name already imported would not warn again),
# and reports the warnings, whether the old name gives the new module, and a name read
# through it.
PROBE = r"""
import importlib, json, sys, warnings
old, new, name = sys.argv[1:4]
name_in_parent = old.rpartition(".")[2]
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    module = importlib.import_module(old)
    again = importlib.import_module(old)
print(json.dumps({
    "warnings": [(w.category.__name__, str(w.message)) for w in caught],
    "same": module is importlib.import_module(new) and again is module,
    "has_name": hasattr(module, name),
    "parent_attribute": getattr(sys.modules[old.rpartition(".")[0]], name_in_parent) is module,
}))
"""

# a public name each old module held
NAMES = {
    "kiseki.localization": "MonteCarloLocalizer",
    "kiseki.global_localization": "global_localize",
    "kiseki.map_io": "load_map",
    "kiseki.map_schema": "RosMapYaml",
    "kiseki.trajectory_csv": "read_trajectory_csv",
    "kiseki.sim.mcap_log": "read_run",
    "kiseki.datasets.ros_orientation": "yaw_or_nan",
}


def test_every_moved_module_is_probed():
    assert set(MOVED) == set(NAMES)


@pytest.mark.parametrize("old", sorted(NAMES))
def test_an_old_module_name_gives_the_new_module_with_one_warning(old):
    new = MOVED[old]
    out = subprocess.run(
        [sys.executable, "-c", PROBE, old, new, NAMES[old]],
        capture_output=True,
        text=True,
        check=True,
    )
    report = json.loads(out.stdout)
    assert report["warnings"] == [
        [
            "DeprecationWarning",
            f"{old} moved to {new}; import {new} instead (the old name goes in the next release)",
        ]
    ]
    assert report["same"] and report["has_name"] and report["parent_attribute"]


def test_from_import_of_an_old_name_points_the_warning_at_the_importer(tmp_path):
    script = tmp_path / "user.py"
    script.write_text("from kiseki.map_io import load_map\n")
    out = subprocess.run(
        [sys.executable, "-W", "always::DeprecationWarning", str(script)],
        capture_output=True,
        text=True,
        check=True,
    )
    assert f"{script}:1: DeprecationWarning: kiseki.map_io moved to kiseki.io.ros_map" in out.stderr


# names that left a module still there: (module, name, where it is now); kiseki.sim.robot's
# are tested beside the robot (tests/python/sim/test_sim_robot_inputs.py)
MOVED_NAMES = [
    ("kiseki.datasets.rosbag", "write_bag", "kiseki.datasets.rosbag_writer"),
    ("kiseki.metrics", "MapTruth", "kiseki.teach.map_truth"),
    ("kiseki.metrics", "taught_map_truth", "kiseki.teach.map_truth"),
    ("kiseki.coop.positioning", "CoopRun", "kiseki.coop.simulation"),
    ("kiseki.coop.positioning", "CoopRun3D", "kiseki.coop.simulation"),
    ("kiseki.coop.positioning", "simulate", "kiseki.coop.simulation"),
    ("kiseki.coop.positioning", "simulate_3d", "kiseki.coop.simulation"),
]


@pytest.mark.parametrize(("module", "name", "new"), MOVED_NAMES)
def test_a_moved_name_gives_the_new_object_with_a_warning_and_others_stay_unknown(
    module, name, new
):
    old = importlib.import_module(module)
    with pytest.warns(DeprecationWarning) as caught:
        got = getattr(old, name)
    assert got is getattr(importlib.import_module(new), name)
    assert [str(w.message) for w in caught] == [
        f"{module}.{name} moved to {new}.{name}; import it from there (the old name goes in the "
        "next release)"
    ]
    assert caught[0].filename == __file__  # pointed at the reader of the name
    with pytest.raises(AttributeError, match=f"module '{module}' has no attribute 'no_such'"):
        old.no_such  # noqa: B018


def test_an_unknown_name_is_not_answered():
    with pytest.raises(ModuleNotFoundError):
        __import__("kiseki.no_such_module")
