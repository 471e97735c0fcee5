# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The root command as a group that loads each command's module only when that command runs.

A table names each command, the module holding it (a typer app named ``app``) and its one-line
help; ``kiseki --help`` lists the table without importing any command, and ``kiseki NAME`` imports
only NAME's module. Old names are hidden aliases: they warn once and run the new command.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

import typer
from typer.core import TyperCommand, TyperGroup

from kiseki.cli._help import reflow_all

__all__ = ["Alias", "Entry", "LazyGroup"]


@dataclass(frozen=True)
class Entry:
    """A command of the root: the module with its typer ``app``, its line in the listing, and
    whether it is a group of commands (``kiseki speed limits``) or one (``kiseki teach``)."""

    module: str
    help: str
    group: bool = True


@dataclass(frozen=True)
class Alias:
    """An old name that still runs for one release: the words of the command it became."""

    new: tuple[str, ...]


class LazyGroup(TyperGroup):
    """The root group; its subclass sets ``table`` (name -> Entry, in listing order) and
    ``aliases`` (old name -> Alias)."""

    table: dict[str, Entry] = {}
    aliases: dict[str, Alias] = {}

    def list_commands(self, ctx: typer.Context) -> list[str]:
        return list(self.table)  # the aliases stay hidden: not listed

    def get_command(self, ctx: typer.Context, cmd_name: str):
        if cmd_name in self.aliases:
            return _AliasCommand(cmd_name, self.aliases[cmd_name].new, self)
        entry = self.table.get(cmd_name)
        if entry is None:
            return None
        # the one deferred import of the command line: importing only the module of the command
        # that runs keeps `kiseki --help` and each command's start-up fast
        module = importlib.import_module(entry.module)
        # a group stays a group with one command (typer would make it that command)
        command = (typer.main.get_group if entry.group else typer.main.get_command)(module.app)
        command.name = cmd_name
        return reflow_all(command)

    def format_help(self, ctx: typer.Context, formatter) -> None:
        """The help of the root, its commands listed from the table: nothing is imported."""
        listing = TyperGroup(
            name=self.name,
            commands=[TyperCommand(name=n, help=e.help) for n, e in self.table.items()],
            params=self.params,
            help=self.help,
            rich_markup_mode=self.rich_markup_mode,
        )
        listing.format_help(ctx, formatter)


class _AliasCommand(TyperCommand):
    """A hidden old name: one warning line on stderr, then the new command parses the same
    arguments and runs (so its exit status is the new command's)."""

    def __init__(self, old: str, new: tuple[str, ...], root: LazyGroup) -> None:
        super().__init__(name=old, hidden=True, help=f"Deprecated: kiseki {' '.join(new)}.")
        self.new, self.root = new, root

    def make_context(self, info_name, args, parent=None, **extra):
        new = " ".join(self.new)
        typer.echo(
            f"kiseki: warning: 'kiseki {self.name}' is deprecated; use 'kiseki {new}'", err=True
        )
        head = self.root.get_command(parent, self.new[0])
        return head.make_context(self.new[0], [*self.new[1:], *args], parent=parent, **extra)
