# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What an output folder already holds that a command would replace. The output guard
(:mod:`kiseki._support.guard`) keeps a command's outputs off its inputs; this keeps them off a
user's other files: a command that writes ``config.yaml`` into ``-o .`` must not replace the
``config.yaml`` the user keeps there. A command replaces the files of an output folder only when
the user says so (an ``--overwrite`` or ``--resume``) or when the folder is its own earlier
output (each command says how it knows its own); otherwise it refuses before any work, in one
line naming the folder and the first file it would replace."""

from __future__ import annotations

import glob
import os
from collections.abc import Sequence
from pathlib import Path

__all__ = ["existing_outputs", "first_of", "refuse_replacing"]


def existing_outputs(folder: str | os.PathLike, patterns: Sequence[str]) -> list[Path]:
    """The entries of ``folder`` that match ``patterns`` (glob patterns relative to it, as the
    guard's :class:`~kiseki._support.guard.Folder` declares them; ``name/`` or ``name`` for a
    sub-folder matches the sub-folder), in pattern order and then by name; links are entries
    too (a broken one as well: the command would replace it)."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    found: list[Path] = []
    for pattern in patterns:
        escaped = glob.escape(str(folder))
        # glob lists a broken link too (os.path.lexists for a literal name, listdir for a
        # pattern): the command would replace it (tested)
        for match in sorted(glob.glob(os.path.join(escaped, pattern.rstrip("/")))):
            path = Path(match)
            if path not in found:
                found.append(path)
    return found


def refuse_replacing(
    folder: str | os.PathLike,
    patterns: Sequence[str],
    label: str,
    remedy: str,
    error: type[Exception] = FileExistsError,
) -> None:
    """Raises ``error`` when ``folder`` holds an entry the command would write (``patterns``):
    '``label`` FOLDER holds NAME (and K more), which this command would replace: ``remedy``'."""
    found = existing_outputs(folder, patterns)
    if found:
        names = [str(p.relative_to(Path(folder))) for p in found]
        raise error(
            f"{label} {folder} holds {first_of(names)}, which this command would replace: {remedy}"
        )


def first_of(names: Sequence[str]) -> str:
    """'NAME' or 'NAME (and K more)': the entries an output folder's refusal names."""
    return names[0] + (f" (and {len(names) - 1} more)" if len(names) > 1 else "")
