# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The house layout (DESIGN.md): imports inside functions say why, and a library file holds
one concept, at most 400 lines but for the few listed with their reason."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from _helpers.module_imports import EXPERIMENTS, PACKAGE, modules_in, write_files


def unexplained_function_imports(source: str) -> list[int]:
    """The lines of the imports inside a function or method in `source` that no comment
    explains. An import inside a function postpones loading a module and nothing else (it is
    still a dependency); its one reason is start-up time (``import kiseki``, ``kiseki --help``
    or a package's own import staying fast), which a comment on its line or on the lines just
    above it says."""
    lines = source.splitlines()
    found = set()
    for function in ast.walk(ast.parse(source)):
        if not isinstance(function, ast.FunctionDef | ast.AsyncFunctionDef):
            continue
        for node in ast.walk(function):
            if not isinstance(node, ast.Import | ast.ImportFrom):
                continue
            above = node.lineno - 2
            while above >= 0 and lines[above].strip().startswith("import "):
                above -= 1  # a group of imports under one comment
            while above >= 0 and lines[above].strip().startswith("from "):
                above -= 1
            commented = "#" in lines[node.lineno - 1] or (
                above >= 0 and lines[above].strip().startswith("#")
            )
            if not commented:
                found.add(node.lineno)
    return sorted(found)


def test_the_function_import_check_finds_what_it_should():
    bare = "def f():\n    from kiseki.mapping import scan_local_map\n    return 1\n"
    assert unexplained_function_imports(bare) == [2]
    method = "class A:\n    def f(self):\n        import scipy.io\n"
    assert unexplained_function_imports(method) == [3]
    same_line = "def f():\n    import scipy.io  # here: scipy is slow to load\n"
    assert unexplained_function_imports(same_line) == []
    above = (
        "def f():\n    # here, not at the top: matplotlib is slow to load\n"
        "    from matplotlib.axes import Axes\n    from matplotlib.figure import Figure\n"
    )
    assert unexplained_function_imports(above) == []
    assert unexplained_function_imports("import os\n\n\ndef f():\n    return os\n") == []


@pytest.mark.parametrize(
    ("folder", "at_least"),
    [(PACKAGE, 100), (EXPERIMENTS, 50)],
    ids=["kiseki", "kiseki_experiments"],
)
def test_imports_inside_functions_say_why(folder, at_least):
    """py/kiseki, the library and its apps, imports at the top of its modules; the few imports
    left inside functions keep a start-up fast and say so. The command line's root loads a
    command's module by name (``importlib``, not an import statement) so that ``kiseki --help``
    stays fast; its command modules import at their tops. py/kiseki_experiments does the same:
    ``kiseki experiment list`` imports every experiment module through the registry, so what
    an experiment imports at its top every ``kiseki experiment`` command loads."""
    found = []
    counted = 0
    for module, path, _ in modules_in(folder):
        counted += 1
        found += [f"{module}:{line}" for line in unexplained_function_imports(path.read_text())]
    assert counted > at_least
    assert found == []


# A library file holds one concept; past this many lines it is usually two. The files allowed
# over it, and why, each of which says so in its module docstring ("Why one file over 400
# lines: ...").
LINE_LIMIT = 400
LONG_FILES: dict[str, str] = {}


def long_files(folder: Path, limit: int = LINE_LIMIT) -> dict[str, int]:
    """The files of the package in `folder` over `limit` lines (path relative to `folder`:
    lines)."""
    out = {}
    for _, path, _ in modules_in(folder):
        lines = len(path.read_text(encoding="utf-8").splitlines())
        if lines > limit:
            out[path.relative_to(folder).as_posix()] = lines
    return out


def test_the_long_file_check_finds_what_it_should(tmp_path):
    write_files(
        tmp_path,
        {
            "kiseki/__init__.py": "",
            "kiseki/short.py": "x = 1\n" * 400,
            "kiseki/long.py": "x = 1\n" * 401,
            "kiseki/cli/long.py": "x = 1\n" * 900,
            "kiseki/area/long.py": "x = 1\n" * 500,
        },
    )
    assert long_files(tmp_path / "kiseki") == {
        "long.py": 401,
        "area/long.py": 500,
        "cli/long.py": 900,
    }


def test_no_library_file_is_long_unless_listed_and_each_listed_says_why():
    assert len(LONG_FILES) <= 5
    long = long_files(PACKAGE)
    assert sorted(set(long) - set(LONG_FILES)) == []
    # a file that got short leaves the list, so the list stays the truth
    assert sorted(set(LONG_FILES) - set(long)) == []
    for name in LONG_FILES:
        docstring = ast.get_docstring(ast.parse((PACKAGE / name).read_text())) or ""
        assert "Why one file over 400 lines:" in docstring, name
