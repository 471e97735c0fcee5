# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""The bounded-reads tests' means (tests/python/core/test_bounded_reads*.py): readers called in
a child process with an address space limit (RLIMIT_AS), a limit on each case's CPU time and
on its wall-clock time and a timeout for the whole, each case's time and peak memory printed;
files of zeros that decompress past a limit; the kiseki command in such a child."""

from __future__ import annotations

import bz2
import functools
import gzip
import json
import subprocess
import sys
from pathlib import Path

from kiseki._support.inputs import GIB, MIB

MEMORY_LIMIT = 3 * GIB  # the children's address space
# Per case: an endless read is caught by its CPU time (SIGPROF), which other processes on the
# machine do not stretch (a wall-clock limit of 5 s tripped under a loaded machine's load); a
# read that blocks (no CPU) by the wall-clock alarm (SIGALRM).
CASE_CPU_SECONDS = 5
CASE_WALL_SECONDS = 30
CHILD_SECONDS = 120  # the whole child; a reader stuck in C (no signal handled) ends here
ZEROS = 64 * MIB

CHILD = r"""
import importlib, json, os, resource, signal, sys, time
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

def alarm(signum, frame):
    raise TimeoutError("no answer within the case's CPU or wall-clock seconds")

signal.signal(signal.SIGALRM, alarm)
signal.signal(signal.SIGPROF, alarm)

def peak_mb():
    with open("/proc/self/status") as f:
        line = next(l for l in f if l.startswith("VmHWM"))
    return int(line.split()[1]) / 1024

def target(name):
    module, attr = name.split(":")
    return importlib.import_module(module), attr

for case in json.loads(sys.argv[2]):
    saved = {}
    for name, value in case.get("set", {}).items():
        module, attr = target(name)
        saved[name] = getattr(module, attr)
        setattr(module, attr, value)
    module, attr = target(case["call"])
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")  # the peak resident size starts again from here
    start, cpu_start = time.monotonic(), time.process_time()
    signal.setitimer(signal.ITIMER_PROF, float(sys.argv[3]))
    signal.alarm(int(sys.argv[4]))
    try:
        getattr(module, attr)(*case["args"])
        error, message = None, ""
    except BaseException as exc:
        error, message = type(exc).__name__, (str(exc).splitlines() or [""])[0]
    finally:
        signal.alarm(0)
        signal.setitimer(signal.ITIMER_PROF, 0)
    seconds, cpu_seconds = time.monotonic() - start, time.process_time() - cpu_start
    for name, value in saved.items():
        module, attr = target(name)
        setattr(module, attr, value)
    result = {"id": case["id"], "error": error, "message": message, "seconds": seconds,
              "cpu_seconds": cpu_seconds, "peak_mb": peak_mb()}
    print(json.dumps(result), flush=True)
"""


def run_cases(cases: list[dict], cwd: Path) -> dict[str, dict]:
    """Runs the reader calls of ``cases`` in one child (RLIMIT_AS, a CPU-time and a wall-clock
    limit per case, a timeout for the whole); returns each case's outcome by id and prints the
    measurements."""
    limits = [str(CASE_CPU_SECONDS), str(CASE_WALL_SECONDS)]
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, str(MEMORY_LIMIT), json.dumps(cases), *limits],
        capture_output=True,
        text=True,
        timeout=CHILD_SECONDS,
        cwd=cwd,
    )
    results = {}
    for line in proc.stdout.splitlines():
        if line.startswith("{"):
            result = json.loads(line)
            results[result["id"]] = result
            print(
                f"{result['id']:<28} {result['seconds']:6.2f} s {result['peak_mb']:7.0f} MB peak"
                f"  {result['error']}: {result['message'].replace(str(cwd) + '/', '')[:90]}"
            )
    missing = [case["id"] for case in cases if case["id"] not in results]
    assert not missing, f"the child stopped before {missing}: {proc.stderr[-2000:]}"
    return results


@functools.cache
def compressed_zeros(kind: str) -> bytes:
    """64 MiB of zeros, gzip (65 KB) or bzip2 (79 bytes)."""
    return (gzip.compress if kind == "gzip" else bz2.compress)(b"\0" * ZEROS, 9)


def zeros_gz(path: Path, members: int) -> Path:
    """A gzip file of ``members`` members of 64 MiB of zeros."""
    path.write_bytes(compressed_zeros("gzip") * members)
    return path


def zeros_bz2(path: Path, streams: int) -> Path:
    """A bzip2 file of ``streams`` streams of 64 MiB of zeros."""
    path.write_bytes(compressed_zeros("bz2") * streams)
    return path


def mcap_of_zeros(path: Path, encoding: str = "json", compression: str = "ZSTD") -> Path:
    """A valid MCAP with one chunk holding one message of 64 MiB of zeros (2 KB with zstd, 250
    KB with lz4); a ROS 2 bag's when ``encoding`` is ``cdr``."""
    from mcap.writer import CompressionType, Writer

    with open(path, "wb") as f:
        kind = getattr(CompressionType, compression)
        writer = Writer(f, chunk_size=ZEROS * 2, compression=kind)
        writer.start(profile="ros2" if encoding == "cdr" else "", library="test")
        schema = writer.register_schema("x", "ros2msg" if encoding == "cdr" else "jsonschema", b"")
        channel = writer.register_channel("/x", encoding, schema)
        writer.add_message(channel, log_time=0, data=bytes(ZEROS), publish_time=0)
        writer.finish()
    return path


def ros1_bag_of_zeros(path: Path) -> Path:
    """The head of a ROS 1 bag: its magic and one bz2 chunk of 64 MiB of zeros."""

    def record(fields: dict[bytes, bytes], data: bytes) -> bytes:
        header = b"".join(
            len(k + b"=" + v).to_bytes(4, "little") + k + b"=" + v for k, v in fields.items()
        )
        return len(header).to_bytes(4, "little") + header + len(data).to_bytes(4, "little") + data

    chunk = record(
        {b"op": b"\x05", b"compression": b"bz2", b"size": ZEROS.to_bytes(4, "little")},
        compressed_zeros("bz2"),
    )
    path.write_bytes(b"#ROSBAG V2.0\n" + chunk)
    return path


def sparse_file(path: Path, size: int) -> Path:
    with open(path, "wb") as f:
        f.truncate(size)
    return path


def limit_memory() -> None:
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def kiseki_child(*args: str) -> subprocess.Popen:
    """The kiseki CLI in a child with the address space limit."""
    return subprocess.Popen(
        [Path(sys.executable).with_name("kiseki"), *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=limit_memory,
    )
