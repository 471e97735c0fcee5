# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Tests of the magnetic-field readers: the MagneticSamples checks, CSV and Aalto files written
here with known values, bad files named in the error, and the recorded Aalto runs. The
Kok-Solin walks' reader is tested in test_datasets_kok.py."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from kiseki.datasets.magnetic import (
    MagneticSamples,
    concatenate_samples,
    read_aalto_run,
    read_field_csv,
    read_magnetic_data,
)
from kiseki.errors import LogFormatError

# ---------------------------------------------------------------- MagneticSamples


def samples(n: int = 4, d: int = 2, **kwargs) -> MagneticSamples:
    arguments = {
        "positions": np.arange(n * d, dtype=float).reshape(n, d),
        "field": np.ones((n, 3)),
        "units": "uT",
        "source": "here",
    }
    arguments.update(kwargs)
    return MagneticSamples(**arguments)


def test_samples_store_read_only_float64_copies() -> None:
    positions = np.zeros((3, 3), dtype=np.float32)
    s = samples(3, 3, positions=positions, times=[0, 1, 2])
    assert s.positions.dtype == np.float64 and s.times.dtype == np.float64
    assert len(s) == 3 and s.dimension == 3
    positions[0, 0] = 5.0
    assert s.positions[0, 0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        s.field[0, 0] = 2.0
    np.testing.assert_allclose(s.magnitude, np.sqrt(3.0))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"units": "mT"}, "units 'mT' not one of uT, G, unknown"),
        ({"positions": np.zeros((4, 4))}, r"positions must be \(n, 2\) or \(n, 3\)"),
        ({"field": np.zeros((4, 2))}, r"field must be \(n, 3\)"),
        ({"field": np.zeros((5, 3))}, "4 positions but 5 field readings"),
        ({"positions": np.zeros((0, 2)), "field": np.zeros((0, 3))}, "no samples"),
        ({"times": np.zeros(3)}, r"times must be \(4,\)"),
        ({"positions": [["a", "b"]] * 4}, "positions are not numbers"),
    ],
)
def test_samples_bad_shapes_refused_naming_the_source(kwargs, message: str) -> None:
    with pytest.raises(ValueError, match=f"^here: {message}"):
        samples(**kwargs)


def test_samples_nan_refused_naming_the_source_and_first_row() -> None:
    field = np.ones((6, 3))
    field[2, 1] = np.nan
    field[4, 0] = np.inf
    beyond = r"NaN, infinite or beyond \+-1e\+09"
    with pytest.raises(ValueError, match=rf"here: 2 rows with a {beyond} field reading, "):
        samples(6, field=field)
    with pytest.raises(ValueError, match=r"first in data row 3 \(counting from 1\)"):
        samples(6, field=field)
    positions = np.zeros((6, 2))
    positions[5, 0] = np.nan
    with pytest.raises(ValueError, match=f"{beyond} position, the first in data row 6"):
        samples(6, positions=positions)
    with pytest.raises(ValueError, match="NaN or infinite time, the first in data row 1"):
        samples(2, times=[np.nan, 0.0])
    # a finite position or reading past 1e9 is refused as well (1e300 m overflowed the fit's
    # squared distances into a traceback); 1e9 itself, and times of the Unix epoch, are read
    positions[5, 0] = 1e300
    with pytest.raises(ValueError, match=f"{beyond} position, the first in data row 6"):
        samples(6, positions=positions)
    field = np.ones((6, 3))
    field[1, 2] = -2e9
    one_row = f"1 row with a {beyond} field reading, the first in data row 2"
    with pytest.raises(ValueError, match=one_row):
        samples(6, field=field)
    positions[5, 0], field[1, 2] = -1e9, 1e9
    assert len(samples(6, positions=positions, field=field, times=1.7e9 + np.arange(6.0))) == 6


def test_take_and_concatenate() -> None:
    a = samples(4, times=np.arange(4.0), source="a")
    b = samples(2, times=np.arange(2.0), source="b")
    both = concatenate_samples([a, b])
    assert len(both) == 6 and both.source == "a+b"
    np.testing.assert_array_equal(both.times, [0, 1, 2, 3, 0, 1])
    np.testing.assert_array_equal(both.take([4, 5]).positions, b.positions)
    assert concatenate_samples([a, samples(2)]).times is None
    with pytest.raises(ValueError, match=r"different units: a \(uT\), g \(G\)"):
        concatenate_samples([a, samples(2, units="G", source="g")])
    with pytest.raises(ValueError, match="2-D and 3-D"):
        concatenate_samples([a, samples(2, 3)])
    with pytest.raises(ValueError, match="no samples"):
        concatenate_samples([])


# ---------------------------------------------------------------- CSV


def write(path: Path, text: str | bytes) -> Path:
    path.write_bytes(text.encode() if isinstance(text, str) else text)
    return path


