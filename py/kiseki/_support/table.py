# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""How a command prints a table: a rich table on a terminal, tab-separated lines (a header,
then one row a line, never wrapped) when piped, or JSON with ``--json``."""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Sequence
from typing import Any

import typer
from rich.console import Console
from rich.table import Table


def cell(value: Any) -> str:
    """A value as a table shows it: floats to 4 significant digits, lists joined by commas."""
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list | tuple):
        return ", ".join(cell(v) for v in value)
    return str(value)


def _plain(value: Any) -> Any:
    """JSON-safe: numpy scalars as Python numbers, NaN and infinities as null."""
    if hasattr(value, "item") and not isinstance(value, list | tuple | dict):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


def show(
    title: str,
    columns: Sequence[str],
    rows: Sequence[Sequence[Any]],
    *,
    as_json: bool,
    data: Any,
    console: Console | None = None,
) -> None:
    """Print ``rows`` under ``columns`` for people, or ``data`` (the same numbers) as JSON."""
    if as_json:
        typer.echo(json.dumps(_plain(data), indent=2))
    elif not sys.stdout.isatty():
        for row in (columns, *rows):
            typer.echo("\t".join(" ".join(cell(v).split()) for v in row))
    else:
        table = Table(title=title)
        for i, column in enumerate(columns):
            table.add_column(column, justify="left" if i == 0 else "right")
        for row in rows:
            table.add_row(*(cell(v) for v in row))
        (console or Console()).print(table)


def show_fields(
    title: str, fields: dict[str, Any], *, as_json: bool, console: Console | None = None
) -> None:
    """A record as a two-column table (field, value), or as one JSON object."""
    show(
        title,
        ("field", "value"),
        list(fields.items()),
        as_json=as_json,
        data=fields,
        console=console,
    )
