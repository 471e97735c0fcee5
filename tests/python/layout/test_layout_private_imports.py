# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The house layout (DESIGN.md): no module of kiseki or kiseki_experiments imports another
module's private names."""

from __future__ import annotations

from _helpers.module_imports import EXPERIMENTS, PACKAGE, imported_names, modules_in


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
