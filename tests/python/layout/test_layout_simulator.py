# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The house layout (DESIGN.md): a method takes scans, images, readings and poses, never a
scene, so no library module outside kiseki.sim imports the simulator; the apps may."""

from __future__ import annotations

from _helpers.module_imports import PACKAGE, imported_names, is_the_cli, modules_in


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
