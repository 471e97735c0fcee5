# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Issue "bounded numbers", the file side: every int and float field of every pydantic model of
kiseki's file readers (scene, objects, robots and sensors with their parameter dataclasses,
magnetic section, waypoint file, key script, ROS map YAML, command/trajectory/points CSVs,
magnetic map descriptions, route history, experiment configs) declares its range.

The walk reads each model's pydantic core schema (where Field, Annotated and constrained types
have been merged, so the convention is pydantic's own: ``ge``/``gt`` and ``le``/``lt`` on the
number, ``allow_inf_nan=False`` on a float, i.e. kiseki._support.schema's number types), recursing
into nested models, dataclasses, lists, tuples, dicts, unions and validator wrappers. A number is
bounded when:

- an int has a lower and an upper bound inside int32, or is kiseki._support.schema.Seed (its
validator
  checks [0, 2**64), the C++ core's uint64 seeds);
- a float is finite (allow_inf_nan=False) and has a finite lower and upper bound.

Then 0, -1, 2**31, 2**63, 1e308, NaN and inf are fed to every number, alone (its own schema)
and inside a minimal valid document of its model where one is written below: a value is either
accepted and inside the declared bounds, or refused with pydantic's ValidationError; never
another exception."""

from __future__ import annotations

import copy
import importlib
import math
import time

import pytest
from pydantic import BaseModel, ValidationError
from pydantic_core import SchemaValidator

MODULES = (
    "kiseki._support.schema",
    "kiseki.io.map_schema",
    "kiseki.io.trajectory_csv",
    "kiseki.magnetic.points_csv",
    "kiseki.magnetic.map_doc",
    "kiseki.magnetic.linear_map_folder",
    "kiseki.serve.app",
    "kiseki.serve.history",
    "kiseki.sim.command_schema",
    "kiseki.sim.magnetic_schema",
    "kiseki.sim.primitives_schema",
    "kiseki.sim.scene_schema",
    "kiseki.sim.setup_schema",
    "kiseki.teach.key_script_schema",
    "kiseki.teach.waypoint_schema",
    "kiseki_experiments.harness.config",
    "kiseki_experiments.harness.runner",
    "kiseki_experiments.harness.registry",
)

INT32 = (-(2**31), 2**31 - 1)
PROBES = (0, -1, 2**31, 2**63, 1e308, math.nan, math.inf)
WALK_BUDGET_S = 20.0

# Numbers that do not reach C++ as numbers, each with its reason: (model, field path).
ALLOWED = {
    ("MagneticMapDoc", "octomap_key_origin[0]"): (
        "written for OctoMap users (origin / resolution + 32768), never read back by kiseki "
        "nor passed to C++"
    ),
}


def _models() -> list[type[BaseModel]]:
    """Every pydantic model defined in kiseki's and kiseki_experiments' modules, with the
    models built at run time (a trajectory CSV's row, each experiment's config)."""
    for name in MODULES:
        importlib.import_module(name)
    from kiseki.io.trajectory_csv import _row_model
    from kiseki_experiments.harness.config import _model
    from kiseki_experiments.harness.registry import all_experiments

    extra = [_row_model(("t", "x", "y", "theta"))]
    extra += [_model(e.config_type, name) for name, e in sorted(all_experiments().items())]
    found: dict[str, type[BaseModel]] = {}
    todo = [BaseModel]
    while todo:
        cls = todo.pop()
        todo += cls.__subclasses__()
        if cls.__module__.startswith(("kiseki.", "kiseki_experiments.")) and "[" not in (
            cls.__name__
        ):
            found[f"{cls.__module__}.{cls.__qualname__}"] = cls
    for cls in extra:
        found[f"{cls.__module__}.{cls.__qualname__}"] = cls
    return [found[k] for k in sorted(found)]


def _constraint(function) -> dict:
    """The constraint of one of pydantic's own validators, as pydantic applies ``Field``
    constraints that follow a validator in ``Annotated`` (``forbid_inf_nan_check``, a
    ``partial(greater_than_validator, gt=0)``, ...); {} for any other function."""
    name = getattr(getattr(function, "func", function), "__name__", "")
    if not getattr(getattr(function, "func", function), "__module__", "").startswith("pydantic"):
        return {}
    if name == "forbid_inf_nan_check":
        return {"allow_inf_nan": False}
    keywords = getattr(function, "keywords", None) or {}
    return {k: v for k, v in keywords.items() if k in ("ge", "gt", "le", "lt")}


def _leaves(schema: dict, path: tuple, defs: dict, ctx: dict | None, seen: frozenset) -> list:
    """(path, leaf: the int or float schema with the constraints around it merged in, the
    whole schema of the number with its validators) of every int and float in ``schema``."""
    if ctx is None:  # a new number starts here: a field, an item, a union's choice
        ctx = {"outer": schema, "extra": {}, "seed": False}
    kind = schema["type"]

    def inner(sub: dict, sub_path: tuple = path, keep: bool = False) -> list:
        return _leaves(sub, sub_path, defs, ctx if keep else None, seen)

    if kind == "definitions":
        defs = {**defs, **{d["ref"]: d for d in schema["definitions"]}}
        return _leaves(schema["schema"], path, defs, ctx, seen)
    if kind == "definition-ref":
        ref = schema["schema_ref"]
        return [] if ref in seen else _leaves(defs[ref], path, defs, ctx, seen | {ref})
    if kind in ("int", "float"):
        leaf = {**schema, **ctx["extra"]}
        if ctx["seed"]:
            leaf["seed"] = True
        return [(path, leaf, ctx["outer"])]
    if kind.startswith("function-") and "schema" in schema:
        function = schema["function"]["function"]
        if kind == "function-before" and _is_seed(function):
            ctx = {**ctx, "seed": True}
        if kind == "function-after":
            ctx = {**ctx, "extra": {**ctx["extra"], **_constraint(function)}}
        return _leaves(schema["schema"], path, defs, ctx, seen)
    if kind in ("nullable", "default", "lax-or-strict"):
        return _leaves(schema.get("schema") or schema["strict_schema"], path, defs, ctx, seen)
    if kind in ("model", "dataclass"):
        return inner(schema["schema"])
    if kind in ("model-fields", "dataclass-args"):
        fields = schema["fields"]
        items = fields.items() if isinstance(fields, dict) else [(f["name"], f) for f in fields]
        out = []
        for name, field in items:
            out += inner(field["schema"], (*path, field.get("validation_alias") or name))
        return out
    if kind == "list":
        return inner(schema.get("items_schema", {"type": "any"}), (*path, 0))
    if kind == "tuple":
        out = []
        for i, item in enumerate(schema["items_schema"]):
            out += inner(item, (*path, i))
        return out
    if kind == "dict":
        keys = inner(schema.get("keys_schema", {"type": "any"}), (*path, "*key"))
        return keys + inner(schema.get("values_schema", {"type": "any"}), (*path, "*"))
    if kind in ("union", "tagged-union"):
        choices = schema["choices"]
        choices = choices.values() if isinstance(choices, dict) else choices
        out = []
        for choice in choices:
            out += inner(choice[0] if isinstance(choice, tuple) else choice)
        return out
    if kind == "chain":
        out = []
        for step in schema["steps"]:
            out += inner(step)
        return out
    # str, bool, literal, any, function-plain (its own model is walked on its own), ...
    return []


def _text(path: tuple) -> str:
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else ("." if out else "") + str(p)
    return out


def _is_seed(function) -> bool:
    return getattr(function, "__qualname__", "") == "_seed" and function.__module__ == (
        "kiseki._support.schema"
    )


def _range(leaf: dict) -> tuple[float, bool, float, bool] | None:
    """(low, low inclusive, high, high inclusive) of a number, or None when it has none."""
    if leaf["type"] == "int" and leaf.get("seed"):
        return (0, True, 2**64 - 1, True)
    low = ("ge", True) if "ge" in leaf else ("gt", False) if "gt" in leaf else None
    high = ("le", True) if "le" in leaf else ("lt", False) if "lt" in leaf else None
    if low is None or high is None:
        return None
    return (leaf[low[0]], low[1], leaf[high[0]], high[1])


def _problem(leaf: dict) -> str | None:
    bounds = _range(leaf)
    if leaf["type"] == "float":
        if leaf.get("allow_inf_nan", True):
            return "a float that may be NaN or infinite (allow_inf_nan=False, FiniteFloat)"
        if bounds is None or not all(math.isfinite(b) for b in bounds[::2]):
            return "a float without a finite lower and upper bound (ge/gt and le/lt)"
        return None
    if bounds is None:
        return "an int without a lower and upper bound (ge/gt and le/lt)"
    if not leaf.get("seed") and not (INT32[0] <= bounds[0] and bounds[2] <= INT32[1]):
        return f"an int whose bounds {bounds[0]}..{bounds[2]} leave int32"
    return None


def _inside(value, bounds) -> bool:
    low, low_in, high, high_in = bounds
    if isinstance(value, float) and not math.isfinite(value):
        return False
    return (low <= value if low_in else low < value) and (
        value <= high if high_in else value < high
    )


@pytest.fixture(scope="module")
def numbers():
    """(model, path, leaf schema, whole schema) of every number of every model."""
    out = []
    for model in _models():
        schema = model.__pydantic_core_schema__
        for path, leaf, whole in _leaves(schema, (), {}, None, frozenset()):
            out.append((model, path, leaf, whole))
    return out


def test_the_walk_finds_the_files_numbers(numbers):
    names = {(m.__name__, _text(p)) for m, p, _, _ in numbers}
    for expected in [
        ("SceneDoc", "grid_resolution"),
        ("Shelf", "levels"),
        ("Rubble", "seed"),
        ("Route", "waypoints[0][1]"),
        ("DiffDriveSpec", "params.encoder_counts_per_rev"),
        ("LaserSpec", "params.beams"),
        ("MagneticSection", "lattices[0].spacing"),
        ("WaypointFile", "waypoints[0].truth[2]"),
        ("DiffDriveCommand", "v"),
        ("KeyLine", "time"),
        ("RosMapYaml", "origin[2]"),
        ("MagneticMapDoc", "shape.x"),
        ("LinearMapDoc", "nodes"),
        ("TrajectoryRow", "x"),
    ]:
        assert expected in names, expected
    assert len({m for m, _, _, _ in numbers}) > 40  # with the experiments' configs


def test_every_number_is_bounded(numbers):
    problems = []
    for model, path, leaf, _ in numbers:
        if (model.__name__, _text(path)) in ALLOWED:
            continue
        problem = _problem(leaf)
        if problem:
            problems.append(f"{model.__module__}.{model.__qualname__}.{_text(path)}: {problem}")
    assert not problems, "\n".join(sorted(set(problems)))


def test_the_allow_list_names_real_fields(numbers):
    names = {(m.__name__, _text(p)) for m, p, _, _ in numbers}
    assert set(ALLOWED) <= names


def _alone(schema: dict) -> dict:
    """The schema of a number without its model's field validators that read the other fields
    (``ValidationInfo.data``: there are none when the number is validated alone)."""
    if schema["type"].startswith("function-") and "schema" in schema:
        inner = _alone(schema["schema"])
        if schema["function"]["type"] == "with-info":
            return inner
        return {**schema, "schema": inner}
    if schema["type"] in ("nullable", "default"):
        return {**schema, "schema": _alone(schema["schema"])}
    return schema


def _probe_alone(leaf: dict, whole: dict) -> list[str]:
    validator = SchemaValidator(_alone(whole))
    bounds = _range(leaf)
    bad = []
    for value in PROBES:
        try:
            got = validator.validate_python(value)
        except ValidationError:
            continue
        except Exception as err:  # noqa: BLE001 (the point: nothing but a ValidationError)
            bad.append(f"{value!r}: {type(err).__name__}: {err}")
            continue
        if bounds is None or not _inside(got, bounds):
            bad.append(f"{value!r} accepted outside {bounds}")
    return bad


def test_every_number_refuses_what_leaves_its_bounds(numbers):
    start = time.perf_counter()
    problems = []
    for model, path, leaf, whole in numbers:
        if (model.__name__, _text(path)) in ALLOWED:
            continue
        for bad in _probe_alone(leaf, whole):
            problems.append(f"{model.__qualname__}.{_text(path)}: {bad}")
    assert not problems, "\n".join(sorted(set(problems)))
    assert time.perf_counter() - start < WALK_BUDGET_S


# --------------------------------------------------------------- inside minimal documents

_OBJECTS = [
    {"type": "wall", "from": [0, 0], "to": [1, 0]},
    {"type": "box", "center": [1, 1], "size": [0.2, 0.2, 0.2]},
    {"type": "workbench", "center": [2, 2], "size": [1, 0.5]},
    {"type": "shelf", "center": [3, 3], "size": [1, 0.4], "items": 1},
    {"type": "slope", "center": [4, 4], "size": [1, 1], "rise": 0.1},
    {"type": "rubble", "center": [5, 5], "radius": 0.5, "count": 2},
    {"type": "beam", "from": [0, 1], "to": [1, 1], "size": [0.1, 0.1], "z": 1},
    {"type": "pillar", "center": [6, 6], "size": [0.3, 0.3]},
]
_SHA1 = "0" * 40


def _documents() -> dict[str, list[dict]]:
    from kiseki_experiments.harness.registry import all_experiments

    docs: dict[str, list[dict]] = {
        "SceneDoc": [
            {
                "bounds": {"min": [-1, -1, 0], "max": [10, 10, 3]},
                "objects": _OBJECTS,
                "route": {"waypoints": [[0, 0], [1, 1]], "speed": 0.5},
                "pedestrians": [{"name": "p", "start": [1, 1], "velocity": [0, 0.5]}],
                "magnetic": {},
                "measurement_grid": {"lower": [0, 0, 0], "upper": [1, 1, 0], "spacing": 0.5},
                "robot": {"params": {}, "odometry_errors": {}, "start": [0, 0, 0]},
                "sensors": [{"type": "laser", "rate_hz": 10}],
            },
            {
                "robots": [{"name": "a"}, {"name": "b", "start": [1, 0, 0]}],
                "turns": {"goal": [1, 1], "moves": [{"robot": "a", "to": [1, 1]}]},
            },
            {"poses": {"corner": [0, 0], "distance": 1, "phi_deg": [0, 90, 10], "heading_deg": 0}},
        ],
        "WaypointFile": [
            {
                "maps": {"band": {"file": "m.yaml", "image_sha1": _SHA1}},
                "waypoints": [
                    {"id": 0, "name": "P0", "x": 0, "y": 0, "theta": 0, "truth": [0, 0, 0]}
                ],
            }  # fmt: skip
        ],
        "RosMapYaml": [{"image": "m.pgm", "resolution": 0.05, "origin": [0, 0, 0]}],
        "MapBuildSettings": [{}],
        "DiffDriveCommand": [{"t": "0", "v": "0.5", "w": "0"}],
        "OmniCommand": [{"t": "0", "vx": "0.5", "vy": "0", "w": "0"}],
        "KeyLine": [{"time": "0", "keys": ["w"]}],
        "Point3": [{"x": "0", "y": "0", "z": "0"}],
        "MagneticSection": [
            {
                "earth_field": {"total": 0.5, "inclination_deg": 60},
                "dipoles": [{"position": [0, 0, 0], "moment": [0, 0, 1]}],
                "lines": [{"start": [0, 0, 0], "end": [1, 0, 0], "moment_per_metre": [0, 1, 0]}],
                "lattices": [
                    {"lower": [0, 0, 0], "upper": [1, 1, 0], "spacing": 0.5, "moment_sd": [1, 1, 1]}
                ],
                "gradient": [[0, 0, 0], [0, 0, 0], [0, 0, 0]],
                "gradient_origin": [0, 0, 0],
                "drift": {"amplitude": 0.01, "period": 100, "phase": 0},
            }  # fmt: skip
        ],
        "ArmSpec": [{"inner": 0.2, "heights": [0.1, 0.5], "period": 10}],
        "MagneticMapDoc": [
            {
                "kind": "magnetic_field_map",
                "format_version": 1,
                "dimension": 3,
                "origin": [0, 0, 0],
                "resolution": 0.25,
                "shape": {"x": 4, "y": 3, "z": 2},
                "units": "uT",
                "prior_mean": [0, 0, 0],
                "prior_variance": [1, 1, 1],
                "kernel": {
                    "mx": {"sigma_f": 1, "length_scale": 1, "sigma_n": 0.1},
                    "my": {"sigma_f": 1, "length_scale": 1, "sigma_n": 0.1},
                    "mz": {"sigma_f": 1, "length_scale": 1, "sigma_n": 0.1},
                },
                "height": 0.5,
                "training": {"points": 10},
                "files": {},
            }  # fmt: skip
        ],
        "LinearMapDoc": [
            {
                "kind": "linear_magnetic_map",
                "format_version": 1,
                "node_spacing": 0.1,
                "nodes": 5,
                "first_node_s": 0,
                "path_id": _SHA1,
                "units": "G",
                "sensor_frame": "x forward, y right, z down",
                "geometric_window": {"range_m": 2, "angle_deg": 30},
                "travel_distance": "odometry",
                "kiseki_version": "0",
                "files": {"nodes": "n"},
            }  # fmt: skip
        ],
    }
    for kind in ("DiffDriveSpec", "OmniSpec"):
        docs[kind] = [
            {
                "type": "omni" if kind == "OmniSpec" else "diff_drive",
                "start": [0, 0, 0],
                "params": {},
                "odometry_errors": {},
            }  # fmt: skip
        ]
    for kind in ("laser", "depth_camera", "bearing", "tilting_laser"):
        name = "".join(w.title() for w in kind.split("_")) + "Spec"
        docs[name] = [{"type": kind, "mount": [0, 0, 0.5, 0], "rate_hz": 10, "params": {}}]
    for obj in _OBJECTS:
        from kiseki.sim.primitives_schema import MODELS

        docs.setdefault(MODELS[obj["type"]].__name__, []).append(obj)
    for experiment in all_experiments().values():
        docs.setdefault(f"{experiment.config_type.__name__}Model", [{}])
    return docs


def _set(doc, path: tuple, value) -> bool:
    """``doc`` with the number at ``path`` set to ``value`` (a missing last key of a mapping is
    added); False when the path is not in the document (an optional section left out)."""
    node = doc
    for i, key in enumerate(path):
        last = i == len(path) - 1
        if key == "*key":
            return False
        if isinstance(node, dict):
            key = next(iter(node), None) if key == "*" else key
            if key is None or (key not in node and not last):
                return False
            if last:
                node[key] = value
                return True
            node = node[key]
        elif isinstance(node, list) and isinstance(key, int):
            if key >= len(node):
                return False
            if last:
                node[key] = value
                return True
            node = node[key]
        else:
            return False
    return False


def test_every_number_inside_a_document(numbers):
    start = time.perf_counter()
    docs = _documents()
    problems, probed = [], 0
    for model, path, leaf, _ in numbers:
        if (model.__name__, _text(path)) in ALLOWED:
            continue
        bounds = _range(leaf)
        for base in docs.get(model.__name__, []):
            for value in PROBES:
                doc = copy.deepcopy(base)
                if not _set(doc, path, value):
                    continue
                probed += 1
                try:
                    model.model_validate(doc)
                except ValidationError:
                    continue
                except Exception as err:  # noqa: BLE001 (nothing but a ValidationError)
                    problems.append(f"{model.__name__}.{_text(path)} = {value!r}: {err!r}")
                    continue
                if bounds is None or not _inside(value, bounds):
                    problems.append(f"{model.__name__}.{_text(path)} = {value!r} accepted")
    assert not problems, "\n".join(problems)
    assert probed > 1000
    assert time.perf_counter() - start < WALK_BUDGET_S


def test_the_minimal_documents_are_valid():
    """The documents above are valid as written (else the probes above prove nothing)."""
    models = {m.__name__: m for m in _models()}
    for name, docs in _documents().items():
        for doc in docs:
            models[name].model_validate(doc)
