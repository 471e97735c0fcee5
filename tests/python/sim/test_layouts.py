# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Seeded factory layouts (kiseki.sim.layouts) and the layouts-exp2-exp3 experiment."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from kiseki.sim import layouts as lay
from kiseki.sim.scene import load_scene

SEEDS = range(20)


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    out = tmp_path_factory.mktemp("layouts")
    found = []
    for seed in SEEDS:
        layout = lay.generate_layout(seed)
        found.append((layout, load_scene(lay.write_layout(layout, out / f"l{seed}.yaml"))))
    return found


def _free_run(grid, start, direction) -> float:
    """Metres from `start` along `direction` to the first occupied cell's face (cell by cell)."""
    res = grid.resolution
    p = np.asarray(start, dtype=float)
    for k in range(1, 400):
        q = p + k * res / 2 * np.asarray(direction, dtype=float)
        cx, cy = grid.world_to_cell(q[None])[0]
        if not (0 <= cx < grid.width and 0 <= cy < grid.height):
            return float("inf")
        if grid.cells[cy, cx] == 100:
            return (k - 1) * res / 2
    return float("inf")


def test_the_generator_is_deterministic_per_seed():
    a, b, c = lay.generate_layout(7), lay.generate_layout(7), lay.generate_layout(8)
    assert a.doc == b.doc and a.params == b.params
    assert a.doc["objects"] != c.doc["objects"]


def test_every_route_is_free_for_the_footprint(scenes):
    for layout, scene in scenes:
        assert lay.route_contact(scene) is None, layout.seed
    # the check finds a block: a box on the final leg
    doc = dict(scenes[0][0].doc)
    doc["objects"] = [*doc["objects"], {"type": "box", "center": [9.0, -3.29], "size": [0.3] * 3}]
    layout = lay.Layout(0, 0, {}, doc)
    for _, scene in scenes:  # independently: sideways clearance along the legs at body height
        body = scene.ground_truth(0.05, 0.99)
        route = np.asarray(scene.route["waypoints"], dtype=float)
        for a, b in zip(route[:-1], route[1:], strict=True):
            u = (b - a) / np.linalg.norm(b - a)
            for f in np.arange(0.0, np.linalg.norm(b - a), 0.25):
                for side in (np.array([-u[1], u[0]]), np.array([u[1], -u[0]])):
                    assert _free_run(body, a + f * u, side) >= lay.MIN_CLEAR - 0.05
    path = lay.write_layout(layout, scenes[0][1].path.parent / "blocked.yaml")
    assert lay.route_contact(load_scene(path)) is not None


def test_route_aisle_widths_and_what_lies_behind_as_stated(scenes):
    """On the ground truth above the furniture (2.1-2.4 m: only walls), sideways from the route:
    the aisles' walls at the drawn distances, the final leg's far walls at the drawn distance
    behind its boundary lines, the end wall at the drawn gap beyond G."""
    behinds = set()
    for layout, scene in scenes:
        p = layout.params
        route = np.asarray(scene.route["waypoints"], dtype=float)
        assert np.allclose(route[-1] - route[0], [10.29, -3.29])
        assert np.allclose(route, [[0, 0], [7, 0], [7, -3.29], [10.29, -3.29]])
        walls = scene.ground_truth(2.1, 2.4)
        probes = {
            "leg1": ((3.5, 0.0), (0, 1)),
            "leg2": ((7.0, -1.65), (1, 0)),
            "final": ((9.6, -3.29), (0, 1)),
        }
        for leg, (at, left) in probes.items():
            width = p[f"{leg}_width"]
            assert 2.2 <= width <= 3.0
            behind = {"left": 0.0, "right": 0.0}
            if leg == "final":
                behind = {s: p[f"final_{s}_wall_behind"] for s in behind}
                behinds |= {p["final_left_behind"], p["final_right_behind"]}
            for side, sign in (("left", 1), ("right", -1)):
                measured = _free_run(walls, at, sign * np.asarray(left))
                expected = p[f"{leg}_{side}"] + behind[side]
                assert abs(measured - expected) <= 0.06, (layout.seed, leg, side)
        assert abs(_free_run(walls, route[-1], (1, 0)) - p["end_gap"]) <= 0.06
    assert behinds == set(lay.BEHIND)


