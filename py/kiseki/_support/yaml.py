# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""YAML read with YAML 1.2's core schema for plain scalars. PyYAML's ``safe_load`` follows YAML
1.1, which differs where a hand-written file can be silently misread: ``5e-2`` (no dot) is a
string there, ``010`` is 8, ``1:30`` is 90, ``1_000`` is 1000, ``yes``/``no``/``on``/``off``
are booleans and ``2024-01-02`` is a date. nav2's reader (yaml-cpp) and every YAML 1.2 reader
take ``5e-2`` as 0.05, ``010`` as 10 and the others as strings; so does kiseki. Only the
implicit typing of plain scalars is changed (null, bool, int and float as the 1.2 core schema
defines them; no timestamps); the rest is PyYAML's safe loader."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from kiseki._support.inputs import YAML_LIMIT, read_input_text

__all__ = ["read_yaml_file", "safe_load_12", "yaml_problem"]

_BOOL, _INT, _FLOAT, _TIMESTAMP = (
    f"tag:yaml.org,2002:{t}" for t in ("bool", "int", "float", "timestamp")
)
# YAML 1.2.2, section 10.3.2 (core schema tag resolution)
_BOOL_12 = re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$")
_INT_12 = re.compile(r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$")
_FLOAT_12 = re.compile(
    r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
    r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"
)


class _Loader12(yaml.SafeLoader):
    """SafeLoader whose plain scalars are typed as YAML 1.2's core schema types them, and whose
    mappings refuse a key given twice (YAML 1.2.2, 3.2.1.1: keys are unique): PyYAML kept the
    last one, so a scene's ``floor: true`` then ``floor: false`` read as false without a word.
    Keys that a merge (``<<``) brings in may be overridden, as YAML's merge key allows."""

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                if not isinstance(key_node, yaml.ScalarNode) or key_node.tag.endswith(":merge"):
                    continue
                key = self.construct_object(key_node)  # the value: 1 and 0x1 are one key
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        None,
                        None,
                        f"found the key {key_node.value!r} twice in one mapping (line "
                        f"{key_node.start_mark.line + 1})",
                        key_node.start_mark,
                    )
                seen.add(key)
        return super().construct_mapping(node, deep)


_Loader12.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag not in (_BOOL, _INT, _FLOAT, _TIMESTAMP)]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader12.add_implicit_resolver(_BOOL, _BOOL_12, list("tTfF"))
_Loader12.add_implicit_resolver(_INT, _INT_12, list("-+0123456789"))
_Loader12.add_implicit_resolver(_FLOAT, _FLOAT_12, list("-+0123456789."))


def _construct_int_12(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> int:
    text = loader.construct_scalar(node)
    if text.startswith(("0o", "0x")):
        return int(text[2:], 8 if text[1] == "o" else 16)
    return int(text, 10)  # "010" is ten, not YAML 1.1's eight


_Loader12.add_constructor(_INT, _construct_int_12)


def safe_load_12(text: str):
    """``yaml.safe_load`` with YAML 1.2's core schema for plain scalars (``5e-2`` and ``1E3``
    are numbers, ``010`` is 10; ``yes``, ``on``, ``1:30``, ``1_000`` and dates are strings). A
    document nested deeper than Python's recursion limit (``[[[[...``) raises a
    ``yaml.YAMLError`` like any other invalid YAML (PyYAML's parser recurses once per level)."""
    try:
        return yaml.load(text, Loader=_Loader12)  # noqa: S506 (a SafeLoader subclass)
    except RecursionError:
        raise yaml.YAMLError("nested too deeply") from None


def read_yaml_file(path, what: str):
    """A YAML file's content (YAML 1.2 core schema), or a ValueError naming the file and
    ``what`` it should be when it is not UTF-8 text or not YAML (random bytes, a binary file),
    or not a regular file of at most :data:`kiseki._support.inputs.YAML_LIMIT` bytes."""

    path = Path(path)
    try:
        return safe_load_12(read_input_text(path, "YAML files", YAML_LIMIT))
    except UnicodeDecodeError:
        raise ValueError(f"{path}: not a {what} (not UTF-8 text)") from None
    except yaml.YAMLError as err:
        raise ValueError(f"{path}: not a {what} (invalid YAML: {yaml_problem(err)})") from None


def yaml_problem(err: yaml.YAMLError) -> str:
    """A YAML error's first line (PyYAML's text runs over several: the problem, then where),
    for a message of one line."""
    return str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
