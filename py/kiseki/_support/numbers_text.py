# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Numbers written as text in the data files kiseki reads (logs, maps, tables, point clouds).

Python's ``int()`` and ``float()``, and numpy's conversion of ``str`` to numbers, also take PEP
515 underscores between digits (``1_0`` is 10) and the digits of other scripts (full-width
``１０``, Arabic-Indic ``١٠``: 10). None of the formats read here allows either, and the tools
that write and read them (C's ``strtod``, ``strtol``) stop at them, so here a token holding one
is not a number: a number is ASCII without an underscore. The readers name the file, the line
and the token.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["NumberTextError", "float_array", "is_number", "parse_float", "parse_int"]


class NumberTextError(ValueError):
    """A token of :func:`float_array` that is not a number: ``row`` is the index of its row in
    a table (of the token itself in a flat list), ``token`` the token as written."""

    def __init__(self, row: int, token: str) -> None:
        super().__init__(f"{token!r} is not a number")
        self.row = row
        self.token = token


def _plain(text: str) -> bool:
    """ASCII without an underscore: what a number of these formats may be written with."""
    return text.isascii() and "_" not in text


def parse_int(token: str) -> int:
    """The decimal integer ``token``; ValueError when it is not one (``1_0`` is not)."""
    if not _plain(token):
        raise ValueError(f"{token!r} is not an integer")
    return int(token)


def parse_float(token: str) -> float:
    """The number ``token`` as ``float()`` reads it; ValueError when it is not one (``1_0``
    is not)."""
    if not _plain(token):
        raise ValueError(f"{token!r} is not a number")
    return float(token)


def is_number(token: str) -> bool:
    """Whether :func:`parse_float` reads ``token``."""
    try:
        parse_float(token)
    except ValueError:
        return False
    return True


def float_array(tokens: Sequence[Sequence[str]] | Sequence[str]) -> np.ndarray:
    """The float64 array of a table of number tokens (rows of equal length) or of a flat list
    of them. :class:`NumberTextError` names the first token that is not a number; rows of unequal
    length raise numpy's ValueError. The underscore test runs on each row's joined text (on the
    whole list's for a flat list), not token by token: a large log stays fast to read."""
    flat = len(tokens) > 0 and isinstance(tokens[0], str)
    rows: Sequence[Sequence[str]] = [tokens] if flat else tokens  # type: ignore[list-item]
    if all(_plain("".join(row)) for row in rows):
        try:
            return np.array(tokens, dtype=np.float64)
        except ValueError:
            pass  # the token is found below
    for k, row in enumerate(rows):
        for j, token in enumerate(row):
            if not is_number(token):
                raise NumberTextError(j if flat else k, token)
    return np.array(tokens, dtype=np.float64)  # every token a number: ragged rows