def test_csv_columns_in_any_order_extra_ignored(tmp_path: Path) -> None:
    text = "mz, label ,Y,mx,x,my,time\n3,a,20,1,10,2,0.5\n6,b,21,4,11,5,0.6\n\n"
    s = read_field_csv(write(tmp_path / "f.csv", text), units="G")
    np.testing.assert_array_equal(s.positions, [[10, 20], [11, 21]])
    np.testing.assert_array_equal(s.field, [[1, 2, 3], [4, 5, 6]])
    np.testing.assert_array_equal(s.times, [0.5, 0.6])
    assert s.units == "G" and s.source == str(tmp_path / "f.csv")


def test_csv_three_dimensional_positions(tmp_path: Path) -> None:
    s = read_field_csv(write(tmp_path / "f.csv", "x,y,z,mx,my,mz\n1,2,3,4,5,6\n"))
    np.testing.assert_array_equal(s.positions, [[1, 2, 3]])
    assert s.units == "unknown" and s.times is None and s.dimension == 3


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (bytes(range(256)) * 4, "binary data"),
        (b"x,y,mx,my,mz\n\xff\xfe1,2,3,4,5\n", "not a text table"),
        ("", "empty file"),
        ("x,y,mx,my,mz\n", "header but no data rows"),
        ("1,2,3,4,5\n6,7,8,9,10\n", "line 1: no header"),
        ("x,y,mx,my\n1,2,3,4\n", "line 1: header lacks mz"),
        ("x,y,mx,my,mz,x\n1,2,3,4,5,6\n", "column 'x' given twice"),
        ("x,y,mx,my,mz\n1,2,3,4,5\n1,2,3,4\n", "line 3: 4 columns, expected 5"),
        ("x,y,mx,my,mz\n1,2,3,4,5\n1,2,abc,4,5\n", "line 3: column 3 is not a number: 'abc'"),
        # PEP 515 underscores are not numbers in a CSV (float() read 3_0 as 30)
        ("x,y,mx,my,mz\n1,2,3,4,5\n1,2,3_0,4,5\n", "line 3: column 3 is not a number: '3_0'"),
        ("x,y,mx,my,mz\n1,2,3,4,5\n1,2,3,4,5\n1_0,2,3,4,5\n", "line 4: column 1 .*: '1_0'"),
    ],
)
def test_bad_csv_refused_naming_the_file(tmp_path: Path, content, message: str) -> None:
    path = write(tmp_path / "bad.csv", content)
    with pytest.raises(LogFormatError, match=f"^{re.escape(str(path))}: .*{message}"):
        read_field_csv(path)


def test_csv_nan_reading_refused_naming_file_and_row(tmp_path: Path) -> None:
    path = write(tmp_path / "f.csv", "x,y,mx,my,mz\n1,2,3,4,5\n1,2,3,nan,5\n")
    with pytest.raises(
        ValueError, match=f"^{re.escape(str(path))}: 1 row with a NaN, infinite .* data row 2"
    ):
        read_field_csv(path)


def test_csv_missing_file_and_bad_units(tmp_path: Path) -> None:
    with pytest.raises(
        FileNotFoundError, match=f"{re.escape(str(tmp_path / 'none.csv'))}: file not found"
    ):
        read_field_csv(tmp_path / "none.csv")
    with pytest.raises(ValueError, match="units 'nT' not one of"):
        read_field_csv(write(tmp_path / "f.csv", "x,y,mx,my,mz\n1,2,3,4,5\n"), units="nT")


# ---------------------------------------------------------------- Aalto layout


def write_aalto(folder: Path, name: str = "1", rows: int = 3) -> str:
    folder.mkdir(exist_ok=True)
    k = np.arange(rows)
    np.savetxt(folder / f"{name}-loc.csv", np.column_stack([k, -k]), delimiter=",")
    np.savetxt(folder / f"{name}-mag.csv", np.column_stack([k, k + 1, k + 2]), delimiter=",")
    np.savetxt(folder / f"{name}-time.csv", 0.02 * k, delimiter=",")
    return str(folder / name)


def test_aalto_run_read_by_prefix(tmp_path: Path) -> None:
    prefix = write_aalto(tmp_path / "sensor")
    for s in (read_aalto_run(prefix), read_magnetic_data(prefix)):
        np.testing.assert_array_equal(s.positions, [[0, 0], [1, -1], [2, -2]])
        np.testing.assert_array_equal(s.field, [[0, 1, 2], [1, 2, 3], [2, 3, 4]])
        np.testing.assert_allclose(s.times, [0, 0.02, 0.04])
        assert s.units == "uT" and s.source == prefix


def test_aalto_mismatched_rows_name_both_files(tmp_path: Path) -> None:
    prefix = write_aalto(tmp_path / "sensor")
    write(Path(f"{prefix}-mag.csv"), "1,2,3\n4,5,6\n")
    with pytest.raises(
        LogFormatError,
        match=f"{re.escape(prefix)}-loc.csv has 3 rows but {re.escape(prefix)}-mag.csv",
    ):
        read_aalto_run(prefix)


