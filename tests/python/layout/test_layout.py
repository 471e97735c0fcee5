# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The house layout (DESIGN.md): importing kiseki has no side effects on matplotlib, no module
imports another module's private names, and the arrows point down (control does not use the
simulator; laser scans are a neutral type that datasets and sim both import; the library does
not import the experiments beside it, and the experiments' packages import each other only
through the harness, without a circle)."""

from __future__ import annotations

import ast
import importlib.machinery
import json
import os
import re
import subprocess
import sys
from collections.abc import Iterable
from pathlib import Path

import numpy as np
import pytest

import kiseki
import kiseki_experiments

PACKAGE = Path(kiseki.__file__).resolve().parent
EXPERIMENTS = Path(kiseki_experiments.__file__).resolve().parent
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


def modules_in(folder: Path) -> list[tuple[str, Path, bool]]:
    """(module name, file, whether it is a package's __init__) of every module in `folder`."""
    out = []
    for path in sorted(folder.rglob("*.py")):
        parts = path.relative_to(folder.parent).with_suffix("").parts
        is_package = parts[-1] == "__init__"
        out.append((".".join(parts[:-1] if is_package else parts), path, is_package))
    return out


def imported_names(source: str, module: str, is_package: bool = False) -> list[tuple[int, str]]:
    """(line, dotted name) of every import in `source` (the text of module `module`), at any
    depth (inside functions too), relative imports resolved: ``import a.b`` gives ``a.b``,
    ``from a.b import c`` gives ``a.b.c`` (c a module or any other name), ``from a.b import *``
    gives ``a.b``, and ``importlib.import_module("a.b")`` (or ``__import__``) gives ``a.b``."""
    package = module if is_package else module.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[: len(parts) - (node.level - 1)]
                base = ".".join(parts + ([base] if base else []))
            found += [
                (node.lineno, base if alias.name == "*" else f"{base}.{alias.name}")
                for alias in node.names
            ]
        elif (
            isinstance(node, ast.Call)
            and getattr(node.func, "attr", getattr(node.func, "id", None))
            in ("import_module", "__import__")
            and node.args
            and isinstance(node.args[0], ast.Constant)
            and isinstance(node.args[0].value, str)
        ):
            found.append((node.lineno, node.args[0].value))
    return found


def private_imports(source: str, module: str, is_package: bool = False) -> list[str]:
    """The imports in `source` (the text of module `module` of kiseki or kiseki_experiments)
    that reach a private name from outside its owner: ``a.b._c`` (a module or any other name)
    belongs to ``a.b`` and may be imported only by ``a.b`` and the modules inside it. So
    ``kiseki.datasets._files`` is for the readers in ``kiseki.datasets``, ``kiseki.plots._figure``
    for ``kiseki.plots`` alone, ``kiseki_experiments.terrain.terrain_envs._rise`` for that module.
    The private modules of the package ``kiseki`` itself (``kiseki._core``,
    ``kiseki._support.atomic``,
    ``kiseki._support.schema``, ...) are for every module of the project: kiseki's and the
    experiments' beside it, shipped in the same wheel (they write files atomically and read configs
    as the CLI does)."""
    found = []
    for line, target in imported_names(source, module, is_package):
        parts = target.split(".")
        if parts[0] not in ("kiseki", "kiseki_experiments"):
            continue
        private = [i for i, p in enumerate(parts) if p.startswith("_") and not p.endswith("__")]
        if not private:
            continue
        owner = ".".join(parts[: private[0]])
        if owner == "kiseki" and module.split(".")[0] == "kiseki_experiments":
            continue
        if module != owner and not module.startswith(owner + "."):
            found.append(f"{module}:{line} imports {target}")
    return found


def test_the_private_import_check_finds_what_it_should():
    assert private_imports("from kiseki.plots import _figure, draw_map\n", "kiseki.x") == [
        "kiseki.x:1 imports kiseki.plots._figure"
    ]
    lazy = "def f():\n    from kiseki.datasets._files import read_maybe_gzipped\n"
    assert private_imports(lazy, "kiseki.io.runlog") == [
        "kiseki.io.runlog:2 imports kiseki.datasets._files.read_maybe_gzipped"
    ]
    assert private_imports(lazy, "kiseki.datasets.carmen") == []
    assert private_imports("from ._files import GZIP_MAGIC\n", "kiseki.datasets.wean") == []
    assert private_imports("from ..plots import _save\n", "kiseki.sim.render") == [
        "kiseki.sim.render:1 imports kiseki.plots._save"
    ]
    allowed = "from kiseki import _core\nfrom kiseki._support.atomic import atomic_write\n"
    assert private_imports(allowed, "kiseki.apps.teach.teaching") == []
    assert private_imports(allowed, "kiseki_experiments.harness.runner") == []
    figure = "from kiseki.plots import _figure\n"
    assert private_imports(figure, "kiseki_experiments.gp.gp_mcl") == [
        "kiseki_experiments.gp.gp_mcl:1 imports kiseki.plots._figure"
    ]
    rise = "from kiseki_experiments.terrain.terrain_envs import _rise\n"
    assert private_imports(rise, "kiseki_experiments.terrain.terrain_corridor") == [
        "kiseki_experiments.terrain.terrain_corridor:1 imports "
        "kiseki_experiments.terrain.terrain_envs._rise"
    ]


def test_no_module_imports_a_private_name_of_another():
    modules = modules_in(PACKAGE) + modules_in(EXPERIMENTS)
    sources = {path for _, path, _ in modules}
    assert PACKAGE / "plots.py" in sources and PACKAGE / "datasets" / "carmen.py" in sources
    assert EXPERIMENTS / "harness" / "runner.py" in sources
    found = []
    for module, path, is_package in modules:
        found += private_imports(path.read_text(encoding="utf-8"), module, is_package)
    assert found == []


def is_the_cli(module: str) -> bool:
    """kiseki's command line (the ``kiseki.cli`` package): an app like the experiments, the one
    part of py/kiseki that may run them."""
    return module == "kiseki.cli" or module.startswith("kiseki.cli.")


def experiment_imports(source: str, module: str, is_package: bool = False) -> list[str]:
    """The imports in `source` (the text of library module `module`) that reach
    kiseki_experiments: the library never imports the experiments beside it, except the CLI."""
    if is_the_cli(module):
        return []
    return [
        f"{module}:{line} imports {target}"
        for line, target in imported_names(source, module, is_package)
        if target.split(".")[0] == "kiseki_experiments"
    ]


def test_the_experiment_import_check_finds_what_it_should():
    lazy = "def f():\n    from kiseki_experiments.harness.runner import run_experiment\n"
    assert experiment_imports(lazy, "kiseki.apps.teach.playback") == [
        "kiseki.apps.teach.playback:2 imports kiseki_experiments.harness.runner.run_experiment"
    ]
    assert experiment_imports("import kiseki_experiments.teach\n", "kiseki.demo") == [
        "kiseki.demo:1 imports kiseki_experiments.teach"
    ]
    assert experiment_imports("from kiseki_experiments import *\n", "kiseki.sim", True) == [
        "kiseki.sim:1 imports kiseki_experiments"
    ]
    dynamic = "import importlib\nimportlib.import_module('kiseki_experiments.gp.gp_mcl')\n"
    assert experiment_imports(dynamic, "kiseki.plots") == [
        "kiseki.plots:2 imports kiseki_experiments.gp.gp_mcl"
    ]
    assert experiment_imports("import kiseki_experimental\n", "kiseki.plots") == []
    assert experiment_imports(lazy, "kiseki.cli") == []
    assert experiment_imports(lazy, "kiseki.cli_speed") != []  # no longer a command-line module
    assert experiment_imports(lazy, "kiseki.cli.experiment") == []
    assert experiment_imports(lazy, "kiseki.client") != []  # not the CLI for sharing a prefix


def test_no_library_module_but_the_cli_imports_the_experiments():
    modules = modules_in(PACKAGE)
    assert {"kiseki.cli.demo", "kiseki.plots", "kiseki.cli"} <= {m for m, _, _ in modules}
    found = []
    for module, path, is_package in modules:
        found += experiment_imports(path.read_text(encoding="utf-8"), module, is_package)
    assert found == []
    # the CLI does run them (the check above does not pass for want of an importer)
    cli_imports = [
        target
        for module, path, is_package in modules
        if is_the_cli(module)
        for _, target in imported_names(path.read_text(encoding="utf-8"), module, is_package)
    ]
    assert "kiseki_experiments.harness.runner.run_experiment" in cli_imports


# The harness modules above the papers: they reach every paper (the registry imports them all,
# the runner and the report look experiments up in it), so no paper imports them.
ABOVE_THE_PAPERS = ("registry", "runner", "report", "readme_blocks", "controls")


def package_rule_breaks(source: str, module: str, is_package: bool = False) -> list[str]:
    """The imports in `source` (the text of kiseki_experiments module `module`) that break its
    package rule. A paper's package (``kiseki_experiments.<paper>``) imports only its own modules
    and the harness below the papers (every ``harness`` module but the registry, the runner, the
    report, its README tables and the controls): what two papers share is in the harness. A
    harness module below the papers imports no paper and nothing above the papers; the runner
    and the report import no paper
    (they reach them through the registry); the registry imports every paper. A package's
    ``__init__`` imports nothing of kiseki_experiments, so that importing a harness module
    never loads the registry."""
    parts = module.split(".")
    group, name = (parts + ["", ""])[1:3]
    found = []
    for line, target in imported_names(source, module, is_package):
        t = target.split(".")
        if t[0] != "kiseki_experiments":
            continue
        t_group, t_name = (t + ["", ""])[1:3]
        if is_package or not t_group:
            allowed = False
        elif group == "harness" and name == "registry":
            allowed = True
        elif group == "harness":
            allowed = t_group == "harness" and (
                name in ABOVE_THE_PAPERS or t_name not in ABOVE_THE_PAPERS
            )
        else:
            allowed = t_group == group or (t_group == "harness" and t_name not in ABOVE_THE_PAPERS)
        if not allowed:
            found.append(f"{module}:{line} imports {target}")
    return found


def test_the_package_rule_check_finds_what_it_should():
    check = package_rule_breaks
    fig = "kiseki_experiments.magnav.magnav_fig_5_4"
    assert check("from kiseki_experiments.speed.speed_common import WORLDS\n", fig) == [
        f"{fig}:1 imports kiseki_experiments.speed.speed_common.WORLDS"
    ]
    # the old circle: a config check looked the experiment up in the registry
    lazy = "def f():\n    from kiseki_experiments.harness.registry import all_experiments\n"
    config = "kiseki_experiments.harness.config"
    assert check(lazy, config) == [
        f"{config}:2 imports kiseki_experiments.harness.registry.all_experiments"
    ]
    assert check(lazy, "kiseki_experiments.teach.layouts") != []
    assert check("from kiseki_experiments.teach import layouts\n", config) != []
    own = (
        "from kiseki_experiments.harness.paths import WORLDS\n"
        "from kiseki_experiments.harness.config import Particles\n"
        "from . import teach_playback as tp\n"
    )
    assert check(own, "kiseki_experiments.teach.layouts") == []
    registry = "kiseki_experiments.harness.registry"
    assert check("from kiseki_experiments.teach import layouts\n", registry) == []
    runner = "kiseki_experiments.harness.runner"
    assert check(lazy, runner) == []
    assert check("from kiseki_experiments.teach import layouts\n", runner) != []
    init = "from kiseki_experiments.harness import base\n"
    assert check(init, "kiseki_experiments.teach", is_package=True) != []
    assert check("import kiseki_experiments\n", "kiseki_experiments.gp.gp_mcl") != []


def test_the_experiments_packages_import_each_other_only_through_the_harness():
    modules = modules_in(EXPERIMENTS)
    names = {m for m, _, _ in modules}
    assert {"kiseki_experiments.harness.registry", "kiseki_experiments.teach.layouts"} <= names
    found = []
    for module, path, is_package in modules:
        found += package_rule_breaks(path.read_text(encoding="utf-8"), module, is_package)
    assert found == []


def import_circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The circles of an import graph (module -> modules it imports): each strongly connected
    component of more than one module, or a module that imports itself (Tarjan's algorithm)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1 or v in graph.get(v, ()):
                circles.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(circles)


def import_edges(*folders: Path, compiled: Iterable[str] = ()) -> dict[str, dict[str, list[int]]]:
    """The import graph of the packages in `folders`, with the lines of each import: module ->
    {module it depends on: [lines]}. What counts (docs/DESIGN.md, "Tiers"):

    * every import statement (:func:`imported_names`), at module level or inside a function:
      an import inside a function postpones the loading, it does not remove the dependency, so
      it cannot hide a circle;
    * ``import a.b.c`` and ``from a.b import c`` (c a module) depend on ``a.b.c``, and on the
      packages ``a.b`` and ``a`` unless the importing module is inside them: Python runs a
      package's ``__init__`` before its modules, so ``import kiseki.datasets.kok`` from outside
      ``kiseki.datasets`` runs ``kiseki/datasets/__init__.py`` (and whatever it imports) first;
    * ``from a.b import name`` (name not a module) depends on ``a.b``, the ``__init__`` that binds
      the name. A module's own packages are no dependency of it for merely containing it (they
      are running when it runs), but they are when it takes a name from them: a submodule that
      reads a name from its package's ``__init__`` is in a circle when that ``__init__`` imports
      it;
    * `compiled` names modules without a .py file (``kiseki._core``): ``from kiseki import _core``
      is that module, not a name of ``kiseki/__init__.py``. Modules outside `folders` (numpy,
      the extension) are left out of the graph.
    """
    modules = [m for folder in folders for m in modules_in(folder)]
    names = {m for m, _, _ in modules} | set(compiled)
    packages = {m for m, _, is_package in modules if is_package}
    graph = {}
    for module, path, is_package in modules:
        edges: dict[str, list[int]] = {}
        for line, target in imported_names(path.read_text(encoding="utf-8"), module, is_package):
            while target and target not in names:
                target = target.rpartition(".")[0]
            found = [target] if target and target not in compiled else []
            package = target.rpartition(".")[0]
            while package:  # the packages that run before `target`, unless they hold `module`
                if package in packages and not f"{module}.".startswith(f"{package}."):
                    found.append(package)
                package = package.rpartition(".")[0]
            for name in found:
                if name != module:
                    edges.setdefault(name, []).append(line)
        graph[module] = edges
    return graph


def import_graph(folder: Path) -> dict[str, set[str]]:
    """The modules of the package in `folder` and the modules of it that each depends on
    (:func:`import_edges`), inside functions too."""
    return {module: set(edges) for module, edges in import_edges(folder).items()}


def compiled_modules(package) -> set[str]:
    """The extension modules of `package` (``kiseki._core``): found by their file suffix in the
    package's folders (an editable install keeps them apart from the sources)."""
    suffixes = tuple(importlib.machinery.EXTENSION_SUFFIXES)
    return {
        f"{package.__name__}.{path.name.partition('.')[0]}"
        for folder in package.__path__
        for path in Path(folder).iterdir()
        if path.name.endswith(suffixes)
    }


def describe_circles(edges: dict[str, dict[str, list[int]]], circles: list[list[str]]) -> list[str]:
    """Each circle as the imports that close it: ``a -> b (line 3); b -> a (line 9)``."""
    out = []
    for circle in circles:
        inside = set(circle)
        arrows = [
            f"{a} -> {b} (line {', '.join(map(str, sorted(set(edges[a][b]))))})"
            for a in circle
            for b in sorted(set(edges[a]) & inside)
        ]
        out.append("; ".join(arrows))
    return out


def test_the_circle_check_finds_what_it_should():
    assert import_circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}) == [
        ["a", "b", "c"]
    ]
    assert import_circles({"a": {"a"}, "b": {"a"}}) == [["a"]]
    assert import_circles({"a": {"b"}, "b": set()}) == []


