# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the MCAP run log on truncated files (cut and really killed) and bad input (moved
from test_sim_mcap.py)."""

from __future__ import annotations

import io
import math
import os
import signal
import subprocess
import sys
import types
import warnings
from pathlib import Path

import numpy as np
import pytest
from mcap.reader import NonSeekingReader, make_reader
from mcap.records import Chunk, ChunkIndex, Message
from mcap.stream_reader import ReadDataStream, breakup_chunk

from _helpers.sim_mcap_sample import (
    write_sample,
)
from kiseki.errors import LogFormatError
from kiseki.io.runlog import (
    RunWriter,
    TruncatedRunWarning,
    read_run,
)

# --- truncated files ---


def read_all(path: Path) -> list[tuple[str, float, dict]]:
    run = read_run(path)
    return [(topic, t, m) for topic in run.topics() for t, m in run.messages(topic)]


def test_cut_file_yields_the_complete_chunks(tmp_path: Path) -> None:
    full = tmp_path / "full.mcap"
    write_sample(full, chunk_size=2048)
    data = full.read_bytes()
    everything = read_all(full)
    with open(full, "rb") as f:
        chunks = make_reader(f).get_summary().chunk_indexes  # type: ignore[union-attr]
    cut_path = tmp_path / "cut.mcap"
    seen_partial = False
    for cut in (chunks[3].chunk_start_offset + 5, len(data) // 2, len(data) - 10, len(data) - 1):
        cut_path.write_bytes(data[:cut])
        with pytest.warns(TruncatedRunWarning, match="cut.mcap: truncated MCAP"):
            run = read_run(cut_path)
        assert run.truncated and run.metadata == {"seed": "42", "world": "corridor"}
        got = [(topic, t, m) for topic in run.topics() for t, m in run.messages(topic)]
        # exactly the messages of the chunks that end before the cut
        complete = [c for c in chunks if c.chunk_start_offset + c.chunk_length <= cut]
        n_complete = sum(chunk_message_count(data, c) for c in complete)
        assert len(got) == n_complete
        seen_partial |= 0 < n_complete < len(everything)
        assert all(item in everything for item in got)
    assert seen_partial
    # the cut before chunk 3 keeps the first 3 chunks: the first written scans are there
    cut_path.write_bytes(data[: chunks[3].chunk_start_offset + 5])
    with pytest.warns(TruncatedRunWarning):
        run = read_run(cut_path)
    assert run.topics()["/map"] == ("foxglove.Grid", 1)


def chunk_message_count(data: bytes, index: ChunkIndex) -> int:
    """Messages in one chunk, decoded straight from the bytes at the index's offset."""
    start = index.chunk_start_offset + 9  # opcode + record length
    chunk = Chunk.read(ReadDataStream(io.BytesIO(data[start : start + index.chunk_length])))
    return sum(isinstance(r, Message) for r in breakup_chunk(chunk))


def test_cut_before_header_or_magic_is_a_log_format_error(sample: Path, tmp_path: Path) -> None:
    data = sample.read_bytes()
    cut = tmp_path / "tiny.mcap"
    for size in (0, 5, 8, 20):
        cut.write_bytes(data[:size])
        with pytest.raises(LogFormatError, match="tiny.mcap"):
            read_run(cut)


def test_mcap_library_alone_needs_the_footer(tmp_path: Path) -> None:
    """What the docstring says of mcap 1.6: the seeking reader fails on a file without its
    footer; the non-seeking reader yields the complete chunks' messages, then raises."""
    full = tmp_path / "full.mcap"
    write_sample(full, chunk_size=2048)
    data = full.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    with open(cut, "rb") as f, pytest.raises(Exception):  # noqa: B017 - any error, see docstring
        list(make_reader(f).iter_messages())
    streamed = []
    with open(cut, "rb") as f, pytest.raises(Exception):  # noqa: B017
        for _, channel, message in NonSeekingReader(f).iter_messages(log_time_order=False):
            streamed.append((channel.topic, message.log_time))
    with pytest.warns(TruncatedRunWarning):
        run = read_run(cut)
    assert len(streamed) == sum(n for _, n in run.topics().values()) > 0


KILLED_WRITER = """
import os, signal, sys
import numpy as np
from kiseki.io.runlog import RunWriter
w = RunWriter(sys.argv[1], {"run": "killed"}, chunk_size=4096)
for k in range(int(sys.argv[2])):
    w.write_pose("/ground_truth", 0.01 * k, (k, 0.0, 0.0))
    w.write_laser_scan("/scan", 0.01 * k, (k, 0.0, 0.0), np.linspace(-1, 1, 50),
                       np.full(50, k % 7 + 1.0))
os.kill(os.getpid(), signal.SIGKILL)
"""


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="needs SIGKILL")
def test_killed_writer_keeps_every_complete_chunk(tmp_path: Path) -> None:
    path = tmp_path / "killed.mcap"
    steps = 301  # 300 steps happen to fill the last chunk exactly: nothing would be lost
    proc = subprocess.run(
        [sys.executable, "-c", KILLED_WRITER, str(path), str(steps)],
        capture_output=True,
        timeout=120,
    )
    assert proc.returncode == -signal.SIGKILL, proc.stderr.decode()
    with pytest.warns(TruncatedRunWarning):
        run = read_run(path)
    assert run.truncated and run.metadata == {"run": "killed"}
    poses = run.messages("/ground_truth")
    scans = run.messages("/scan")
    # Only the last, unfinished chunk is lost: a step (pose ~41 B + scan ~462 B of protobuf + 2
    # message headers of 31 B) takes ~565 B, so a 4 KiB chunk holds fewer than 8 steps.
    assert steps - 8 <= len(poses) <= steps and len(scans) < steps
    assert len(scans) in (len(poses), len(poses) - 1)  # the chunk may end between the two
    assert [m["pose"]["position"]["x"] for _, m in poses] == list(range(len(poses)))
    assert [m["ranges"][0] for _, m in scans] == [k % 7 + 1.0 for k in range(len(scans))]
    assert os.path.getsize(path) > 0


