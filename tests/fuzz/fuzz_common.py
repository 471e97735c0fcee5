# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The runner shared by the atheris targets ``fuzz_<reader>.py`` of this folder.

Each target hands :func:`main` a reader (``read(path)``, the public function a user's file goes
to) and its seeds. Every fuzzed input is written to one file, the reader reads it, and the
run fails on anything but a clear refusal: a ``ValueError`` (kiseki's ``MapFormatError`` and
``LogFormatError`` are ValueErrors) or a ``FileNotFoundError`` (a file the input refers to)
whose message names the input file. A ``UnicodeDecodeError`` (a ValueError, but a codec
message), any other exception, a hang (``-timeout``) or a native crash is a finding; atheris
writes the input to ``crash-<sha1>`` (``-artifact_prefix``).

Usage (libFuzzer flags, see https://llvm.org/docs/LibFuzzer.html#options)::

    python tests/fuzz/fuzz_carmen.py -runs=2000 -seed=1      # seeded, then mutated
    python tests/fuzz/fuzz_carmen.py crash-0123abcd          # replay one input

The seeds are small real files: heads of the recorded logs in ``../shared/data`` (left out when
the folder is absent) and the project's ``data/``, written to ``$KISEKI_FUZZ_DIR/corpus``
(by default a temporary folder, removed when the run ends), which libFuzzer then grows.
"""

from __future__ import annotations

import functools
import gc
import gzip
import os
import shutil
import signal
import sys
import tempfile
import types
import warnings
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

import atheris

ROOT = Path(__file__).resolve().parents[2]
PROJECT_DATA = ROOT / "data"
SHARED_DATA = ROOT.parent / "shared" / "data"

Reader = Callable[[Path], object]


class FindingError(AssertionError):
    """The reader failed in a way a user should never see."""


def shared_data() -> Path | None:
    """``../shared/data`` when present, else None (seeds from it are then left out)."""
    return SHARED_DATA if SHARED_DATA.is_dir() else None


def head_lines(path: Path, count: int, *, skip_comments: bool = True) -> bytes:
    """The first ``count`` lines (``#`` comment lines skipped) of a text or gzip file."""
    opener = gzip.open if path.read_bytes()[:2] == b"\x1f\x8b" else open
    lines = []
    with opener(path, "rb") as handle:
        for line in handle:
            if skip_comments and line.lstrip().startswith(b"#"):
                continue
            lines.append(line)
            if len(lines) == count:
                break
    return b"".join(lines)


def check_refusal(path: Path, read: Reader, accepted: tuple[type[BaseException], ...]) -> None:
    """Run ``read(path)``; raise :class:`FindingError` unless it returns or refuses clearly."""
    try:
        read(path)
    except UnicodeDecodeError as err:
        raise FindingError(f"codec error instead of a clear refusal: {err}") from err
    except accepted as err:
        if str(path) not in str(err):
            raise FindingError(
                f"the error does not name the file: {type(err).__name__}: {err}"
            ) from err


def instrument(packages: Iterable[str]) -> int:
    """Add atheris' coverage instrumentation to every function already imported from
    ``packages`` (``atheris.instrument_imports`` misses kiseki when it is installed editable:
    its custom loader bypasses the import hook). Returns the number of functions."""
    roots = tuple(packages)
    count = 0
    for obj in gc.get_objects():
        if not isinstance(obj, types.FunctionType):
            continue
        module = getattr(obj, "__module__", None) or ""
        if module.split(".")[0] in roots:
            atheris.instrument_func(obj)
            count += 1
    return count


_TEMPORARY: list[Path] = []


@functools.cache
def workdir() -> Path:
    """``$KISEKI_FUZZ_DIR`` (kept), else a temporary folder, the same for every call, that
    :func:`main` removes when the fuzzer ends."""
    folder = os.environ.get("KISEKI_FUZZ_DIR")
    if folder:
        path = Path(folder)
        path.mkdir(parents=True, exist_ok=True)
        return path
    path = Path(tempfile.mkdtemp(prefix="kiseki-fuzz-"))
    _TEMPORARY.append(path)
    return path


def remove_when_done(folder: Path) -> None:
    """Returns in a child process, which fuzzes; this process waits for it, removes ``folder``
    and exits with its status. libFuzzer ends the process with exit() or _Exit() from C (after
    -runs, a finding, Ctrl-C), which skip Python's atexit handlers."""
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        return
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C reaches the child, which reports
    _, status = os.waitpid(pid, 0)
    shutil.rmtree(folder, ignore_errors=True)
    code = os.waitstatus_to_exitcode(status)
    sys.exit(code if code >= 0 else 128 - code)  # killed by a signal: 128 + its number


def pick_target(choices: Sequence[str]) -> str:
    """The reader named by ``--target NAME`` for a script that fuzzes several (the option is
    removed from ``sys.argv`` before libFuzzer reads it); ``choices[0]`` when absent. Exits
    with a message when the name is missing or not one of ``choices``."""
    if "--target" not in sys.argv:
        return choices[0]
    at = sys.argv.index("--target")
    if at + 1 == len(sys.argv):
        sys.exit(f"--target needs a name: {' or '.join(choices)}")
    target = sys.argv[at + 1]
    del sys.argv[at : at + 2]
    if target not in choices:
        sys.exit(f"--target must be {' or '.join(choices)}, got {target!r}")
    return target


def write_corpus(folder: Path, seeds: Iterable[bytes]) -> int:
    folder.mkdir(parents=True, exist_ok=True)
    count = 0
    for i, seed in enumerate(seeds):
        (folder / f"seed-{i:03d}").write_bytes(seed)
        count += 1
    return count


def main(
    read: Reader,
    seeds: Callable[[Path], Iterable[bytes]],
    *,
    suffix: str,
    accepted: tuple[type[BaseException], ...] = (ValueError, FileNotFoundError),
    prepare: Callable[[Path], None] | None = None,
    packages: Iterable[str] = ("kiseki",),
) -> None:
    """Fuzz ``read`` on files named ``input<suffix>``. ``seeds(folder)`` yields the seed inputs;
    ``prepare(folder)`` writes the files an input may refer to (a map beside a waypoint file);
    the functions of ``packages`` (imported by then) are instrumented for coverage."""
    count = instrument(packages)
    print(f"[fuzz] {count} functions of {', '.join(packages)} instrumented", file=sys.stderr)
    folder = workdir()
    if folder in _TEMPORARY:
        remove_when_done(folder)
    files = folder / "files"
    files.mkdir(exist_ok=True)
    if prepare is not None:
        prepare(files)
    target = files / f"input{suffix}"
    argv = list(sys.argv)
    if not any(not a.startswith("-") for a in argv[1:]):  # no corpus or input given: seed one
        corpus = folder / "corpus"
        count = write_corpus(corpus, seeds(folder))
        print(f"[fuzz] {count} seed inputs in {corpus}", file=sys.stderr)
        argv.append(str(corpus))
    warnings.simplefilter("ignore")  # truncated-run and numeric warnings are not findings

    def one_input(data: bytes) -> None:
        target.write_bytes(data)
        check_refusal(target, read, accepted)

    atheris.Setup(argv, one_input)
    atheris.Fuzz()
