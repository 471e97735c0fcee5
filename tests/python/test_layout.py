# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The house layout (DESIGN.md): importing kiseki has no side effects on matplotlib, no module
imports another module's private names, and the arrows point down (control does not use the
simulator; laser scans are a neutral type that datasets and sim both import)."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import kiseki

PACKAGE = Path(kiseki.__file__).resolve().parent

# Imports every kiseki module, then draws a map with kiseki.plots, and prints the backend
# matplotlib reports before and after, with the modules that failed to import.
IMPORT_ALL = r"""
import importlib, json, pkgutil, sys
import matplotlib
if sys.argv[1] == "use":
    matplotlib.use("pdf")
before = matplotlib.get_backend()
import kiseki
failed = {}
for info in pkgutil.walk_packages(kiseki.__path__, "kiseki."):
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
    "modules": sorted(m for m in sys.modules if m.startswith("kiseki.")),
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
    assert {"kiseki.plots", "kiseki.sim.render", "kiseki.experiments.teach_playback"} <= set(
        report["modules"]
    )
    assert report["before"].lower() == expected
    assert report["after_import"].lower() == expected
    assert report["after_drawing"].lower() == expected
    assert bytes.fromhex(report["png"]) == b"\x89PNG\r\n\x1a\n"  # drawn by Agg all the same


def private_imports(source: str, module: str, is_package: bool = False) -> list[str]:
    """The imports in `source` (the text of kiseki module `module`) that reach a private name
    from outside its owner: ``a.b._c`` (a module or any other name) belongs to ``a.b`` and may
    be imported only by ``a.b`` and the modules inside it. So ``kiseki._core`` and
    ``kiseki._atomic`` are for every kiseki module, ``kiseki.datasets._files`` for the readers
    in ``kiseki.datasets``, and ``kiseki.plots._figure`` for ``kiseki.plots`` alone."""
    package = module if is_package else module.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[: len(parts) - (node.level - 1)]
                base = ".".join(parts + ([base] if base else []))
            targets = [f"{base}.{alias.name}" for alias in node.names if alias.name != "*"]
        else:
            continue
        for target in targets:
            parts = target.split(".")
            if parts[0] != "kiseki":
                continue
            private = [i for i, p in enumerate(parts) if p.startswith("_") and not p.endswith("__")]
            if not private:
                continue
            owner = ".".join(parts[: private[0]])
            if module != owner and not module.startswith(owner + "."):
                found.append(f"{module}:{node.lineno} imports {target}")
    return found


def test_the_private_import_check_finds_what_it_should():
    assert private_imports("from kiseki.plots import _figure, draw_map\n", "kiseki.x") == [
        "kiseki.x:1 imports kiseki.plots._figure"
    ]
    lazy = "def f():\n    from kiseki.datasets._files import read_maybe_gzipped\n"
    assert private_imports(lazy, "kiseki.sim.mcap_log") == [
        "kiseki.sim.mcap_log:2 imports kiseki.datasets._files.read_maybe_gzipped"
    ]
    assert private_imports(lazy, "kiseki.datasets.carmen") == []
    assert private_imports("from ._files import GZIP_MAGIC\n", "kiseki.datasets.wean") == []
    assert private_imports("from ..plots import _save\n", "kiseki.sim.render") == [
        "kiseki.sim.render:1 imports kiseki.plots._save"
    ]
    allowed = "from kiseki import _core\nfrom kiseki._atomic import atomic_write\n"
    assert private_imports(allowed, "kiseki.teach.teaching") == []


def test_no_module_imports_a_private_name_of_another():
    sources = sorted(PACKAGE.rglob("*.py"))
    assert PACKAGE / "plots.py" in sources and PACKAGE / "datasets" / "carmen.py" in sources
    found = []
    for path in sources:
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        is_package = parts[-1] == "__init__"
        module = ".".join(parts[:-1] if is_package else parts)
        found += private_imports(path.read_text(encoding="utf-8"), module, is_package)
    assert found == []


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
        ("import kiseki.sim.mcap_log", ("kiseki.datasets",)),  # the old datasets <-> sim cycle
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
    from kiseki.sim import mcap_log, run

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
