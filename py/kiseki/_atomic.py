# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Write-then-rename: a file is either its old self or completely written, never half. Files
that belong together (a map's YAML and image, a taught run's maps and waypoint file) are all
written to temporary names first and renamed only once every one is complete, so a full disk
leaves the old set as it was and no temporary file behind."""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

__all__ = ["atomic_write", "atomic_write_all", "check_writable_folder"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _naming_target(err: OSError, target: Path, tmp: str | None) -> OSError:
    """The error of writing a temporary file, told about its target (the user never sees the
    temporary name); other errors unchanged."""
    if tmp is not None and err.filename not in (None, tmp):
        return err
    reason = err.strerror or str(err)
    message = f"{target}: {reason[:1].lower()}{reason[1:]}; not written (a previous one is kept)"
    try:
        out = type(err)(message)
    except TypeError:
        out = OSError(message)
    out.errno = err.errno
    return out


def atomic_write_all(
    writes: Sequence[tuple[str | os.PathLike, Callable[[str], object]]],
) -> list[Path]:
    """Calls each ``write(tmp_path)`` on a temporary file beside its target (same suffix, so
    that writers choosing the format by extension work), in order, and renames them all onto
    their targets once every one is written. If any write fails, every temporary file is
    removed and no target is touched; an OSError then names the target it was writing."""
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
                write(tmp)
                os.chmod(tmp, 0o666 & ~_umask())
            except OSError as err:
                raise _naming_target(err, target, tmp) from err
        for tmp, target in zip(temps, targets, strict=True):
            os.replace(tmp, target)
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