def test_the_experiments_form_no_import_circle():
    """Before they left the library, the experiments' config imported the registry (to name an
    experiment in a message), which imports every experiment: a circle of 25 files."""
    graph = import_graph(EXPERIMENTS)
    assert "kiseki_experiments.harness.registry" in graph["kiseki_experiments.harness.runner"]
    assert len(graph["kiseki_experiments.harness.registry"]) > 20
    assert import_circles(graph) == []


def write_files(root: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text, encoding="utf-8")


def test_the_import_graph_finds_the_circles_of_a_small_package(tmp_path):
    write_files(
        tmp_path,
        {
            "pkg/__init__.py": "from pkg.grid import Grid\n",
            "pkg/grid.py": "from pkg import _ext\n\nGrid = _ext.Grid\n",
            # a circle closed inside a function (a map's load and its folder reader)
            "pkg/maps.py": "import pkg.grid\n\n\ndef load(f):\n    from pkg.folder import read\n",
            "pkg/folder.py": "from .maps import load\n\n\ndef read(f):\n    return f\n",
            # a submodule that takes a name from its own package's __init__, which imports it
            "pkg/sensors/__init__.py": "from pkg.sensors.laser import Laser\n\nMAX_RANGE = 5.0\n",
            "pkg/sensors/laser.py": "from pkg.sensors import MAX_RANGE\n\nLaser = MAX_RANGE\n",
            # siblings and the own package by module name: no circle
            "pkg/sensors/camera.py": (
                "import pkg.sensors.laser\nfrom . import laser\nfrom pkg import grid\n"
            ),
            # importing a module runs its package's __init__ first, which imports the importer
            "pkg/readers/__init__.py": "from pkg.scans import Scans\n",
            "pkg/readers/csv.py": "ROWS = 1\n",
            "pkg/scans.py": "Scans = 1\n\n\ndef read(f):\n    import pkg.readers.csv\n",
        },
    )
    edges = import_edges(tmp_path / "pkg", compiled={"pkg._ext"})
    assert edges["pkg.sensors.camera"] == {"pkg.sensors.laser": [1, 2], "pkg.grid": [3]}
    assert edges["pkg.scans"] == {"pkg.readers.csv": [5], "pkg.readers": [5]}
    graph = {module: set(e) for module, e in edges.items()}
    circles = import_circles(graph)
    assert circles == [
        ["pkg.folder", "pkg.maps"],
        ["pkg.readers", "pkg.scans"],
        ["pkg.sensors", "pkg.sensors.laser"],
    ]
    assert describe_circles(edges, circles) == [
        "pkg.folder -> pkg.maps (line 1); pkg.maps -> pkg.folder (line 5)",
        "pkg.readers -> pkg.scans (line 1); pkg.scans -> pkg.readers (line 5)",
        "pkg.sensors -> pkg.sensors.laser (line 1); pkg.sensors.laser -> pkg.sensors (line 1)",
    ]
    # without knowing that pkg._ext is a compiled module, `from pkg import _ext` reads as a name
    # of pkg's __init__, which imports grid: a circle that is not there
    blind = {module: set(e) for module, e in import_edges(tmp_path / "pkg").items()}
    assert ["pkg", "pkg.grid"] in import_circles(blind)


