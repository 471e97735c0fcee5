# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""YAML read with YAML 1.2's numbers: PyYAML's ``safe_load`` follows YAML 1.1, which reads
``5e-2`` (no dot) as a string; nav2's reader (yaml-cpp, YAML 1.2) reads it as 0.05. Only that
difference is bridged: every plain scalar that is a YAML 1.2 core-schema float becomes a float."""

from __future__ import annotations

import re

import yaml

__all__ = ["read_yaml_file", "safe_load_12"]

_FLOAT_12 = re.compile(r"^[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?$")


class _Loader12(yaml.SafeLoader):
    """SafeLoader with YAML 1.2's float pattern added after YAML 1.1's int and float ones."""


_Loader12.add_implicit_resolver("tag:yaml.org,2002:float", _FLOAT_12, list("-+0123456789."))


def safe_load_12(text: str):
    """``yaml.safe_load`` with YAML 1.2 floats (``5e-2``, ``1E3``) read as numbers. A document
    nested deeper than Python's recursion limit (``[[[[...``) raises a ``yaml.YAMLError`` like
    any other invalid YAML (PyYAML's parser recurses once per level)."""
    try:
        return yaml.load(text, Loader=_Loader12)  # noqa: S506 (a SafeLoader subclass)
    except RecursionError:
        raise yaml.YAMLError("nested too deeply") from None


def read_yaml_file(path, what: str):
    """A YAML file's content (YAML 1.2 numbers), or a ValueError naming the file and ``what`` it
    should be when it is not UTF-8 text or not YAML (random bytes, a binary file)."""
    from pathlib import Path

    path = Path(path)
    try:
        return safe_load_12(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a {what} (not UTF-8 text)") from None
    except yaml.YAMLError as err:
        first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ValueError(f"{path}: not a {what} (invalid YAML: {first})") from None
