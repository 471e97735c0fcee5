# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Ctrl-C (SIGINT) and SIGTERM during a long command: the command stops through its cleanup
(temporary files removed, files being written closed) and says in one line what it left: the
files it had completely written before the interruption, or that it wrote none. kiseki writes
every file whole or not at all (:mod:`kiseki._support.atomic`), so nothing partial is ever left.
Exit status 130 after SIGINT, 143 after SIGTERM (128 + the signal, as shells report them)."""

from __future__ import annotations

import functools
import signal
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import typer

from kiseki._support.atomic import written_files

__all__ = ["interruptible", "left_behind"]

_F = TypeVar("_F", bound=Callable[..., Any])
_SIGTERM_EXIT = 128 + signal.SIGTERM


def left_behind(files: list[Path], hint: str = "") -> str:
    """The one line an interrupted command prints: what it had written, and ``hint``."""
    if not files:
        text = "interrupted before any output was written (no partial file is left)"
    elif len(files) <= 3:
        text = f"interrupted; written completely before it: {', '.join(map(str, files))}"
    else:
        text = (
            f"interrupted; {len(files)} files were written completely before it "
            f"({files[0]} ... {files[-1]})"
        )
    if files:
        text += "; no partial file is left"
    return f"kiseki: {text}{'; ' + hint if hint else ''}"


def interruptible(hint: str = "") -> Callable[[_F], _F]:
    """Decorates a CLI command (below ``@app.command``): an interruption prints
    :func:`left_behind` (with ``hint``, e.g. how to resume) and exits 130 or 143."""

    def wrap(command: _F) -> _F:
        @functools.wraps(command)
        def run(*args: Any, **kwargs: Any) -> Any:
            before = len(written_files())
            try:
                return command(*args, **kwargs)
            except KeyboardInterrupt:
                code = 130
            except SystemExit as stop:  # SIGTERM, raised by the CLI's handler
                if stop.code != _SIGTERM_EXIT:
                    raise
                code = _SIGTERM_EXIT
            typer.echo(left_behind(written_files()[before:], hint), err=True)
            raise typer.Exit(code)

        return run  # type: ignore[return-value]

    return wrap
