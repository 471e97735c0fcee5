# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Outputs never destroy inputs: before a command starts its work, its output files (and the
files written beside them) are compared with its input files (and the files they refer to, such
as a ROS map YAML's image), paths resolved through symlinks and relative parts, and every
output folder is checked to exist and be writable. kiseki writes a file by renaming a new one
onto its path (:mod:`kiseki._support.atomic`), so an output must be a regular file or nothing yet:
one that is a device, a FIFO or a socket (``-o /dev/null``) is refused, and so is an output that is
a symlink, whatever it points to (the rename would replace the link, not the file it points
to): give that file instead. :func:`check_outputs` holds the rules; :mod:`kiseki._support.guard`
applies them to every command from its declared parameters."""

from __future__ import annotations

import collections
import functools
import glob
import os
import shutil
import stat
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from fnmatch import fnmatchcase
from functools import cached_property
from pathlib import Path

from kiseki._support.atomic import check_writable_folder
from kiseki._support.input_refs import (
    WALK_DEPTH,
    WALK_ENTRIES,
    input_files,
    input_folder,
)
from kiseki._support.inputs import special_kind

__all__ = [
    "FIGURE_SUFFIXES",
    "check_outputs",
    "check_suffix",
]


class _FigureSuffixes(Sequence[str]):
    """The extensions matplotlib's ``savefig`` writes (it chooses the format by extension),
    matplotlib's own list, sorted: read on first use, since importing matplotlib takes about
    0.3 s and ``import kiseki.cli`` does not otherwise need it."""

    @cached_property
    def _suffixes(self) -> tuple[str, ...]:
        from matplotlib.backend_bases import FigureCanvasBase  # here: see the docstring

        return tuple(sorted(f".{ext}" for ext in FigureCanvasBase.get_supported_filetypes()))

    def __getitem__(self, index):  # type: ignore[override]
        return self._suffixes[index]

    def __len__(self) -> int:
        return len(self._suffixes)

    def __repr__(self) -> str:
        return repr(self._suffixes)


FIGURE_SUFFIXES: Sequence[str] = _FigureSuffixes()


def _of(label: str, what: str) -> str:
    return f"{label}'s {what}" if what else label


def _same(a: Path, b: Path) -> bool:
    if a.exists() and b.exists():
        try:
            return os.path.samefile(a, b)  # hard links and symlinks alike
        except OSError:
            pass
    return a.resolve() == b.resolve()


def _within(path: Path, folder: Path) -> bool:
    """Whether ``path`` is ``folder`` or lies inside it, as written or resolved."""
    for p, f in ((Path(os.path.abspath(path)), Path(os.path.abspath(folder))),
                 (path.resolve(), folder.resolve())):  # fmt: skip
        if p == f or f in p.parents:
            return True
    return False


def _relative(path: Path, folder: Path) -> str | None:
    """``path`` relative to ``folder`` (POSIX), as written or resolved; None when outside."""
    for p, f in ((Path(os.path.abspath(path)), Path(os.path.abspath(folder))),
                 (path.resolve(), folder.resolve())):  # fmt: skip
        if f in p.parents:
            return p.relative_to(f).as_posix()
    return None


def _walk(folder: Path, links: bool = False) -> Iterator[tuple[str, os.stat_result, bool]]:
    """The entries below ``folder``, nearest first, as (path relative to it, POSIX; its
    ``os.stat``, symlinks followed; whether it is a folder): listed at most :data:`WALK_DEPTH`
    folders deep (``folder`` itself is the first) and :data:`WALK_ENTRIES` entries in all; a
    dangling symlink is left out. ``links``: folders reached through symlinks are listed too,
    each folder once; otherwise a symlink to a folder is an entry, not a folder."""
    queue = collections.deque([(str(folder), "", 1)])
    listed, seen = set(), 0
    if links:
        try:
            top = os.stat(folder)
        except OSError:
            return
        listed.add((top.st_dev, top.st_ino))
    while queue and seen < WALK_ENTRIES:
        where, prefix, depth = queue.popleft()
        try:
            entries = os.scandir(where)
        except OSError:
            continue
        with entries:
            for entry in entries:
                seen += 1
                if seen > WALK_ENTRIES:
                    break
                try:
                    st = entry.stat()
                    is_dir = entry.is_dir(follow_symlinks=links)
                except OSError:
                    continue
                rel = f"{prefix}{entry.name}"
                if is_dir and depth < WALK_DEPTH and (st.st_dev, st.st_ino) not in listed:
                    if links:
                        listed.add((st.st_dev, st.st_ino))
                    queue.append((entry.path, f"{rel}/", depth + 1))
                yield rel, st, is_dir


def _folder_files(folder: Path) -> set[tuple[int, int]]:
    """(device, inode) of the files in ``folder`` (symlinks followed), listed by
    :func:`_walk`."""
    return {(st.st_dev, st.st_ino) for _, st, is_dir in _walk(folder) if not is_dir}


def _folder_entries(folder: Path) -> dict[tuple[int, int], list[tuple[str, bool]]]:
    """An existing output folder's entries by (device, inode), symlinks followed (as
    :func:`os.path.samefile` compares files): their paths relative to it and whether each is
    a folder; listed by :func:`_walk`, folders reached through symlinks too (the command
    writes through them)."""
    found: dict[tuple[int, int], list[tuple[str, bool]]] = {}
    for rel, st, is_dir in _walk(folder, links=True):
        found.setdefault((st.st_dev, st.st_ino), []).append((rel, is_dir))
    return found


def _written_by(rel: str, writes: Sequence[str], folder: bool) -> str | None:
    """The pattern of ``writes`` under which the command writes ``rel`` (or, for a folder,
    anything inside it); None if it writes neither."""
    for pattern in writes:
        if pattern == "**" or fnmatchcase(rel, pattern):
            return pattern
        if folder and (pattern.startswith(rel + "/") or fnmatchcase(pattern, rel + "/*")):
            return pattern
    return None


def _labelled(values: Mapping[str, Path | Iterable[Path] | None]) -> list[tuple[str, Path]]:
    out: list[tuple[str, Path]] = []
    for label, value in values.items():
        if value is None:
            continue
        for path in [value] if isinstance(value, str | os.PathLike) else list(value):
            out.append((label, Path(path)))
    return out


def _refuse_in_input_folder(
    label: str, out: Path, in_label: str, folder: Path, files, rewritten: Sequence[str]
) -> None:
    rel = _relative(out, folder)
    if rel is not None and any(fnmatchcase(rel, pattern) for pattern in rewritten):
        return  # a file the command itself rewrites in its input folder
    if _within(out, folder):
        if out.exists():
            raise ValueError(
                f"{label} {out} exists inside the input folder {in_label} {folder}: writing it "
                "would overwrite the input"
            )
        raise ValueError(
            f"{label} {out} is inside the input folder {in_label} {folder}: give a file outside it"
        )
    if out.is_file():
        st = out.stat()
        if (st.st_dev, st.st_ino) in files():
            raise ValueError(
                f"{label} {out} is a file of the input folder {in_label} {folder} (a link to "
                "it): writing it would overwrite the input"
            )


def _identity(path: Path) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino


def _refuse_link_in_output_folder(
    label: str, folder: Path, writes: Sequence[str], in_label: str, what: str, path: Path,
    entries: dict[tuple[int, int], list[tuple[str, bool]]],
) -> None:  # fmt: skip
    """Refuses an entry of the output folder that the command writes and that is ``path``
    (a hard link, a symlink, or reached through a symlinked folder)."""
    for rel, is_dir in entries.get(_identity(path), ()):  # type: ignore[arg-type]
        pattern = _written_by(rel, writes, is_dir)
        if pattern is not None:
            writes_it = "" if pattern == "**" else f"; the command writes {pattern} there"
            kind = "folder" if is_dir else "file"
            raise ValueError(
                f"{label} {folder} would overwrite the input {_of(in_label, what)} {path}: "
                f"{folder / rel} is the same {kind} (a link){writes_it}"
            )


def _refuse_input_in_output_folder(
    label: str, folder: Path, writes: Sequence[str], in_label: str, read: list[tuple[str, Path]],
    entries: Callable[[], dict[tuple[int, int], list[tuple[str, bool]]]],
) -> None:  # fmt: skip
    if not folder.is_dir():
        return
    literal = [w for w in writes if not glob.has_magic(w)]
    for what, path in read:
        rel = _relative(path, folder)
        pattern = None if rel is None else _written_by(rel, writes, path.is_dir())
        if pattern is None and path.exists():  # a link to a file the command writes
            pattern = next((w for w in literal if _same(folder / w, path)), None)
            if pattern is None:  # a file the command writes there is a link to the input
                _refuse_link_in_output_folder(
                    label, folder, writes, in_label, what, path, entries()
                )
        if pattern == "**":
            raise ValueError(
                f"{label} {folder} would overwrite the folder holding the input "
                f"{_of(in_label, what)} {path}"
            )
        if pattern is not None:
            raise ValueError(
                f"{label} {folder} would overwrite the input {_of(in_label, what)} {path} (the "
                f"command writes {pattern} there)"
            )


def _refuse_not_regular(label: str, out: Path) -> None:
    """Refuses an output file that exists and is not a regular file (a device, a FIFO, a
    socket; symlinks followed), and an output that is a symlink: kiseki writes a file by
    renaming a new one onto its path, which would put a regular file in the device's place,
    or in the symlink's (the link gone, the file it pointed to left as it was)."""
    replacing = "not a regular file: kiseki writes files by replacing them"
    try:
        mode = os.stat(out).st_mode
    except (OSError, ValueError):  # nothing there (or a dangling symlink)
        mode = None
    link = os.path.islink(out)
    if mode is not None and not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        kind = special_kind(mode)
        via = f" (through a symlink to {os.readlink(out)})" if link else ""
        raise ValueError(f"{label} {out}: {kind}{via}, {replacing}")
    if link:
        raise ValueError(
            f"{label} {out}: a symlink (to {os.readlink(out)}), {replacing}; give the file "
            "it points to, or remove the link"
        )