# While the experiments' old home exists (their move out of the library), its circles are the
# move's to break; every other circle that holds a kiseki module is the library's.
OLD_EXPERIMENTS = "kiseki.experiments"


def test_the_library_forms_no_import_circle():
    """No circle among kiseki's modules, counting imports inside functions and the experiments
    beside it (a circle through them and back is found too). Before issue 28 there were four:
    datasets.kok and datasets.magnetic, magnetic.field_map and magnetic.map_folder, sim.magnetic
    with magnetic_lattice and magnetic_schema, sim.sensors and sim.tilting_laser (a module
    __getattr__ left after a move)."""
    compiled = compiled_modules(kiseki)
    assert "kiseki._core" in compiled
    edges = import_edges(PACKAGE, EXPERIMENTS, compiled=compiled)
    assert "kiseki" not in edges["kiseki.core"]  # it imports the extension, not kiseki's __init__
    # inside a function in map_io: the reader, and the datasets' __init__ that runs before it
    assert {"kiseki.datasets.wean", "kiseki.datasets"} <= set(edges["kiseki.io.ros_map"])
    circles = [
        circle
        for circle in import_circles({module: set(e) for module, e in edges.items()})
        if any(
            m.split(".")[0] == "kiseki" and not f"{m}.".startswith(f"{OLD_EXPERIMENTS}.")
            for m in circle
        )
    ]
    assert describe_circles(edges, circles) == []


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


