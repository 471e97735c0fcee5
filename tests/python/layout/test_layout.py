# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The house layout (DESIGN.md): importing kiseki has no side effects on matplotlib, no module
imports another module's private names, and the arrows point down (control does not use the
simulator; laser scans are a neutral type that datasets and sim both import; the library does
not import the experiments beside it, and the experiments' packages import each other only
through the harness, without a circle). Each rule is checked in its own file beside this one:
test_layout_private_imports.py, test_layout_experiments.py, test_layout_circles.py,
test_layout_simulator.py and test_layout_files.py (imports inside functions, long files)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[3]

# Imports every module of kiseki and of kiseki_experiments, then draws a map with kiseki.plots,
# and prints the backend matplotlib reports before and after, with the modules that failed to
# import.
IMPORT_ALL = r"""
import importlib, json, pkgutil, sys
import matplotlib
if sys.argv[1] == "use":
    matplotlib.use("pdf")
before = matplotlib.get_backend()
import kiseki, kiseki_experiments
failed = {}
for package in (kiseki, kiseki_experiments):
    for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
        try:
            importlib.import_module(info.name)
        except Exception as exc:
            failed[info.name] = repr(exc)
after_import = matplotlib.get_backend()
import numpy as np
from kiseki import OccupancyGrid, Pose2
from kiseki.plots import render_map
cells = np.zeros((20, 30), np.int8)
cells[5, 3:20] = 100
path = render_map(OccupancyGrid(cells, 0.1, Pose2(0.0, 0.0, 0.0)), sys.argv[2],
                  trajectory=np.array([[0.5, 0.2, 0.0], [2.0, 1.5, 0.0]]))
print(json.dumps({
    "before": before,
    "after_import": after_import,
    "after_drawing": matplotlib.get_backend(),
    "modules": sorted(m for m in sys.modules if m.startswith(("kiseki.", "kiseki_experiments."))),
    "failed": failed,
    "png": open(path, "rb").read(8).hex(),
}))
"""


@pytest.mark.parametrize(
    ("how", "expected"), [("env", "svg"), ("use", "pdf")], ids=["MPLBACKEND", "matplotlib.use"]
)
def test_importing_and_drawing_keep_the_users_matplotlib_backend(tmp_path, how, expected):
    env = {**os.environ, "MPLBACKEND": "svg"} if how == "env" else dict(os.environ)
    if how == "use":
        env.pop("MPLBACKEND", None)
    out = subprocess.run(
        [sys.executable, "-c", IMPORT_ALL, how, str(tmp_path / "map.png")],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    report = json.loads(out.stdout.strip().splitlines()[-1])
    assert report["failed"] == {}
    # the walk reached the modules that drew with pyplot after matplotlib.use("Agg")
    assert {"kiseki.plots", "kiseki.sim.render", "kiseki_experiments.teach.teach_playback"} <= set(
        report["modules"]
    )
    assert report["before"].lower() == expected
    assert report["after_import"].lower() == expected
    assert report["after_drawing"].lower() == expected
    assert bytes.fromhex(report["png"]) == b"\x89PNG\r\n\x1a\n"  # drawn by Agg all the same


def design_doc_paths(text: str) -> tuple[list[str], list[str]]:
    """(the folders or modules each area heading of docs/DESIGN.md names, every path in
    backticks of the page) that start with a folder of the repository."""
    path = r"`((?:py|cpp|bindings|tests|docs|data)/[^`*<>\s]*)`"
    headings = [line for line in text.splitlines() if line.startswith("### ")]
    areas = [p for line in headings for p in re.findall(path, line)]
    return areas, re.findall(path, text)


def test_the_design_doc_names_folders_that_exist():
    """docs/DESIGN.md gives each area its folders; a folder renamed or an area moved makes the
    page wrong, and this test says where."""
    areas, paths = design_doc_paths((ROOT / "docs" / "DESIGN.md").read_text(encoding="utf-8"))
    assert {"py/kiseki/sim/", "py/kiseki/datasets/", "py/kiseki_experiments/"} <= set(areas)
    assert len(areas) >= 20
    assert [p for p in sorted(set(paths)) if not (ROOT / p).exists()] == []
    assert design_doc_paths("### x — `py/nowhere/`, `py/kiseki/sim/`\nsee `tests/a.py`") == (
        ["py/nowhere/", "py/kiseki/sim/"],
        ["py/nowhere/", "py/kiseki/sim/", "tests/a.py"],
    )


def imported_kiseki_modules(statement: str) -> list[str]:
    """The kiseki modules loaded by running `statement` in a fresh interpreter."""
    code = f"import sys\n{statement}\nprint('\\n'.join(sorted(sys.modules)))"
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    return [m for m in out.split() if m.startswith("kiseki.")]


@pytest.mark.parametrize(
    ("statement", "forbidden"),
    [
        ("import kiseki.control", ("kiseki.sim", "kiseki.teach", "kiseki.experiments")),
        ("import kiseki.scans", ("kiseki.datasets", "kiseki.sim")),
        ("import kiseki.io.runlog", ("kiseki.datasets",)),  # the old datasets <-> sim cycle
        ("import kiseki.sim.run", ("kiseki.datasets", "kiseki.teach")),
    ],
)
def test_arrows_point_down(statement, forbidden):
    loaded = imported_kiseki_modules(statement)
    assert statement.split()[-1] in loaded
    assert [m for m in loaded if m.startswith(forbidden)] == []


def test_laser_scans_are_one_type_for_logs_and_simulated_runs():
    from kiseki import datasets, scans
    from kiseki.control import PurePursuit
    from kiseki.io import runlog as mcap_log
    from kiseki.sim import run

    assert datasets.LaserScans is scans.LaserScans
    assert "LaserScans" in datasets.__all__ and "LaserScans" not in mcap_log.__all__
    assert run.PurePursuit is PurePursuit and "PurePursuit" not in run.__all__
    s = scans.LaserScans(
        times=np.zeros(2),
        poses=np.full((2, 3), np.nan),
        odometry=np.zeros((2, 3)),
        ranges=np.ones((2, 3), np.float32),
        angles=np.zeros(3),
        max_range=5.0,
    )
    assert len(s) == 2 and not s.has_reference_poses
