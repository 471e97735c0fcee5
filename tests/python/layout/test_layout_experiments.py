# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The house layout (DESIGN.md): the library does not import the experiments beside it (the
command line does), and the experiments' packages import each other only through the
harness."""

from __future__ import annotations

from _helpers.module_imports import (
    EXPERIMENTS,
    PACKAGE,
    imported_names,
    is_the_cli,
    modules_in,
)


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
