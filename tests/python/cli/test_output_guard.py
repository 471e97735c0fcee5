# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue 27, item 1: one output guard that every command goes through (kiseki._support.guard).

Every command of the typer app, found by walking it (25 today, and any added later), carries
the guard, and each of its path parameters is declared as an input, an output or an output
folder: a new output option without a declaration fails here. Then the defects a user found,
run as a user would (``python -m kiseki.cli``), inputs compared by SHA-256 before and after:
each is one line ``kiseki: error: ...`` naming the option and the file, exit status 1, before
any work (test_output_guard_defects.py). Last, the guard's rules on their own, in this process
(test_output_guard_rules.py), and links, large YAML inputs and outputs that are no regular
file (test_output_guard_links.py)."""

from __future__ import annotations

import pathlib
import typing


def _commands(group=None, path=()):
    import typer.main

    from kiseki.cli import app

    group = typer.main.get_command(app) if group is None else group
    ctx = typer.Context(group)  # the root loads its groups on request: asked through click's API
    for name in sorted(group.list_commands(ctx)):
        sub = group.get_command(ctx, name)
        if hasattr(sub, "commands"):
            yield from _commands(sub, (*path, name))
        else:
            yield " ".join((*path, name)), sub


def _is_path(param) -> bool:
    """Whether a click parameter takes paths (Path, Path | None, list[Path]): typer's own
    descriptor of the annotation, or click's Path type."""
    descriptor = getattr(param, "type_descriptor", None)
    if descriptor is None:
        import click

        return isinstance(getattr(param, "type", None), click.Path)
    kinds = typing.get_args(descriptor.annotation) or (descriptor.annotation,)
    return any(isinstance(k, type) and issubclass(k, pathlib.PurePath) for k in kinds)


def test_every_command_is_guarded_and_declares_each_path_parameter():
    from kiseki._support.guard import guard_of

    problems, seen = [], 0
    for words, command in _commands():
        seen += 1
        spec = guard_of(command.callback)
        if spec is None:
            problems.append(f"kiseki {words}: no @guarded(...) (kiseki._support.guard)")
            continue
        paths = {p.name for p in command.params if _is_path(p)}
        roles = {r: spec.params(r) for r in ("inputs", "outputs", "output_folders")}
        declared = set().union(*roles.values())
        for name in sorted(paths - declared):
            problems.append(f"kiseki {words}: path parameter {name!r} is not declared")
        for name in sorted(declared - paths):
            problems.append(f"kiseki {words}: {name!r} is declared but takes no path")
        twice = [n for n in declared if sum(n in names for names in roles.values()) > 1]
        problems += [f"kiseki {words}: {n!r} has two roles" for n in twice]
    assert seen >= 25, seen  # the walk reaches every group (map, sim, magnetic, terrain, ...)
    assert not problems, "\n".join(problems)
