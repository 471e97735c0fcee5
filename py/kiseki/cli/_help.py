# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Help texts that reflow to the terminal's width.

The docstrings wrap at the source's 100 columns; typer's rich formatter keeps a single line
break inside a paragraph (in the command listing and after the first paragraph), so the help
broke mid-sentence on a wide terminal. Each paragraph becomes one line here and rich wraps it.
"""

from __future__ import annotations

import inspect

__all__ = ["reflow", "reflow_all"]


def reflow(text: str | None) -> str | None:
    """``text`` with each paragraph (blocks separated by a blank line) on one line; a paragraph
    marked ``\\b`` (click's "keep my line breaks") is kept as written."""
    if not text:
        return text
    paragraphs = inspect.cleandoc(text).split("\n\n")
    return "\n\n".join(
        p if p.startswith("\b") else " ".join(line.strip() for line in p.splitlines())
        for p in paragraphs
    )


def reflow_all(command):
    """``command`` and, for a group, every command below it, their help texts reflowed."""
    command.help = reflow(command.help)
    for sub in getattr(command, "commands", {}).values():
        reflow_all(sub)
    return command
