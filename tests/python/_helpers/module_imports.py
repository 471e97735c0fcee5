# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What the house-layout tests (tests/python/layout) read of the source: the modules of a
package folder and the names each imports, with kiseki's and kiseki_experiments' folders,
and a writer of small packages for the checks' own tests."""

from __future__ import annotations

import ast
from pathlib import Path

import kiseki
import kiseki_experiments

PACKAGE = Path(kiseki.__file__).resolve().parent
EXPERIMENTS = Path(kiseki_experiments.__file__).resolve().parent


def modules_in(folder: Path) -> list[tuple[str, Path, bool]]:
    """(module name, file, whether it is a package's __init__) of every module in `folder`."""
    out = []
    for path in sorted(folder.rglob("*.py")):
        parts = path.relative_to(folder.parent).with_suffix("").parts
        is_package = parts[-1] == "__init__"
        out.append((".".join(parts[:-1] if is_package else parts), path, is_package))
    return out


def imported_names(source: str, module: str, is_package: bool = False) -> list[tuple[int, str]]:
    """(line, dotted name) of every import in `source` (the text of module `module`), at any
    depth (inside functions too), relative imports resolved: ``import a.b`` gives ``a.b``,
    ``from a.b import c`` gives ``a.b.c`` (c a module or any other name), ``from a.b import *``
    gives ``a.b``, and ``importlib.import_module("a.b")`` (or ``__import__``) gives ``a.b``."""
    package = module if is_package else module.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[: len(parts) - (node.level - 1)]
                base = ".".join(parts + ([base] if base else []))
            found += [
                (node.lineno, base if alias.name == "*" else f"{base}.{alias.name}")
                for alias in node.names
            ]
        elif (
            isinstance(node, ast.Call)
            and getattr(node.func, "attr", getattr(node.func, "id", None))
            in ("import_module", "__import__")
            and node.args
            and isinstance(node.args[0], ast.Constant)
            and isinstance(node.args[0].value, str)
        ):
            found.append((node.lineno, node.args[0].value))
    return found


def is_the_cli(module: str) -> bool:
    """kiseki's command line (the ``kiseki.cli`` package): an app like the experiments, the one
    part of py/kiseki that may run them."""
    return module == "kiseki.cli" or module.startswith("kiseki.cli.")


def write_files(root: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text, encoding="utf-8")
