# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Seeded factory layouts around the teaching-and-playback thesis' route with a turn (Exp. 2/3).

The thesis (000_7c5a0f8de3fa28f5.txt) gives only the route's displacement (10.29 m in x,
-3.29 m in y) and says that workbenches, shelves and machine tools line the aisles, the goal
waypoint standing in front of a parts shelf. ``data/worlds/factory_turn.yaml`` is one layout
that fits; :func:`generate_layout` draws others. Every layout keeps that scene's robot, sensors,
start and route (P0 (0, 0) -> T1 (7, 0) -> T2 (7, -3.29) -> G (10.29, -3.29), read from the
file), so only the surroundings change. Leg 1 runs east from P0, leg 2 south from T1, the final
leg east from T2 to G. Each leg's aisle is bounded on both sides by a boundary line; furniture
stands with its back on the line, its face toward the route.

Ranges (uniform unless said otherwise) and why:

- Aisle width per leg, boundary line to boundary line: 2.2-3.0 m (today's 2.6 m +- 0.4 m).
  Narrower, an aisle lined with 0.6-0.8 m benches on both sides leaves less than the AGV's
  0.58 m width plus margins; wider, the 0.5 m minimum range of the sideways cameras no longer
  matters, and the thesis' aisles are working aisles, not halls.
- The route's offset from the aisle's centre line: -0.1..0.1 m per leg (today's leg 2 is 0.05 m
  off centre); a taught route is pushed by hand, not centred.
- Furniture along every side of every leg, one item after another: a workbench (probability
  0.45; 1.0-1.8 m long, 0.6-0.8 m deep, top at 0.7-1.0 m: the thesis' Tables 3.1/3.2), a shelf
  (0.35; 0.9-1.8 m long, 0.4-0.6 m deep, 1.5-2.0 m high, 3-5 levels with 1-3 items each) or a
  machine tool (0.2; a solid block 0.8-1.6 m long, 0.6-1.0 m deep, 1.2-2.0 m high: the thesis
  names machine tools but not their size). Gaps between items 0.2-1.5 m, the first item
  0-1.0 m from the line's start. An item is made shallower so that at least ``MIN_CLEAR``
  (0.6 m, today's clearance in front of its benches) remains between the route and its face,
  and is left out when that leaves it under 0.3 m deep.
- The goal stands in front of a parts shelf (thesis, sec. 2.1.2): a shelf 1.2-1.8 m long,
  0.4-0.6 m deep, its centre within 0.3 m of G along the final leg, on a side drawn at random.
- Behind each of the final leg's two boundary lines (drawn independently, 1/3 each), because
  exp2-turn's report finds that the methods' ordering depends on what the plane at 0.4 m sees
  there: ``wall`` (a 2.5 m wall right behind the furniture, as today), ``aisle`` (another aisle:
  the space behind the furniture is free up to a second row of furniture standing against a
  wall 3.0-3.8 m behind the line) or ``open`` (an empty hall: the building's wall 5-8 m behind
  the line, where the Xtion-like cameras' depth error exceeds 5 cm and nears their 10 m range).
  Legs 1 and 2 keep walls behind their furniture, as today, so that the family varies what the
  report names and not the rest.
- The wall across the end of the final leg: 1.5-2.5 m beyond G (today 2.0 m), room for the
  AGV's 0.525 m half length and its braking. The wall behind P0 stays 1.4 m behind it.

A drawn layout is kept only when the route is free for the robot's footprint (1.05 x 0.58 m,
grown by ``ROUTE_MARGIN`` on every side) on the ground truth of the band 0.05-0.99 m (the robot's
height): along every leg with its heading, turning in place at T1 and T2, and along a 0.6 m
fillet at each turn (the pure-pursuit operator's 0.6 m lookahead cuts corners). Otherwise the
layout is redrawn from the next stream of its seed (``Layout.attempt`` counts them).
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from kiseki._support.inputs import YAML_LIMIT, read_input_text
from kiseki._support.yaml import safe_load_12
from kiseki.core import Random, derive_seed
from kiseki.sim.collisions import FootprintChecker, body_grid
from kiseki.sim.scene import Scene, load_scene

__all__ = [
    "BEHIND",
    "Layout",
    "generate_layout",
    "route_contact",
    "route_poses",
    "write_layout",
]

BASE_SCENE = Path(__file__).resolve().parents[3] / "data" / "worlds" / "factory_turn.yaml"
AISLE_WIDTH = (2.2, 3.0)  # m, boundary line to boundary line
ROUTE_OFFSET = (-0.1, 0.1)  # m, toward the leg's left
MIN_CLEAR = 0.6  # m, route to a furniture face (today's benches leave 0.6 m)
ROUTE_MARGIN = 0.1  # m, around the footprint: playback's estimate and stop errors
# m, a turn waypoint to furniture: the grown footprint turning in place, plus one 0.05 m cell
TURN_CLEAR = math.hypot(0.525 + ROUTE_MARGIN, 0.29 + ROUTE_MARGIN) + 0.05
MIN_DEPTH = 0.3  # m, shallower items are left out
GAP = (0.2, 1.5)  # m, between items along a line
FIRST = (0.0, 1.0)  # m, line start to the first item
END_GAP = (1.5, 2.5)  # m, G to the end wall's face
OTHER_AISLE_WALL = (3.0, 3.8)  # m, boundary line to the wall behind another aisle
OPEN_WALL = (5.0, 8.0)  # m, boundary line to the building's wall behind an open hall
GOAL_SHELF_LENGTH = (1.2, 1.8)
GOAL_SHELF_SHIFT = 0.3  # m, along the final leg
BEHIND = ("wall", "aisle", "open")
FILLET = 0.6  # m, the operator's pure-pursuit lookahead
MAX_ATTEMPTS = 50
WALL = {"height": 2.5, "thickness": 0.1}
# kind: (probability, length range, depth range, height range)
FURNITURE = {
    "workbench": (0.45, (1.0, 1.8), (0.6, 0.8), (0.7, 1.0)),
    "shelf": (0.35, (0.9, 1.8), (0.4, 0.6), (1.5, 2.0)),
    "machine": (0.20, (0.8, 1.6), (0.6, 1.0), (1.2, 2.0)),
}


@dataclass
class Layout:
    """A drawn layout: the scene as a mapping (kiseki.sim.scene's format), the parameters drawn,
    the seed and the attempt (stream of the seed) that gave a free route."""

    seed: int
    attempt: int
    params: dict
    doc: dict = field(repr=False)


class _Draw:
    def __init__(self, seed: int) -> None:
        self.rng = Random(seed)

    def u(self, lo_hi: tuple[float, float]) -> float:
        return float(self.rng.uniform(lo_hi[0], lo_hi[1], 1)[0])

    def pick(self, options, weights=None) -> str:
        weights = np.ones(len(options)) if weights is None else np.asarray(weights, dtype=float)
        r = self.u((0.0, float(weights.sum())))
        return options[int(min(np.searchsorted(np.cumsum(weights), r), len(options) - 1))]


def _wall(a, b) -> dict:
    ends = {"from": [round(a[0], 3), round(a[1], 3)], "to": [round(b[0], 3), round(b[1], 3)]}
    return {"type": "wall", **ends, **WALL}


def _item(d: _Draw, kind: str, at, u, n, length: float, depth: float, tag: str) -> dict:
    """One piece of furniture, its back centred on the line point `at`, facing along `n`."""
    c = np.asarray(at) + n * depth / 2
    yaw = round(math.degrees(math.atan2(u[1], u[0])), 3)
    center = [round(float(c[0]), 3), round(float(c[1]), 3)]
    height = d.u(FURNITURE[kind][3])
    size = [round(length, 3), round(depth, 3)]
    if kind == "workbench":
        spec = {"type": "workbench", "center": center, "size": size, "height": round(height, 3)}
    elif kind == "shelf":
        levels, items = 3 + int(d.rng.below(3)), 1 + int(d.rng.below(3))
        spec = {"type": "shelf", "center": center, "size": size, "height": round(height, 3)}
        spec |= {"levels": levels, "items": items, "seed": int(d.rng.below(1 << 30))}
    else:
        spec = {"type": "box", "center": center, "size": [*size, round(height, 3)]}
    return {**spec, "yaw": yaw, "id": tag}


def _clear_depth(at, u, n, size: float, depth: float, route: np.ndarray) -> float:
    """The largest depth, at most `depth` in 0.05 m steps, that keeps an item (its back centred
    on `at`) ``MIN_CLEAR`` from the route's legs and ``TURN_CLEAR`` from its turns; 0 if none."""
    along = np.linspace(-size / 2, size / 2, max(2, int(size / 0.05) + 1))
    while depth >= MIN_DEPTH:
        deep = np.linspace(0.0, depth, max(2, int(depth / 0.05) + 1))
        pts = np.vstack(
            [
                at + np.outer(along, u) + depth * n,
                at + np.outer(deep, n) - size / 2 * u,
                at + np.outer(deep, n) + size / 2 * u,
            ]
        )
        turns = np.linalg.norm(pts[:, None, :] - route[None, 1:-1, :], axis=2)
        if _distance_to_polyline(pts, route).min() >= MIN_CLEAR and turns.min() >= TURN_CLEAR:
            return depth
        depth -= 0.05
    return 0.0


def _distance_to_polyline(pts: np.ndarray, line: np.ndarray) -> np.ndarray:
    """(n,) distances of points (n, 2) from a polyline (m, 2)."""
    a, b = line[:-1], line[1:]
    ab = b - a
    t = ((pts[:, None, :] - a[None]) * ab[None]).sum(axis=2) / (ab * ab).sum(axis=1)[None]
    nearest = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.linalg.norm(pts[:, None, :] - nearest, axis=2).min(axis=1)


def _line(d: _Draw, a, b, n, route: np.ndarray, tag: str, reserved=()) -> list[dict]:
    """Furniture along the boundary line a -> b, faces along the unit normal n, each as deep as
    drawn or as :func:`_clear_depth` allows; `reserved` intervals (distance along the line) are
    kept clear."""
    a, b, n = (np.asarray(v, dtype=float) for v in (a, b, n))
    length = float(np.linalg.norm(b - a))
    u = (b - a) / length
    kinds = list(FURNITURE)
    weights = [FURNITURE[k][0] for k in kinds]
    out, s = [], d.u(FIRST)
    while True:
        kind = d.pick(kinds, weights)
        size, depth = d.u(FURNITURE[kind][1]), d.u(FURNITURE[kind][2])
        if s + size > length:
            return out
        clash = [r for r in reserved if s < r[1] and r[0] < s + size]
        if clash:
            s = max(r[1] for r in clash) + d.u(GAP)
            continue
        at = a + (s + size / 2) * u
        depth = _clear_depth(at, u, n, size, depth, route)
        if depth >= MIN_DEPTH:
            out.append(_item(d, kind, at, u, n, size, depth, f"{tag}_{kind}_{len(out)}"))
        s += size + d.u(GAP)


def _legs(d: _Draw) -> dict:
    """Each leg's distance from the route to its left and right boundary lines."""
    out = {}
    for leg in ("leg1", "leg2", "final"):
        width, offset = d.u(AISLE_WIDTH), d.u(ROUTE_OFFSET)
        out[f"{leg}_width"], out[f"{leg}_offset"] = width, offset
        out[f"{leg}_left"], out[f"{leg}_right"] = width / 2 - offset, width / 2 + offset
    return out


def _draw(seed: int, base: dict) -> tuple[dict, dict]:
    d = _Draw(seed)
    (x0, y0), (xt, _), _, (xg, yg) = base["route"]["waypoints"]
    p = _legs(d)
    p["final_left_behind"], p["final_right_behind"] = d.pick(BEHIND), d.pick(BEHIND)
    p["end_gap"] = d.u(END_GAP)
    yn1, ys1 = y0 + p["leg1_left"], y0 - p["leg1_right"]
    xe2, xw2 = xt + p["leg2_left"], xt - p["leg2_right"]
    yn3, ys3 = yg + p["final_left"], yg - p["final_right"]
    xs, xe = x0 - 1.4, xg + p["end_gap"]
    far = {}
    for side, line, sign in (("left", yn3, 1.0), ("right", ys3, -1.0)):
        behind = p[f"final_{side}_behind"]
        rng = {"wall": None, "aisle": OTHER_AISLE_WALL, "open": OPEN_WALL}[behind]
        p[f"final_{side}_wall_behind"] = 0.0 if rng is None else d.u(rng)
        far[side] = line + sign * p[f"final_{side}_wall_behind"]
    top, bottom = max(yn1, far["left"]), min(ys3, far["right"])
    t = WALL["thickness"] / 2
    objects = [
        _wall((xs - t, ys1 - 2 * t), (xs - t, yn1 + 2 * t)),
        _wall((xs - 2 * t, yn1 + t), (xe2 + 2 * t, yn1 + t)),
        _wall((xs - 2 * t, ys1 - t), (xw2 - t, ys1 - t)),
        _wall((xe2 + t, top + 2 * t), (xe2 + t, yn3)),
        _wall((xw2 - t, ys1 - t), (xw2 - t, bottom - 2 * t)),
        _wall((xe + t, bottom - 2 * t), (xe + t, top + 2 * t)),
        _wall((xe2, far["left"] + t), (xe + 2 * t, far["left"] + t)),
        _wall((xw2 - 2 * t, far["right"] - t), (xe + 2 * t, far["right"] - t)),
    ]
    # furniture: (tag, line start, line end, facing)
    lines = [
        ("leg1_left", (xs, yn1), (xe2 - 1.0, yn1), (0, -1)),
        ("leg1_right", (xs, ys1), (xw2, ys1), (0, 1)),
        ("leg2_left", (xe2, yn1), (xe2, yn3), (-1, 0)),
        ("leg2_right", (xw2, ys1), (xw2, ys3 + 1.0), (1, 0)),
        ("final_left", (xe2, yn3), (xe, yn3), (0, -1)),
        ("final_right", (xw2, ys3), (xe, ys3), (0, 1)),
    ]
    for side, sign in (("left", 1.0), ("right", -1.0)):
        if p[f"final_{side}_behind"] == "aisle":
            x_from = xe2 if side == "left" else xw2
            face = (0, -sign)
            lines.append((f"other_aisle_{side}", (x_from, far[side]), (xe, far[side]), face))
    p["goal_shelf_side"] = d.pick(["left", "right"])
    route = np.asarray(base["route"]["waypoints"], dtype=float)
    goal_shelf = _goal_shelf(d, p, lines, route)
    for tag, a, b, n in lines:
        reserved = goal_shelf["reserved"] if tag == goal_shelf["line"] else ()
        objects += _line(d, a, b, n, route, tag, reserved)
    objects.append(goal_shelf["spec"])
    kinds = [o["id"].split("_")[-2] for o in objects if "id" in o and o["id"][0] != "g"]
    for kind in FURNITURE:
        p[f"{kind}_count"] = kinds.count(kind)
    bounds = {"min": [xs - 0.3, bottom - 0.3, -0.1], "max": [xe + 0.3, top + 0.3, 2.6]}
    return p, {"bounds": bounds, "objects": objects}


def _goal_shelf(d: _Draw, p: dict, lines: list, route: np.ndarray) -> dict:
    """The parts shelf in front of which the goal stands, on the drawn side of the final leg."""
    tag = f"final_{p['goal_shelf_side']}"
    _, a, _, n = next(line for line in lines if line[0] == tag)
    n, u = np.asarray(n, dtype=float), np.array([1.0, 0.0])
    length = d.u(GOAL_SHELF_LENGTH)
    x = route[-1][0] + d.u((-GOAL_SHELF_SHIFT, GOAL_SHELF_SHIFT))
    at = np.array([x, a[1]])
    depth = _clear_depth(at, u, n, length, d.u(FURNITURE["shelf"][2]), route)
    spec = _item(d, "shelf", at, u, n, length, depth, "goal_shelf")
    spec["items"] = 3  # a parts shelf is stocked
    p["goal_shelf_x"] = float(x)
    s0 = x - length / 2 - a[0]
    return {"line": tag, "spec": spec, "reserved": [(s0 - 0.2, s0 + length + 0.2)]}


def route_poses(waypoints, step: float = 0.05, fillet: float = FILLET) -> np.ndarray:
    """(n, 3) poses the robot may take on the route: every `step` along each leg with its
    heading, turning in place at each inner waypoint (5 deg steps), and along a circular fillet
    of radius `fillet` tangent to both legs at each turn."""
    pts = np.asarray(waypoints, dtype=float)
    out = []
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        n = max(2, int(math.ceil(np.linalg.norm(b - a) / step)) + 1)
        heading = math.atan2(*(b - a)[::-1])
        for f in np.linspace(0.0, 1.0, n):
            out.append((*(a + f * (b - a)), heading))
    for prev, at, nxt in zip(pts[:-2], pts[1:-1], pts[2:], strict=True):
        h0, h1 = math.atan2(*(at - prev)[::-1]), math.atan2(*(nxt - at)[::-1])
        turn = math.remainder(h1 - h0, 2 * math.pi)
        for f in np.linspace(0.0, 1.0, max(2, int(abs(math.degrees(turn)) / 5) + 1)):
            out.append((*at, h0 + f * turn))
        if abs(turn) < 1e-6:
            continue
        back = fillet * math.tan(abs(turn) / 2)  # tangent points this far from the corner
        u0, side = (at - prev) / np.linalg.norm(at - prev), math.copysign(1.0, turn)
        centre = at - back * u0 + side * fillet * np.array([-u0[1], u0[0]])
        for f in np.linspace(0.0, 1.0, 19):
            h = h0 + f * turn
            r = fillet * np.array([math.sin(h), -math.cos(h)]) * side
            out.append((*(centre + r), h))
    return np.asarray(out)


def route_contact(scene: Scene, margin: float = ROUTE_MARGIN):
    """The first pose of :func:`route_poses` on the scene's route where the robot's footprint
    (grown by `margin` on every side) touches an obstacle of the band 0.05 m .. its height, and
    the contact point, or None when the route is free."""
    params = scene.robot.get("params", {})
    length, width = params.get("length", 1.05), params.get("width", 0.58)
    checker = FootprintChecker(
        body_grid(scene, params.get("height", 0.99)), length + 2 * margin, width + 2 * margin
    )
    for pose in route_poses(scene.route["waypoints"]):
        point = checker.contact(pose)
        if point is not None:
            return tuple(float(v) for v in pose), point
    return None


def _base(path: Path) -> dict:
    doc = safe_load_12(read_input_text(path, "scene files", YAML_LIMIT))
    return {k: doc[k] for k in ("robot", "sensors", "route") if k in doc}


def generate_layout(seed: int, base_scene: str | Path = BASE_SCENE) -> Layout:
    """Layout number `seed`: drawn as the module docstring says, redrawn (from stream
    ``derive_seed(seed, attempt)``) until its route is free; deterministic per seed."""
    base = _base(Path(base_scene))
    for attempt in range(MAX_ATTEMPTS):
        params, geometry = _draw(derive_seed(seed, attempt), base)
        doc = {
            "name": f"factory_layout_{seed}",
            "description": _describe(params),
            "source": "000_7c5a0f8de3fa28f5.txt, Exp. 2/3; kiseki.sim.layouts",
            **geometry,
            "floor": True,
            **base,
        }
        with tempfile.TemporaryDirectory() as tmp:
            scene = load_scene(write_layout(doc, Path(tmp) / "layout.yaml"))
        if route_contact(scene) is None:
            return Layout(seed, attempt, {"seed": seed, "attempt": attempt, **params}, doc)
    raise RuntimeError(f"layout {seed}: no free route in {MAX_ATTEMPTS} draws")


def _describe(p: dict) -> str:
    widths = "/".join(f"{p[f'{leg}_width']:.2f}" for leg in ("leg1", "leg2", "final"))
    return (
        f"aisles {widths} m; behind the final leg: left {p['final_left_behind']}, "
        f"right {p['final_right_behind']}; parts shelf at G on the {p['goal_shelf_side']}"
    )


def write_layout(layout: Layout | dict, path: str | Path) -> Path:
    """Writes the layout's scene file (YAML, loadable by kiseki.sim.scene.load_scene)."""
    doc = layout.doc if isinstance(layout, Layout) else layout
    path = Path(path)
    path.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return path
