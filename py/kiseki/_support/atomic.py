# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Write-then-rename: a file is either its old self or completely written, never half. Files
that belong together (a map's YAML and image, a taught run's maps and waypoint file) are all
written to temporary names and synced to disk first, and renamed only once every one is
complete, so a full disk leaves the old set as it was and no temporary file behind. The renames
themselves are one after another, not one atomic step: the set is replaced file by file in the
order given (a map's image before its YAML, so a reader never sees a YAML whose image is
missing)."""

from __future__ import annotations

import contextlib
import os
import re
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

__all__ = [
    "atomic_write",
    "atomic_write_all",
    "check_writable_folder",
    "record_written",
    "reworded",
    "written_files",
]

# a temporary file older than this is left by a killed writer (a live one is being written)
STALE_SECONDS = 60.0

# every target this process has put in place, in order (what an interrupted command reports)
_WRITTEN: list[Path] = []


def written_files() -> list[Path]:
    """The files this process has written completely (renamed into place), oldest first."""
    return list(_WRITTEN)


def record_written(path: str | os.PathLike) -> None:
    """Records a file or folder put in place by other means than :func:`atomic_write_all` (a
    map folder swapped in whole), for :func:`written_files`."""
    _WRITTEN.append(Path(path))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def reworded(err: OSError, message: str) -> OSError:
    """An OSError of the same type and errno as ``err`` (so that callers can still tell a full
    disk from a missing file) whose text is ``message``; to raise ``from err``."""
    if not isinstance(err, OSError):
        raise TypeError(f"reworded takes an OSError, got {type(err).__name__}")
    try:
        out = type(err)(message)
    except TypeError:  # a subclass whose constructor takes other arguments
        out = OSError(message)
    out.errno = err.errno
    return out


def _naming_target(err: OSError, target: Path, tmp: str | None) -> OSError:
    """The error of writing a temporary file, told about its target (the user never sees the
    temporary name); other errors unchanged."""
    if tmp is not None and err.filename not in (None, tmp):
        return err
    reason = err.strerror or str(err)
    kept = " (a previous one is kept)" if target.exists() else ""
    return reworded(err, f"{target}: {reason[:1].lower()}{reason[1:]}; not written{kept}")


def _remove_stale_temporaries(target: Path, keep: Sequence[str]) -> None:
    """Removes the temporary files of ``target`` that a killed writer left behind: hidden
    siblings named as :func:`tempfile.mkstemp` names them here (``.{stem}.`` + 8 random
    characters + the suffix), older than :data:`STALE_SECONDS`, other than ``keep``."""
    pattern = re.compile(re.escape(f".{target.stem}.") + "[a-z0-9_]{8}" + re.escape(target.suffix))
    kept = {os.path.abspath(k) for k in keep}
    now = time.time()
    with contextlib.suppress(OSError), os.scandir(target.parent) as entries:
        for entry in entries:
            if not pattern.fullmatch(entry.name) or os.path.abspath(entry.path) in kept:
                continue
            with contextlib.suppress(OSError):
                if entry.is_file(follow_symlinks=False) and (
                    now - entry.stat(follow_symlinks=False).st_mtime > STALE_SECONDS
                ):
                    os.unlink(entry.path)


def _fsync_file(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_folder(folder: Path) -> None:
    """Syncs a folder's entries (the renames) where the system supports it (not Windows,
    not every filesystem); the files are in place already, so a failure here is ignored."""
    with contextlib.suppress(OSError, AttributeError):
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def atomic_write_all(
    writes: Sequence[tuple[str | os.PathLike, Callable[[str], object]]],
) -> list[Path]:
    """Calls each ``write(tmp_path)`` on a temporary file beside its target (same suffix, so
    that writers choosing the format by extension work), in order, syncs it to disk, and once
    every one is written renames them onto their targets one after another, in the order
    given, then syncs the folders. If any write fails, every temporary file is removed and no
    target is touched; an OSError then names the target it was writing. A failure during the
    renames (rare: same folder, no new space needed) can leave the first targets replaced and
    the others not. Temporary files of these targets left by a killed writer (older than
    :data:`STALE_SECONDS`) are removed."""
    targets = [Path(target) for target, _ in writes]
    for target in targets:
        if not target.parent.is_dir():
            raise FileNotFoundError(f"{target}: directory {target.parent} does not exist")
    temps: list[str] = []
    try:
        for target, (_, write) in zip(targets, writes, strict=True):
            tmp = None
            try:
                fd, tmp = tempfile.mkstemp(
                    dir=target.parent, prefix=f".{target.stem}.", suffix=target.suffix
                )
                temps.append(tmp)
                os.close(fd)
                _remove_stale_temporaries(target, temps)
                write(tmp)
                os.chmod(tmp, 0o666 & ~_umask())
                _fsync_file(tmp)
            except OSError as err:
                raise _naming_target(err, target, tmp) from err
        for tmp, target in zip(temps, targets, strict=True):
            os.replace(tmp, target)
            _WRITTEN.append(target)
        for folder in dict.fromkeys(target.parent for target in targets):
            _fsync_folder(folder)
    except BaseException:
        for tmp in temps:
            Path(tmp).unlink(missing_ok=True)
        raise
    return targets


def atomic_write(target: str | os.PathLike, write: Callable[[str], object]) -> Path:
    """Calls ``write(tmp_path)`` on a temporary file beside ``target`` (same suffix, so that
    writers choosing the format by extension work), then renames it onto ``target``."""
    return atomic_write_all([(target, write)])[0]


def check_writable_folder(folder: str | os.PathLike, what: str = "output") -> None:
    """Raises PermissionError naming the folder when it, or the nearest folder above it while
    it does not exist yet, cannot be written (a read-only filesystem, missing permission):
    for the commands to refuse before their work rather than fail at its end."""
    folder = Path(folder).absolute()
    probe = folder
    while not probe.exists() and probe.parent != probe:
        probe = probe.parent
    if not probe.is_dir():
        raise NotADirectoryError(f"{folder}: {probe} is not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        read_only = bool(os.statvfs(probe).f_flag & os.ST_RDONLY)
        why = "on a read-only filesystem" if read_only else "no write permission"
        raise PermissionError(f"{folder}: the {what} folder is not writable ({why})")
