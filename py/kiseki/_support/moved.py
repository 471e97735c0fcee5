# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The public modules and names that moved (in the house issue's layout and in later splits),
importable by their old names for one release, each with a DeprecationWarning naming where it
is now.

* Modules: ``import kiseki.localization`` gives the module now at ``kiseki.filters`` (the same
  module object, so the old name and the new one share their state) and warns once. The old
  names are answered by a finder on ``sys.meta_path`` that knows only the names in
  :data:`MOVED`; every other import passes it by. ``kiseki/__init__`` installs it.
* Names that left a module that is still there (a split): the module sets
  ``__getattr__ = moved_names(__name__, {name: new module})``, and reading such a name from it
  gives the object of the new module and warns each time. Assigning such a name there is
  refused: it would set a copy that the code, now in the new module, never reads (a ROS bag
  limit raised by its old name changed nothing the reader checks)."""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import warnings
from collections.abc import Callable
from types import ModuleType
from typing import Any

__all__ = ["MOVED", "install", "moved_names"]

MOVED = {
    "kiseki.localization": "kiseki.filters",
    "kiseki.global_localization": "kiseki.filters",
    "kiseki.map_io": "kiseki.io.ros_map",
    "kiseki.map_schema": "kiseki.io.map_schema",
    "kiseki.trajectory_csv": "kiseki.io.trajectory_csv",
    "kiseki.sim.mcap_log": "kiseki.io.runlog",
    "kiseki.datasets.ros_orientation": "kiseki.datasets.ros_messages",
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


class _ModuleWithMovedNames(ModuleType):
    """A module some of whose names moved out (``__moved_names__``: name -> new module)."""

    def __setattr__(self, name: str, value: Any) -> None:
        new = self.__dict__.get("__moved_names__", {}).get(name)
        if new is not None:
            raise AttributeError(
                f"{self.__name__}.{name} moved to {new}.{name}; set it there (here it would "
                "change nothing)"
            )
        super().__setattr__(name, value)


def moved_names(module: str, names: dict[str, str]) -> Callable[[str], Any]:
    """The module-level ``__getattr__`` of ``module`` (PEP 562) that answers the ``names`` that
    moved out of it (name -> the module holding it now) with a DeprecationWarning, and any other
    name with the usual AttributeError. ``module`` (being imported: it calls this) refuses from
    then on an assignment of those names, naming where to set them."""
    target = sys.modules[module]
    target.__class__ = _ModuleWithMovedNames
    vars(target)["__moved_names__"] = dict(names)

    def moved_attribute(name: str) -> Any:
        if name not in names:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        new = names[name]
        warnings.warn(
            f"{module}.{name} moved to {new}.{name}; import it from there (the old name goes in "
            "the next release)",
            DeprecationWarning,
            stacklevel=2,
        )
        return getattr(importlib.import_module(new), name)

    return moved_attribute
