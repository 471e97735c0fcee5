# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Recorded magnetic-field samples: positions, the field vector there, its units.

Three sources give :class:`~kiseki.datasets.magnetic_samples.MagneticSamples` (the type, with
:func:`~kiseki.datasets.magnetic_samples.concatenate_samples`, lives in
:mod:`kiseki.datasets.magnetic_samples` and is importable from here too):

* a CSV with a header naming the columns ``x,y[,z],mx,my,mz`` (any order, other columns ignored;
  an optional ``t`` or ``time`` column gives the times): :func:`read_field_csv`;
* a run in the layout of the Aalto robot data (Solin et al., IEEE T-RO 2018), named by its prefix
  ``DIR/N`` for ``DIR/N-loc.csv`` (x, y in m), ``DIR/N-mag.csv`` (field in uT, already in the world
  frame) and ``DIR/N-time.csv`` (s), comma-separated without a header: :func:`read_aalto_run`;
* a MATLAB v5 hand-held walk in the layout of Kok and Solin (MFI 2024):
  :func:`kiseki.datasets.kok.read_kok_walk`.

:func:`read_magnetic_data` picks the reader from the name. Bad files raise
:class:`~kiseki.errors.LogFormatError` (a ``ValueError``) naming the file and the line; a missing
file raises ``FileNotFoundError`` naming it.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from kiseki._support.inputs import CSV_LIMIT, check_input, read_input
from kiseki._support.numbers_text import is_number, parse_float
from kiseki.datasets.kok import read_kok_walk
from kiseki.datasets.magnetic_samples import UNITS, MagneticSamples, concatenate_samples
from kiseki.errors import LogFormatError

__all__ = [
    "UNITS",
    "MagneticSamples",
    "concatenate_samples",
    "read_aalto_run",
    "read_field_csv",
    "read_magnetic_data",
]

_CSV_COLUMNS = ("x", "y", "z", "mx", "my", "mz", "t")
_AALTO_PARTS = (("loc", 2, "x, y"), ("mag", 3, "mx, my, mz"), ("time", 1, "t"))


def read_field_csv(path: str | os.PathLike, units: str = "unknown") -> MagneticSamples:
    """Samples from a CSV whose header names ``x,y[,z],mx,my,mz`` (any order, case ignored,
    other columns ignored; ``t`` or ``time`` read as times). ``units`` states the field's units
    ("uT", "G" or "unknown")."""
    path = Path(path)
    if units not in UNITS:
        raise ValueError(f"{path}: units {units!r} not one of {', '.join(UNITS)}")
    lines = _numbered_lines(path)
    if not lines:
        raise LogFormatError(f"{path}: empty file: expected a header x,y[,z],mx,my,mz and rows")
    header_line, header = lines[0]
    names = [name.strip().strip('"').strip().lower() for name in header.split(",")]
    columns = _header_columns(path, header_line, names)
    present = [name for name in _CSV_COLUMNS if name in columns]
    table = _parse_rows(path, lines[1:], len(names), [columns[n] for n in present], header)
    if len(table) == 0:
        raise LogFormatError(f"{path}: header but no data rows")
    values = dict(zip(present, table.T, strict=True))
    coords = ("x", "y", "z") if "z" in columns else ("x", "y")
    return MagneticSamples(
        positions=np.column_stack([values[c] for c in coords]),
        field=np.column_stack([values["mx"], values["my"], values["mz"]]),
        units=units,
        source=str(path),
        times=values.get("t"),
    )


def read_aalto_run(prefix: str | os.PathLike) -> MagneticSamples:
    """One run in the Aalto layout: ``DIR/N`` names ``DIR/N-loc.csv``, ``DIR/N-mag.csv`` and
    ``DIR/N-time.csv`` (comma-separated, no header, one row per sample). The field is in uT and
    already in the motion-capture (world) frame; positions are 2-D."""
    prefix = str(prefix)
    paths = {part: Path(f"{prefix}-{part}.csv") for part, _, _ in _AALTO_PARTS}
    for path in paths.values():
        check_input(path, error=LogFormatError)
    missing = [str(p) for p in paths.values() if not p.is_file()]
    if missing:
        raise FileNotFoundError(
            f"{prefix}: not an Aalto run: missing {', '.join(missing)} "
            "(a run DIR/N needs DIR/N-loc.csv, DIR/N-mag.csv and DIR/N-time.csv)"
        )
    tables = {}
    for part, count, names in _AALTO_PARTS:
        path = paths[part]
        tables[part] = _parse_rows(path, _numbered_lines(path), count, list(range(count)), names)
        if len(tables[part]) == 0:
            raise LogFormatError(f"{path}: no rows")
    rows = {part: len(table) for part, table in tables.items()}
    for part in ("mag", "time"):
        if rows[part] != rows["loc"]:
            raise LogFormatError(
                f"{prefix}: {paths['loc']} has {rows['loc']} rows but {paths[part]} has "
                f"{rows[part]}: one row per sample in each file"
            )
    return MagneticSamples(
        positions=tables["loc"],
        field=tables["mag"],
        units="uT",
        source=prefix,
        times=tables["time"][:, 0],
    )


