# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Outputs never destroy inputs: before a command starts its work, its output files (and the
files written beside them) are compared with its input files (and the files they refer to, such
as a ROS map YAML's image), paths resolved through symlinks and relative parts, and every
output folder is checked to exist and be writable."""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from functools import cached_property
from pathlib import Path

import yaml

from kiseki._yaml import safe_load_12

__all__ = ["FIGURE_SUFFIXES", "check_outputs", "check_suffix", "files_behind"]


class _FigureSuffixes(Sequence[str]):
    """The extensions matplotlib's ``savefig`` writes (it chooses the format by extension),
    matplotlib's own list, sorted: read on first use, since importing matplotlib takes about
    0.3 s and ``import kiseki.cli`` does not otherwise need it."""

    @cached_property
    def _suffixes(self) -> tuple[str, ...]:
        from matplotlib.backend_bases import FigureCanvasBase

        return tuple(sorted(f".{ext}" for ext in FigureCanvasBase.get_supported_filetypes()))

    def __getitem__(self, index):  # type: ignore[override]
        return self._suffixes[index]

    def __len__(self) -> int:
        return len(self._suffixes)

    def __repr__(self) -> str:
        return repr(self._suffixes)


FIGURE_SUFFIXES: Sequence[str] = _FigureSuffixes()


def files_behind(path: Path) -> list[Path]:
    """The file itself and the files it refers to: for a ROS map YAML, its image."""
    out = [path]
    if path.suffix.lower() in (".yaml", ".yml") and path.is_file():
        try:
            doc = safe_load_12(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            return out  # the reader itself reports what is wrong with it
        if isinstance(doc, dict) and isinstance(doc.get("image"), str) and doc["image"]:
            image = Path(doc["image"])
            out.append(image if image.is_absolute() else path.parent / image)
    return out


def _same(a: Path, b: Path) -> bool:
    if a.exists() and b.exists():
        try:
            return os.path.samefile(a, b)  # hard links and symlinks alike
        except OSError:
            pass
    return a.resolve() == b.resolve()


def check_outputs(
    outputs: Mapping[str, Path | Iterable[Path] | None],
    inputs: Mapping[str, Path | None],
) -> None:
    """Raises ValueError naming both when an output is one of the inputs or a file an input
    refers to, or when two outputs are one file; FileNotFoundError / PermissionError when an
    output's folder is missing or not writable. ``outputs``: label -> path, or the paths one
    option writes (a map YAML and its image); ``inputs``: label -> path."""
    written: list[tuple[str, Path]] = []
    for label, value in outputs.items():
        if value is None:
            continue
        for path in [value] if isinstance(value, Path) else list(value):
            written.append((label, Path(path)))
    read: list[tuple[str, Path]] = []
    for label, path in inputs.items():
        if path is not None:
            read += [(label if p == path else f"{label}'s image", p) for p in files_behind(path)]
    for label, out in written:
        for in_label, src in read:
            if _same(out, src):
                raise ValueError(f"{label} {out} would overwrite the input {in_label} {src}")
    for i, (label, out) in enumerate(written):
        for other_label, other in written[i + 1 :]:
            if _same(out, other):
                raise ValueError(f"{label} {out} and {other_label} {other} are the same file")
    for label, out in written:
        folder = out.parent if str(out.parent) else Path(".")
        if not folder.is_dir():
            raise FileNotFoundError(f"{label} {out}: folder {folder} does not exist")
        if not os.access(folder, os.W_OK | os.X_OK):
            raise PermissionError(f"{label} {out}: folder {folder} is not writable")


def check_suffix(label: str, path: Path | None, suffixes: Sequence[str]) -> None:
    """Raises ValueError naming the output when its extension is not one of ``suffixes`` (the
    writers choose the format by extension; without this check the error named a temporary
    file, after the work)."""
    if path is not None and path.suffix.lower() not in suffixes:
        got = f"extension {path.suffix!r}" if path.suffix else "no extension"
        raise ValueError(f"{label} {path}: {got}; give a file ending in {', '.join(suffixes)}")
    if path is not None and path.suffix.lower() == ".pgf" and suffixes is FIGURE_SUFFIXES:
        _check_tex(label, path)


def _check_tex(label: str, path: Path) -> None:
    """matplotlib's pgf backend measures text with a LaTeX engine (``pgf.texsystem``, xelatex
    by default): without one installed a .pgf figure fails after all the work, so it is refused
    before."""
    import shutil

    from matplotlib import rcParams

    engine = rcParams["pgf.texsystem"]
    if shutil.which(engine) is None:
        raise ValueError(
            f"{label} {path}: a .pgf figure needs {engine} (a LaTeX engine, matplotlib's "
            "pgf.texsystem), which is not installed; give .pdf, .svg or .png"
        )
