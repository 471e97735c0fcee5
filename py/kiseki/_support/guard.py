# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The output guard every command goes through. ``@guarded(...)``, placed under
``@app.command(...)``, declares which of the command's parameters are inputs, output files and
output folders (and the files it writes or reads that no option names), records that
declaration on the command (:data:`SPEC_ATTRIBUTE`, a :class:`GuardSpec`, so that a test can
check that every path parameter of every command is declared) and, before the command's body
runs, refuses in one line whatever would let an output destroy an input: the rules are
:func:`kiseki._support.outputs.check_outputs`'s. Labels are the ones the user typed: an option's
long name (``--output``), an argument's metavar (``MAP``).

A file written beside an output (a result's config, a map's image) that is already there while
that output is not is no earlier output of the command: it is refused too, and kept.

Checks that need the work's own results (the scene a recorded run names, read from the run)
stay in the command, through :func:`~kiseki._support.outputs.check_outputs` itself.

What the guard lets through is written whole or not at all (:mod:`kiseki._support.atomic`: a
temporary file in the same folder, renamed), save the MCAP logs that runs stream as they go (``sim
run``, ``teach``'s ``teach.mcap``, ``playback --log``, ``magnetic navigate``'s ``run.mcap``): those
are closed properly when interrupted, so that what was recorded stays readable (``teach
--resume`` rebuilds from it), and an existing one is replaced only with ``--overwrite`` (or
is the command's own, in its output folder)."""

from __future__ import annotations

import functools
import inspect
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from kiseki._support.outputs import check_outputs

__all__ = [
    "SPEC_ATTRIBUTE",
    "Derived",
    "Folder",
    "GuardSpec",
    "Rewrites",
    "guard_of",
    "guarded",
]

SPEC_ATTRIBUTE = "__kiseki_guard__"
_F = TypeVar("_F", bound=Callable[..., Any])


@dataclass(frozen=True)
class Derived:
    """A file that no option names, made from the command's arguments (a map YAML's image, a
    result's config beside it): ``label`` and ``path(arguments)``, None when not this time.
    As an output it is written beside the output parameter ``beside`` names: one already there
    while that output is not is no earlier output of the command, and is not replaced."""

    label: str
    path: Callable[[Mapping[str, Any]], Path | None]
    beside: str = "output"


@dataclass(frozen=True)
class Folder:
    """An output folder: the parameter naming it and the files the command writes in it, as
    glob patterns relative to it (``**``: anything, all through it, or the folder replaced
    whole). An input inside the folder is refused when the command writes it."""

    param: str
    writes: tuple[str, ...] = ("**",)


@dataclass(frozen=True)
class Rewrites:
    """An input folder that the command also rewrites files of, in place (kiseki serve: the
    taught run's waypoint file and route history): the parameter naming it and the files, as
    glob patterns relative to it, where an output option may point."""

    param: str
    files: tuple[str, ...]


@dataclass(frozen=True)
class GuardSpec:
    """A command's declaration: parameter names (and :class:`Derived` files) by role, and the
    label of each parameter."""

    inputs: tuple[str | Rewrites | Derived, ...]
    outputs: tuple[str | Derived, ...]
    output_folders: tuple[Folder, ...]
    labels: Mapping[str, str]

    def params(self, role: str) -> set[str]:
        """The parameter names declared as ``inputs``, ``outputs`` or ``output_folders``."""
        items = [i for i in getattr(self, role) if not isinstance(i, Derived)]
        return {i if isinstance(i, str) else i.param for i in items}

    def check(self, arguments: Mapping[str, Any]) -> None:
        """Raises (ValueError, OSError) as :func:`check_outputs` does for these arguments, and
        FileExistsError for a derived output already there beside an output that is not (a
        user's run.config.yaml beside a run.csv to come), checked after the inputs' rules (a
        derived output that is an input is refused as that)."""
        check_outputs(
            self._paths(self.outputs, arguments),
            self._paths(self.inputs, arguments),
            {
                self.labels[f.param]: (_path_of(arguments.get(f.param)), f.writes)
                for f in self.output_folders
            },
            {self.labels[i.param]: i.files for i in self.inputs if isinstance(i, Rewrites)},
        )
        self._refuse_orphans(arguments)

    def _refuse_orphans(self, arguments: Mapping[str, Any]) -> None:
        for item in self.outputs:
            if not isinstance(item, Derived) or item.beside not in self.labels:
                continue
            named, path = _path_of(arguments.get(item.beside)), _derived_path(item, arguments)
            if named is None or path is None or named.exists():
                continue
            if path.exists() or path.is_symlink():
                label = self.labels[item.beside]
                raise FileExistsError(
                    f"{item.label} {path} exists and {label} {named} does not: it is no earlier "
                    f"output of this command, and is not replaced: give another {label}, or "
                    f"move {path.name}"
                )

    def _paths(self, items, arguments: Mapping[str, Any]) -> dict[str, list[Path]]:
        out: dict[str, list[Path]] = {}
        for item in items:
            if isinstance(item, Rewrites):
                item = item.param
            if isinstance(item, Derived):
                path = _derived_path(item, arguments)
                label, paths = item.label, [] if path is None else [path]
            else:
                label, paths = self.labels[item], _paths_of(arguments.get(item))
            out.setdefault(label, []).extend(paths)
        return out


def _derived_path(item: Derived, arguments: Mapping[str, Any]) -> Path | None:
    """A derived file's path for these arguments, None when not this time or when the arguments
    cannot make one (with_suffix of '.', an argument missing in a direct call: the command's
    body reports it)."""
    try:
        path = item.path(arguments)
    except (AttributeError, KeyError, TypeError, ValueError):
        return None
    return None if path is None else Path(path)


def _path_of(value: Any) -> Path | None:
    return Path(value) if isinstance(value, str | os.PathLike) else None


def _paths_of(value: Any) -> list[Path]:
    """The paths a parameter holds: one, a list (``list[Path]``), or none (None, or a default
    that is still typer's OptionInfo when the function is called directly)."""
    if isinstance(value, list | tuple):
        return [Path(v) for v in value if isinstance(v, str | os.PathLike)]
    path = _path_of(value)
    return [] if path is None else [path]


def _label(name: str, default: Any) -> str:
    """What the user typed for a parameter: an option's first long name, an argument's metavar
    (without an extension: ``WALK.mat`` is WALK), else the name as typer spells it."""
    decls = [d for d in getattr(default, "param_decls", None) or () if d.startswith("-")]
    if decls:
        return next((d for d in decls if d.startswith("--")), decls[0])
    if type(default).__name__ == "ArgumentInfo":
        metavar = getattr(default, "metavar", None)
        return metavar.split(".")[0] if metavar else name.upper()
    return "--" + name.replace("_", "-")


def guarded(
    *,
    inputs: Sequence[str | Rewrites | Derived] = (),
    outputs: Sequence[str | Derived] = (),
    output_folders: Sequence[str | Folder] = (),
) -> Callable[[_F], _F]:
    """Decorates a CLI command (directly under ``@app.command``): ``inputs`` and ``outputs``
    are parameter names (or :class:`Derived` files; an input folder that the command also
    rewrites in place, :class:`Rewrites`), ``output_folders`` parameter names (the command
    writes anything in them) or :class:`Folder` with the files written. A command
    with no path at all still takes ``@guarded()``, so that every command is declared. Names
    that are not parameters of the command raise TypeError when the module is imported."""

    def wrap(command: _F) -> _F:
        signature = inspect.signature(command)
        folders = tuple(f if isinstance(f, Folder) else Folder(f) for f in output_folders)
        names = [i if isinstance(i, str) else i.param for i in (*inputs, *outputs, *folders)
                 if not isinstance(i, Derived)]  # fmt: skip
        unknown = [n for n in names if n not in signature.parameters]
        if unknown:
            raise TypeError(f"{command.__name__}: guarded names no parameter {unknown}")
        labels = {n: _label(n, signature.parameters[n].default) for n in names}
        spec = GuardSpec(tuple(inputs), tuple(outputs), folders, labels)

        @functools.wraps(command)
        def run(*args: Any, **kwargs: Any) -> Any:
            bound = signature.bind_partial(*args, **kwargs)
            spec.check(bound.arguments)
            return command(*args, **kwargs)

        setattr(run, SPEC_ATTRIBUTE, spec)
        return run  # type: ignore[return-value]

    return wrap


def guard_of(callback: Callable[..., Any] | None) -> GuardSpec | None:
    """The guard declared on a command's callback (or on a function it wraps), or None."""
    while callback is not None:
        spec = getattr(callback, SPEC_ATTRIBUTE, None)
        if isinstance(spec, GuardSpec):
            return spec
        callback = getattr(callback, "__wrapped__", None)
    return None