def read_magnetic_data(spec: str | os.PathLike) -> MagneticSamples:
    """Samples from ``spec``: an existing ``.csv`` file is read by :func:`read_field_csv` (units
    "unknown"), a ``.mat`` file by :func:`kiseki.datasets.kok.read_kok_walk`, anything else is
    taken as an Aalto run prefix (:func:`read_aalto_run`)."""
    path = Path(spec)
    suffix = path.suffix.lower()
    if suffix == ".mat":
        return read_kok_walk(path)
    if suffix == ".csv":
        if not path.exists():
            raise FileNotFoundError(f"{path}: file not found")
        return read_field_csv(path)
    if path.is_file():
        raise LogFormatError(
            f"{path}: not magnetic data: expected a .csv with columns x,y[,z],mx,my,mz, a .mat "
            "walk, or an Aalto run prefix DIR/N"
        )
    return read_aalto_run(spec)


def _numbered_lines(path: Path) -> list[tuple[int, str]]:
    """The file's non-blank lines with their 1-based line numbers (a file of at most
    :data:`kiseki._support.inputs.CSV_LIMIT` bytes)."""
    check_input(path, error=LogFormatError)
    if path.is_dir():
        raise LogFormatError(f"{path}: a directory, not a file")
    if not path.is_file():
        raise FileNotFoundError(f"{path}: file not found")
    data = read_input(path, "magnetic sample CSVs", CSV_LIMIT, LogFormatError)
    if b"\x00" in data:
        raise LogFormatError(f"{path}: binary data, not a comma-separated text table")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise LogFormatError(
            f"{path}: not a text table (byte {exc.start} is not valid UTF-8)"
        ) from exc
    return [(k + 1, line) for k, line in enumerate(text.splitlines()) if line.strip()]


def _header_columns(path: Path, line: int, names: list[str]) -> dict[str, int]:
    if all(is_number(name) for name in names):
        raise LogFormatError(
            f"{path}: line {line}: no header: the first line must name the columns "
            "x,y[,z],mx,my,mz (an Aalto run is named by its prefix DIR/N, not by one of its files)"
        )
    aliases = {"time": "t"}
    columns: dict[str, int] = {}
    for k, name in enumerate(names):
        name = aliases.get(name, name)
        if name in _CSV_COLUMNS:
            if name in columns:
                raise LogFormatError(f"{path}: line {line}: column {name!r} given twice")
            columns[name] = k
    missing = [name for name in ("x", "y", "mx", "my", "mz") if name not in columns]
    if missing:
        raise LogFormatError(
            f"{path}: line {line}: header lacks {', '.join(missing)} "
            f"(needs x,y[,z],mx,my,mz; found {','.join(names)})"
        )
    return columns


def _parse_rows(
    path: Path, lines: list[tuple[int, str]], count: int, wanted: list[int], names: str
) -> np.ndarray:
    """The wanted columns of comma-separated rows of exactly ``count`` fields, as float64."""
    if lines:
        try:  # numpy's parser first; the loop below finds the line of any error
            table = np.loadtxt([t for _, t in lines], delimiter=",", comments=None, ndmin=2)
            if table.shape == (len(lines), count):
                return table[:, wanted]
        except ValueError:
            pass
    table = np.empty((len(lines), len(wanted)))
    for row, (line, text) in enumerate(lines):
        fields = text.split(",")
        if len(fields) != count:
            raise LogFormatError(
                f"{path}: line {line}: {len(fields)} columns, expected {count} ({names})"
            )
        for j, k in enumerate(wanted):
            try:
                table[row, j] = parse_float(fields[k])
            except ValueError:
                raise LogFormatError(
                    f"{path}: line {line}: column {k + 1} is not a number: {fields[k].strip()!r}"
                ) from None
    return table