@pytest.mark.parametrize(
    ("part", "content", "message"),
    [
        ("mag", "1,2\n3,4\n5,6\n", "line 1: 2 columns, expected 3 .mx, my, mz."),
        ("loc", bytes(range(256)), "binary data"),
        ("time", "0.0\n0.1\nx\n", "line 3: column 1 is not a number"),
        ("loc", "0,0\n1,-1\n2_0,-2\n", "line 3: column 1 is not a number: '2_0'"),
        ("mag", "0,1,2\n1,2,3\n2,3,4_0\n", "line 3: column 3 is not a number: '4_0'"),
        ("time", "", "no rows"),
    ],
)
def test_aalto_bad_file_named(tmp_path: Path, part: str, content, message: str) -> None:
    prefix = write_aalto(tmp_path / "sensor")
    path = write(Path(f"{prefix}-{part}.csv"), content)
    with pytest.raises(LogFormatError, match=f"^{re.escape(str(path))}: {message}"):
        read_aalto_run(prefix)


def test_aalto_missing_files_named(tmp_path: Path) -> None:
    prefix = write_aalto(tmp_path / "sensor")
    Path(f"{prefix}-time.csv").unlink()
    with pytest.raises(FileNotFoundError, match=f"missing {re.escape(prefix)}-time.csv"):
        read_aalto_run(prefix)
    with pytest.raises(FileNotFoundError, match="not an Aalto run"):
        read_magnetic_data(tmp_path / "nothing" / "7")


def test_dispatch_by_name(tmp_path: Path) -> None:
    csv = write(tmp_path / "f.CSV", "x,y,mx,my,mz\n1,2,3,4,5\n")
    assert read_magnetic_data(csv).units == "unknown"
    with pytest.raises(FileNotFoundError, match="none.csv: file not found"):
        read_magnetic_data(tmp_path / "none.csv")
    with pytest.raises(FileNotFoundError, match="none.mat: file not found"):
        read_magnetic_data(tmp_path / "none.mat")
    with pytest.raises(LogFormatError, match="f.txt: not magnetic data"):
        read_magnetic_data(write(tmp_path / "f.txt", "hello\n"))
    # One file of an Aalto run is not a run: the header error says how to name it.
    prefix = write_aalto(tmp_path / "sensor")
    with pytest.raises(LogFormatError, match="named by its prefix DIR/N"):
        read_magnetic_data(f"{prefix}-mag.csv")


# ---------------------------------------------------------------- recorded data

AALTO_ROWS = {
    "invensense": [8875, 9105, 9404, 7332, 8313, 7119, 8394, 8928, 8557],
    "nexus": [8880, 9121, 9424, 7354, 8334, 7132, 8413, 8951, 8581],
}


@pytest.fixture(scope="module")
def aalto(shared_data: Path) -> dict[tuple[str, int], MagneticSamples]:
    folder = shared_data / "magnetic" / "aalto"
    return {
        (sensor, run): read_aalto_run(folder / sensor / str(run))
        for sensor in AALTO_ROWS
        for run in range(1, 10)
    }


def test_aalto_runs_rows_area_and_rate(aalto) -> None:
    for (sensor, run), s in aalto.items():
        assert len(s) == AALTO_ROWS[sensor][run - 1], (sensor, run)
        assert s.dimension == 2 and s.units == "uT"
        # Vicon positions inside the ~6 m x 6 m tracked area.
        assert np.all(s.positions >= [-1.5, -3.7]) and np.all(s.positions <= [5.0, 1.5])
        assert np.ptp(s.positions, axis=0).max() < 6.0
        # 50 Hz, times increasing, about three minutes.
        assert np.all(np.diff(s.times) > 0)
        assert np.median(np.diff(s.times)) == pytest.approx(0.02, abs=1e-3)
        assert 120.0 < s.times[-1] - s.times[0] < 200.0


def test_aalto_field_strength_plausible_in_the_static_runs(aalto) -> None:
    for run in range(1, 6):
        for sensor, low in (("invensense", 45.0), ("nexus", 38.0)):
            magnitude = np.median(aalto[sensor, run].magnitude)
            assert low < magnitude < 55.0, (sensor, run, magnitude)
    # Both sensors ride together: in run 1 their mean fields agree within 1.5 uT per component.
    difference = aalto["nexus", 1].field.mean(axis=0) - aalto["invensense", 1].field.mean(axis=0)
    assert np.all(np.abs(difference) < 1.5)


def test_aalto_nexus_vertical_offset_drifts(aalto) -> None:
    """A property of the recording that users of runs 5-9 must know: the Nexus's z component
    departs from the InvenSense's (10 uT in run 5, 40 uT in run 8) while x and y agree within
    1.5 uT; the InvenSense's mean z stays within 6 uT of its run-1 value."""
    reference_z = aalto["invensense", 1].field[:, 2].mean()
    for run, low in ((5, 8.0), (8, 30.0)):
        difference = aalto["nexus", run].field.mean(0) - aalto["invensense", run].field.mean(0)
        assert np.all(np.abs(difference[:2]) < 1.5) and difference[2] > low, (run, difference)
        assert abs(aalto["invensense", run].field[:, 2].mean() - reference_z) < 6.0
