# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""What an input stands for, for the output guard (:mod:`kiseki._support.outputs`): the input
itself, the files it names (a ROS map YAML's image, a scene's octree, a waypoint file's maps and
their images), the files of an Aalto run prefix, and the folder it is or belongs to (a ROS 2 bag).
YAML inputs are looked into as kiseki's readers read them, without building the document."""

from __future__ import annotations

import glob
from collections.abc import Iterator
from pathlib import Path

import yaml

from kiseki._support.inputs import YAML_LIMIT, read_input_text
from kiseki._support.yaml import _Loader12, safe_load_12

__all__ = ["WALK_DEPTH", "WALK_ENTRIES", "files_behind", "input_files", "input_folder"]

# the listing of an input folder for links to its files, and of an existing output folder for
# links to inputs: at most this deep (the folder itself is depth 1) and this many entries in all
WALK_DEPTH, WALK_ENTRIES = 3, 5000
_STR = "tag:yaml.org,2002:str"


def _beside(path: Path, name: str) -> Path:
    named = Path(name)
    return named if named.is_absolute() else path.parent / named


def _yaml_doc(path: Path):
    """What a YAML input's document says under the keys that name files (its top-level
    mapping with only ``image``, ``octomap`` and ``maps``), or None (not YAML, unreadable: the
    reader itself reports what is wrong with it). Any YAML file kiseki's readers accept is
    looked into: read as they read it, in pieces and at most
    :data:`kiseki._support.inputs.YAML_LIMIT` bytes (larger, or a device: None, the reader refuses
    it), then scanned with libyaml's event parser (:func:`_scan`, a fraction of a second a
    MB), or where that cannot tell (an alias, a merge key), loaded whole as the readers load
    it."""
    if path.suffix.lower() not in (".yaml", ".yml"):
        return None
    try:
        if not path.is_file():
            return None
        text = read_input_text(path, "YAML files", YAML_LIMIT)
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    if getattr(yaml, "__with_libyaml__", False):
        try:
            return _scan(yaml.parse(text, Loader=yaml.CSafeLoader))
        except (_NeedsLoadError, yaml.YAMLError, RuntimeError, StopIteration):
            pass  # an alias or a merge key; or what libyaml refuses: as the readers read it
    try:
        return safe_load_12(text)
    except yaml.YAMLError:
        return None


class _NeedsLoadError(Exception):
    """The event stream alone cannot tell a key's value (an alias, a merge key ``<<``)."""


_STARTS = frozenset((yaml.MappingStartEvent, yaml.SequenceStartEvent))
_ENDS = frozenset((yaml.MappingEndEvent, yaml.SequenceEndEvent))


def _skip(events: Iterator[yaml.Event], first: yaml.Event) -> None:
    """Consumes the rest of the node that starts with ``first``."""
    if type(first) not in _STARTS:
        return
    depth = 1
    for event in events:
        if type(event) in _STARTS:
            depth += 1
        elif type(event) in _ENDS:
            depth -= 1
            if not depth:
                return
    raise yaml.YAMLError("unexpected end of the events")


_RESOLVER = _Loader12("")  # the readers' tags for plain scalars (YAML 1.2's core schema)


def _string(event: yaml.Event) -> str | None:
    """A scalar's text when the readers take it as a string, else None; an alias raises."""
    if isinstance(event, yaml.AliasEvent):
        raise _NeedsLoadError
    if not isinstance(event, yaml.ScalarEvent):
        return None
    tag = event.tag
    if tag in (None, "!"):
        tag = _RESOLVER.resolve(yaml.ScalarNode, event.value, event.implicit)
    if tag == "tag:yaml.org,2002:merge":
        raise _NeedsLoadError
    return event.value if tag == _STR else None


def _items(events: Iterator[yaml.Event]) -> Iterator[tuple[str | None, yaml.Event]]:
    """After a mapping's start: (its key as a string or None, the first event of its value)
    for each pair; the caller reads or skips the value before the next."""
    while not isinstance(key := next(events), yaml.MappingEndEvent):
        name = _string(key)
        _skip(events, key)  # a key that is a mapping or a list: no file name
        yield name, next(events)


def _scan(events: Iterator[yaml.Event]) -> dict | None:
    """The top-level mapping's ``image``, ``octomap`` and ``maps`` from a document's events, without
    building the rest (``maps``' entries by their order: only their ``file`` is kept); a key
    given twice is taken as the readers take it, the last one."""
    starts = (yaml.StreamStartEvent, yaml.DocumentStartEvent)
    root = next(e for e in events if not isinstance(e, starts))
    if not isinstance(root, yaml.MappingStartEvent):
        return None
    doc: dict = {}
    for key, value in _items(events):
        if key in ("image", "octomap"):
            doc[key] = _string(value)
        elif key == "maps" and isinstance(value, yaml.MappingStartEvent):
            doc["maps"] = maps = {}
            for _, entry in _items(events):
                if isinstance(entry, yaml.MappingStartEvent):
                    maps[len(maps)] = fields = {}
                    for field, file in _items(events):
                        if field == "file":
                            fields["file"] = _string(file)
                        _skip(events, file)
                else:
                    _string(entry)  # an alias raises
                    _skip(events, entry)
            continue  # read to its end
        elif key == "maps":
            _string(value)  # an alias raises
        _skip(events, value)
    return doc


def _referred(path: Path, depth: int = 0) -> list[tuple[str, Path]]:
    """The files a YAML input names: a ROS map's ``image``, a scene's ``octomap``, a waypoint
    file's ``maps.*.file`` (and their images)."""
    doc = _yaml_doc(path)
    if not isinstance(doc, dict):
        return []
    out = [
        (key, _beside(path, doc[key]))
        for key in ("image", "octomap")
        if isinstance(doc.get(key), str) and doc[key]
    ]
    maps = doc.get("maps")
    if depth == 0 and isinstance(maps, dict):
        for entry in maps.values():
            if isinstance(entry, dict) and isinstance(entry.get("file"), str) and entry["file"]:
                named = _beside(path, entry["file"])
                out.append(("map", named))
                out += [(f"map's {what}", p) for what, p in _referred(named, 1)]
    return out


def input_files(path: Path) -> list[tuple[str, Path]]:
    """What an input stands for, as (what, path): the input itself (what ``""``), the files it
    refers to (:func:`_referred`), and for a name that is no file or folder, an Aalto run prefix
    ``DIR/N``, its existing ``DIR/N-*.csv`` files (what ``"run file"``)."""
    path = Path(path)
    out = [("", path)] + _referred(path)
    if not path.exists() and path.name and path.parent.is_dir():
        parts = sorted(path.parent.glob(f"{glob.escape(path.name)}-*.csv"))[:WALK_ENTRIES]
        out += [("run file", p) for p in parts]
    return out


def files_behind(path: Path) -> list[Path]:
    """The file itself and the files it refers to (:func:`input_files`)."""
    return [p for _, p in input_files(path)]


def input_folder(path: Path) -> Path | None:
    """The folder an input is, or belongs to: itself when a folder; for a ROS 2 storage file
    (``.db3``, ``.mcap``) beside a ``metadata.yaml``, its bag folder; else None."""
    path = Path(path)
    if path.is_dir():
        return path
    if path.suffix.lower() in (".db3", ".mcap") and (path.parent / "metadata.yaml").is_file():
        return path.parent
    return None