def test_the_experiment_runs_on_two_layouts_and_writes_the_table(tmp_path):
    """Above 20 s (about 24 s beside another test): two layouts is the fewest a share of
    layouts is taken over, and each layout's run is one teaching and four playbacks
    (exp2-turn's conventional and proposal 2, the two methods of its main claims; exp3-boxes'
    with its boxes and without them), whose cost is the simulated sensors at their rates (the
    depth cameras at 30 Hz first), not the particle count (100)."""
    from kiseki_experiments.harness.runner import run_experiment

    result = run_experiment(
        "layouts-exp2-exp3",
        runs=2,
        seed=0,
        overrides=["runs_per_layout=1", "particles=100", "methods=conventional,proposal2"],
        out=tmp_path / "run",
        progress=False,
    )
    assert result.failed == 0
    shares = pd.read_csv(result.run_dir / "tables" / "claim_shares.csv")
    assert set(shares["layouts"]) == {2}
    assert {"exp2", "exp3"} == set(shares["experiment"])
    assert (result.run_dir / "figures" / "layouts.png").is_file()
    claims = pd.read_csv(result.run_dir / "claims.csv", keep_default_na=False)
    # exp2-turn's two claims on conventional and proposal 2 and exp3-boxes' two on proposal 2
    # with the boxes, each on both layouts' runs (2 values: too few for an interval)
    assert claims["claim"].str.endswith("(all layouts' runs)").all()
    assert claims["claim"].str[:6].value_counts().to_dict() == {"exp2: ": 2, "exp3: ": 2}
    assert (claims["trials"] == 2).all() and (claims["verdict"] == "inconclusive").all()
    # the exp3 claims' values are the mean of the two layouts' runs
    trials = pd.read_parquet(result.run_dir / "trials.parquet")
    stop = claims[claims["claim"].str.startswith("exp3: proposal 2 with unknown boxes: stop")]
    want = trials["exp3_r0_proposal2_stop_error"].mean()
    assert stop["measured_value"].iloc[0].startswith(f"{want:.4g} ")
    assert set(shares["generalises"].str.split(":").str[0]) <= {
        "general", "layout-specific", "undecided by this many layouts (the 95 % interval spans 80%)"
    }  # fmt: skip
    assert "claim_shares" in (result.run_dir / "report.md").read_text(encoding="utf-8")


def test_a_refused_route_fails_only_that_method(monkeypatch, tmp_path):
    """Playback refuses a route through the taught map's occupied cells; exp2 then runs once
    per method, so the refusal is recorded for that method and the others still stop."""
    from kiseki_experiments.teach import layouts as exp

    def fake_trial(cfg, index, seed, taught=None):
        if "conventional" in cfg.methods:
            raise ValueError(f"the route leg T2 -> G {exp.REFUSED} at (7.05, -3.15) m")
        return exp.TrialOutput({f"{m}_stop_error": 0.05 for m in cfg.methods})

    monkeypatch.setattr(exp.tp, "trial", fake_trial)
    config = exp.LayoutsConfig(methods=["conventional", "proposal2"])
    record = exp._exp2(config, tmp_path / "layout.yaml", 0, 1, "exp2_r0_")
    assert exp.REFUSED in record["exp2_r0_conventional_refused"]
    assert record["exp2_r0_proposal2_stop_error"] == 0.05
    monkeypatch.setattr(exp.tp, "trial", lambda *a, **k: (_ for _ in ()).throw(ValueError("other")))
    with pytest.raises(ValueError, match="other"):
        exp._exp2(config, tmp_path / "layout.yaml", 0, 1, "exp2_r0_")