def _refuse_over_input(
    in_label: str,
    src: Path,
    written: list[tuple[str, Path]],
    made: list[tuple[str, Path, tuple[str, ...]]],
    rewritten: Sequence[str],
    listings: Mapping[str, Callable[[], dict[tuple[int, int], list[tuple[str, bool]]]]],
) -> None:
    """:func:`check_outputs`'s rules for one input ``src`` (``listings``: each output folder's
    entries, :func:`_folder_entries`, listed once for all inputs)."""
    read = input_files(src)
    for label, out in written:
        for what, path in read:
            if _same(out, path):
                raise ValueError(
                    f"{label} {out} would overwrite the input {_of(in_label, what)} {path}"
                )
    inside = input_folder(src)
    if inside is not None:
        files = functools.cache(functools.partial(_folder_files, inside))  # listed once
        for label, out in written:
            _refuse_in_input_folder(label, out, in_label, inside, files, rewritten)
        for label, folder, _ in made:
            if _within(folder, inside):
                where = "is" if _same(folder, inside) else "is inside"
                raise ValueError(
                    f"{label} {folder} {where} the input folder {in_label} {inside}: give a "
                    "folder outside it"
                )
    for label, folder, writes in made:
        extra = [] if inside is None or inside == src else [("bag folder", inside)]
        _refuse_input_in_output_folder(
            label, folder, writes, in_label, read + extra, listings[label]
        )