def is_an_app(module: str) -> bool:
    """The apps inside py/kiseki: the command line (the demo in it), ``kiseki.serve`` (the route
    web page of a simulated AGV) and ``kiseki.apps`` (the runs that drive the simulator with
    the methods). Everything else in py/kiseki is the library."""
    return is_the_cli(module) or any(
        module == app or module.startswith(f"{app}.") for app in ("kiseki.serve", "kiseki.apps")
    )


def simulator_imports(source: str, module: str, is_package: bool = False) -> list[str]:
    """The imports in `source` (the text of library module `module`) that reach the simulator:
    a method takes scans, images, readings and poses, never a scene, so no library module
    outside ``kiseki.sim`` imports it; the apps may."""
    if is_an_app(module) or module == "kiseki.sim" or module.startswith("kiseki.sim."):
        return []
    return [
        f"{module}:{line} imports {target}"
        for line, target in imported_names(source, module, is_package)
        if target == "kiseki.sim" or target.startswith("kiseki.sim.")
    ]


def test_the_simulator_import_check_finds_what_it_should():
    lazy = "def f():\n    from kiseki.sim.scene import load_scene\n"
    assert simulator_imports(lazy, "kiseki.teach.playback_log") == [
        "kiseki.teach.playback_log:2 imports kiseki.sim.scene.load_scene"
    ]
    assert simulator_imports("from kiseki import sim\n", "kiseki.magnetic.render") == [
        "kiseki.magnetic.render:1 imports kiseki.sim"
    ]
    assert simulator_imports("from ..sim import run\n", "kiseki.datasets", True) == [
        "kiseki.datasets:1 imports kiseki.sim.run"
    ]
    assert simulator_imports("import kiseki.simulation\n", "kiseki.teach.x") == []
    assert simulator_imports(lazy, "kiseki.sim.run") == []  # the simulator itself
    for app in (
        "kiseki.apps.teach.teaching",
        "kiseki.serve.robot",
        "kiseki.cli.demo",
        "kiseki.cli",
    ):
        assert simulator_imports(lazy, app) == []
    assert simulator_imports(lazy, "kiseki.services") != []  # not serve for sharing a prefix


