# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The command line of a benchmark that takes no options: --help prints its usage (the first
paragraph of its docstring) and any other argument is refused, instead of being ignored while
the whole benchmark runs."""

from __future__ import annotations

import argparse


def no_options(doc: str | None) -> None:
    """Parses sys.argv for a benchmark without options (exits on --help or an argument)."""
    argparse.ArgumentParser(description=(doc or "").split("\n\n")[0]).parse_args()