# --- bad input ---


def test_overwrite_is_refused_unless_asked(sample: Path) -> None:
    before = sample.read_bytes()
    with pytest.raises(FileExistsError, match="overwrite=True"):
        RunWriter(sample)
    assert sample.read_bytes() == before
    with RunWriter(sample, overwrite=True) as w:
        w.write_pose("/p", 1.0, (1, 2, 3))
    assert read_run(sample).topics() == {"/p": ("foxglove.PoseInFrame", 1)}


def test_bad_messages_raise_value_error(tmp_path: Path) -> None:
    path = tmp_path / "bad.mcap"
    with RunWriter(path) as w:
        with pytest.raises(ValueError, match="NaN"):
            w.write_pose("/p", 0.0, (1.0, float("nan"), 0.0))
        with pytest.raises(ValueError, match="NaN"):
            w.write_transform(0.0, "world", "base_link", (0.0, 0.0, float("inf")))
        with pytest.raises(ValueError, match=">= 0"):
            w.write_pose("/p", -0.5, (0, 0, 0))
        with pytest.raises(ValueError, match="finite"):
            w.write_pose("/p", float("nan"), (0, 0, 0))
        with pytest.raises(ValueError, match="shape"):
            w.write_pose("/p", 0.0, (0, 0))
        with pytest.raises(ValueError, match="unit norm"):
            w.write_pose("/p", 0.0, (0, 0, 0, 0, 0, 0, 2))
        with pytest.raises(ValueError, match="evenly spaced"):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1, 0.5], [1, 2, 3])
        with pytest.raises(ValueError, match="shape"):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1, 0.2], [1, 2])
        with pytest.raises(ValueError, match="max_range"):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1], [1, float("inf")])
        with pytest.raises(ValueError, match=r"\(h, w\)"):
            w.write_depth_image("/d", 0.0, np.zeros(5, np.float32), "cam")
        with pytest.raises(ValueError, match="floating"):
            w.write_depth_image("/d", 0.0, np.zeros((2, 2), np.uint16), "cam")
        with pytest.raises(ValueError, match="finite JSON"):
            w.write_json("/j", 0.0, "kiseki.X", {"v": float("nan")}, {"type": "object"})
        w.write_pose("/p", 0.0, (0, 0, 0))
        with pytest.raises(ValueError, match="carries foxglove.PoseInFrame"):
            w.write_laser_scan("/p", 0.0, (0, 0, 0), [0.0, 0.1], [1, 2])
    with pytest.raises(ValueError, match="closed"):
        w.write_pose("/p", 1.0, (0, 0, 0))
    # nothing invalid reached the file
    assert read_run(path).topics() == {"/p": ("foxglove.PoseInFrame", 1)}


@pytest.mark.parametrize("bad", [True, "1.5", -0.5, math.nan])
def test_a_time_range_or_resolution_that_is_no_number_is_refused(tmp_path: Path, bad) -> None:
    """True was written as 1 s, 1 m or 1 m per cell and "1.5" as 1.5 s or m (a negative or NaN
    value was refused before too); a max range that no float32 holds is refused as before."""
    grid = types.SimpleNamespace(cells=np.zeros((2, 2), np.int8), resolution=bad, origin=None)
    with RunWriter(tmp_path / "bad.mcap") as w:
        with pytest.raises(ValueError, match=r"^time must be a finite number >= 0 s, got "):
            w.write_pose("/p", bad, (0, 0, 0))
        with pytest.raises(ValueError, match=r"^max_range must be a finite number > 0 m, got "):
            w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1], [1, 2], max_range=bad)
        with pytest.raises(
            ValueError, match=r"^grid resolution must be a finite number > 0 m, got "
        ):
            w.write_grid("/map", 0.0, grid)
        for past in (1e39, 1e-50):  # no float32 holds them: inf and 0
            with pytest.raises(ValueError, match=r"m is outside a float32's range$"):
                w.write_laser_scan("/s", 0.0, (0, 0, 0), [0.0, 0.1], [1, 2], max_range=past)
    assert read_run(tmp_path / "bad.mcap").topics() == {}


def test_missing_and_garbage_files(tmp_path: Path, sample: Path) -> None:
    with pytest.raises(FileNotFoundError):
        read_run(tmp_path / "missing.mcap")
    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"this is not an mcap file at all\n" * 10)
    with pytest.raises(LogFormatError, match="garbage.mcap"):
        read_run(garbage)
    fake = tmp_path / "fake.mcap"
    fake.write_bytes(b"\x89MCAP0\r\n" + bytes(range(256)) * 4)
    with pytest.raises(LogFormatError, match="fake.mcap"):
        read_run(fake)


def test_corrupt_chunk_is_a_log_format_error(tmp_path: Path) -> None:
    path = tmp_path / "corrupt.mcap"
    write_sample(path, chunk_size=2048)
    with open(path, "rb") as f:
        chunk = make_reader(f).get_summary().chunk_indexes[2]  # type: ignore[union-attr]
    data = bytearray(path.read_bytes())
    middle = chunk.chunk_start_offset + chunk.chunk_length // 2
    data[middle] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(LogFormatError, match="corrupt.mcap: corrupt MCAP"):
        read_run(path)


def test_no_warning_on_a_complete_file(sample: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run = read_run(sample)
    assert "truncated" not in repr(run)