def test_no_library_module_imports_the_simulator():
    modules = modules_in(PACKAGE)
    names = {m for m, _, _ in modules}
    assert {"kiseki.teach.local_maps", "kiseki.datasets", "kiseki.magnetic.linear_map_run"} <= names
    found = []
    for module, path, is_package in modules:
        found += simulator_imports(path.read_text(encoding="utf-8"), module, is_package)
    assert found == []
    # the apps do drive it (the check above does not pass for want of an importer)
    teaching = PACKAGE / "apps" / "teach" / "teaching.py"
    targets = {t for _, t in imported_names(teaching.read_text(), "kiseki.apps.teach.teaching")}
    assert "kiseki.sim.setup.build_robot" in targets


def unexplained_function_imports(source: str) -> list[int]:
    """The lines of the imports inside a function or method in `source` that no comment
    explains. An import inside a function postpones loading a module and nothing else (it is
    still a dependency); its one reason is start-up time (``import kiseki``, ``kiseki --help``
    or a package's own import staying fast), which a comment on its line or on the lines just
    above it says."""
    lines = source.splitlines()
    found = set()
    for function in ast.walk(ast.parse(source)):
        if not isinstance(function, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        for node in ast.walk(function):
            if not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            above = node.lineno - 2
            while above >= 0 and lines[above].strip().startswith("import "):
                above -= 1  # a group of imports under one comment
            while above >= 0 and lines[above].strip().startswith("from "):
                above -= 1
            commented = "#" in lines[node.lineno - 1] or (
                above >= 0 and lines[above].strip().startswith("#")
            )
            if not commented:
                found.add(node.lineno)
    return sorted(found)


def test_the_function_import_check_finds_what_it_should():
    bare = "def f():\n    from kiseki.mapping import scan_local_map\n    return 1\n"
    assert unexplained_function_imports(bare) == [2]
    method = "class A:\n    def f(self):\n        import scipy.io\n"
    assert unexplained_function_imports(method) == [3]
    same_line = "def f():\n    import scipy.io  # here: scipy is slow to load\n"
    assert unexplained_function_imports(same_line) == []
    above = (
        "def f():\n    # here, not at the top: matplotlib is slow to load\n"
        "    from matplotlib.axes import Axes\n    from matplotlib.figure import Figure\n"
    )
    assert unexplained_function_imports(above) == []
    assert unexplained_function_imports("import os\n\n\ndef f():\n    return os\n") == []


@pytest.mark.parametrize(
    ("folder", "at_least"),
    [(PACKAGE, 100), (EXPERIMENTS, 50)],
    ids=["kiseki", "kiseki_experiments"],
)
def test_imports_inside_functions_say_why(folder, at_least):
    """py/kiseki, the library and its apps, imports at the top of its modules; the few imports
    left inside functions keep a start-up fast and say so. The command line's root loads a
    command's module by name (``importlib``, not an import statement) so that ``kiseki --help``
    stays fast; its command modules import at their tops. py/kiseki_experiments does the same:
    ``kiseki experiment list`` imports every experiment module through the registry, so what
    an experiment imports at its top every ``kiseki experiment`` command loads."""
    found = []
    counted = 0
    for module, path, _ in modules_in(folder):
        counted += 1
        found += [f"{module}:{line}" for line in unexplained_function_imports(path.read_text())]
    assert counted > at_least
    assert found == []


# A library file holds one concept; past this many lines it is usually two. The files allowed
# over it, and why, each of which says so in its module docstring ("Why one file over 400
# lines: ...").
LINE_LIMIT = 400
LONG_FILES = {
    "datasets/rosbag.py": "ROS 1 and ROS 2 bags share the message layout and the writer",
    "sim/robot.py": "the two simulated platforms share the odometry error model",
    "sim/magnetic.py": "the simulated field and the magnetometer that reads it",
    "apps/teach/teaching.py": "a teaching run, its recovery from the log and its files",
}


def long_files(folder: Path, limit: int = LINE_LIMIT) -> dict[str, int]:
    """The files of the package in `folder` over `limit` lines (path relative to `folder`:
    lines)."""
    out = {}
    for _, path, _ in modules_in(folder):
        lines = len(path.read_text(encoding="utf-8").splitlines())
        if lines > limit:
            out[path.relative_to(folder).as_posix()] = lines
    return out


def test_the_long_file_check_finds_what_it_should(tmp_path):
    write_files(
        tmp_path,
        {
            "kiseki/__init__.py": "",
            "kiseki/short.py": "x = 1\n" * 400,
            "kiseki/long.py": "x = 1\n" * 401,
            "kiseki/cli/long.py": "x = 1\n" * 900,
            "kiseki/area/long.py": "x = 1\n" * 500,
        },
    )
    assert long_files(tmp_path / "kiseki") == {
        "long.py": 401,
        "area/long.py": 500,
        "cli/long.py": 900,
    }


def test_at_most_five_library_files_are_long_and_each_says_why():
    assert len(LONG_FILES) <= 5
    long = long_files(PACKAGE)
    assert sorted(set(long) - set(LONG_FILES)) == []
    # a file that got short leaves the list, so the list stays the truth
    assert sorted(set(LONG_FILES) - set(long)) == []
    for name in LONG_FILES:
        docstring = ast.get_docstring(ast.parse((PACKAGE / name).read_text())) or ""
        assert "Why one file over 400 lines:" in docstring, name
