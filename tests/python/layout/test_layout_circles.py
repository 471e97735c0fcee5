# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The house layout (DESIGN.md, "Tiers"): neither the library nor the experiments form an
import circle, counting imports inside functions and the packages whose ``__init__`` runs
first."""

from __future__ import annotations

import importlib.machinery
from collections.abc import Iterable
from pathlib import Path

import kiseki
from _helpers.module_imports import (
    EXPERIMENTS,
    PACKAGE,
    imported_names,
    modules_in,
    write_files,
)


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
