# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The public modules that moved in the house layout, importable by their old names for one
release: ``import kiseki.localization`` gives the module now at ``kiseki.filters`` (the same
module object, so the old name and the new one share their state) and warns once, with a
DeprecationWarning naming the new module.

The old names are answered by a finder on ``sys.meta_path`` that knows only the names in
:data:`MOVED`; every other import passes it by. ``kiseki/__init__`` installs it."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import warnings
from types import ModuleType

__all__ = ["MOVED", "install"]

MOVED = {
    "kiseki.localization": "kiseki.filters",
    "kiseki.global_localization": "kiseki.filters",
    "kiseki.map_io": "kiseki.io.ros_map",
    "kiseki.map_schema": "kiseki.io.map_schema",
    "kiseki.trajectory_csv": "kiseki.io.trajectory_csv",
    "kiseki.sim.mcap_log": "kiseki.io.runlog",
}
"""old module -> the module that holds its names now."""


class _MovedModule(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    def find_spec(self, fullname, path=None, target=None):
        if fullname not in MOVED:
            return None
        return importlib.machinery.ModuleSpec(fullname, self)

    def create_module(self, spec) -> None:
        """The default module: a stand-in that :meth:`exec_module` replaces."""

    def exec_module(self, module: ModuleType) -> None:
        """Imports the new module and puts it in the old name's place in ``sys.modules``, which
        is what the import statement returns (the stand-in is dropped)."""
        new = MOVED[module.__name__]
        warnings.warn(
            f"{module.__name__} moved to {new}; import {new} instead (the old name goes in the "
            "next release)",
            DeprecationWarning,
            # 2: the import statement (warnings skips importlib's frames between)
            stacklevel=2,
        )
        sys.modules[module.__name__] = importlib.import_module(new)


def install() -> None:
    """Puts the finder first on ``sys.meta_path`` (once)."""
    if not any(isinstance(f, _MovedModule) for f in sys.meta_path):
        sys.meta_path.insert(0, _MovedModule())