def check_outputs(
    outputs: Mapping[str, Path | Iterable[Path] | None],
    inputs: Mapping[str, Path | Iterable[Path] | None],
    folders: Mapping[str, tuple[Path | None, Sequence[str]]] | None = None,
    rewritten: Mapping[str, Sequence[str]] | None = None,
) -> None:
    """Refuses, before any work, outputs that would destroy inputs. ``outputs``: label -> the
    file(s) written (a map YAML and its image); ``inputs``: label -> the file(s) or folder(s)
    read; ``folders``: label -> (an output folder, glob patterns relative to it of the files
    the command writes there; ``**``: anything, all through it); ``rewritten``: input label ->
    glob patterns, relative to that input folder, of the files the command itself rewrites in
    it (an output may be one of them: kiseki serve's route history). The rules, paths compared
    as written and resolved through symlinks, existing files by identity (hard links):

    * an output file is not an existing folder (IsADirectoryError), an output folder not an
      existing file (NotADirectoryError);
    * an output file is not an input, nor a file an input refers to
      (:func:`~kiseki._support.input_refs.input_files`: a map YAML's image, a scene's octomap, a
      waypoint file's maps, an Aalto prefix's ``N-*.csv``), nor inside an input folder
      (:func:`~kiseki._support.input_refs.input_folder`: a ROS 2 bag, a taught run, a map folder),
      nor a link to a file in it (the folder listed as :func:`_folder_files` says);
    * an output folder is not an input folder nor inside one;
    * an input (or a file it refers to) inside an output folder is refused when the command
      writes it there (matches a pattern; an input folder: when the command writes anything
      inside it); with ``**``, any input inside the folder; and so is an entry of an existing
      output folder that the command writes (with ``**``: any) and that is an input or a file
      an input refers to (a hard link, a symlink, a symlinked folder holding it), compared by
      identity as :func:`os.path.samefile` does over the folder's listing (:func:`_walk`: at
      most :data:`WALK_DEPTH` folders deep, :data:`WALK_ENTRIES` entries, symlinked folders
      followed, each folder once);
    * an output file that exists is a regular file, not a device, a FIFO or a socket (symlinks
      followed), and is not a symlink (ValueError): the file is replaced by a rename;
    * two outputs are not one file;
    * an output file's folder exists and is writable (FileNotFoundError, PermissionError); an
      output folder, or the nearest existing folder above it, is writable.

    ValueError names the output, the input and both paths."""

    written = _labelled(outputs)
    made = [(label, Path(f), tuple(w)) for label, (f, w) in (folders or {}).items() if f]
    for label, out in written:
        if out.is_dir():
            raise IsADirectoryError(f"{label} {out} is a folder: give the file to write")
    for label, folder, _ in made:
        if folder.exists() and not folder.is_dir():
            raise NotADirectoryError(f"{label} {folder}: not a folder")
    listings = {
        label: functools.cache(functools.partial(_folder_entries, folder))
        for label, folder, _ in made
    }
    for in_label, src in _labelled(inputs):
        again = (rewritten or {}).get(in_label, ())
        _refuse_over_input(in_label, src, written, made, again, listings)
    for label, out in written:
        _refuse_not_regular(label, out)
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
    for label, folder, _ in made:
        check_writable_folder(folder, label)


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
    by default): without one a .pgf figure fails after all the work, so it is refused before."""
    from matplotlib import rcParams  # here: matplotlib only once a .pgf is asked for

    engine = rcParams["pgf.texsystem"]
    if shutil.which(engine) is None:
        raise ValueError(
            f"{label} {path}: a .pgf figure needs {engine} (a LaTeX engine, matplotlib's "
            "pgf.texsystem), which is not installed; give .pdf, .svg or .png"
        )
