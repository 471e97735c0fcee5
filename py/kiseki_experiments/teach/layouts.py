# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""layouts-exp2-exp3: the teaching-and-playback thesis' Exp. 2 and Exp. 3 across factory layouts.

kiseki's factory_turn.yaml is one assumed layout around the thesis' route with a turn, and
exp2-turn's report finds that the methods' ordering depends on what lies behind the final
leg's wall. Trial i runs both experiments on layout i (kiseki.sim.layouts.generate_layout with
the trial's seed): ``runs_per_layout`` runs, each one call of exp2-turn's trial (teaching, then
playback with the four methods) and one of exp3-boxes' trial (the same seed, so the same
teaching; proposal 2 with three unknown boxes, and the same run without them). exp2-turn's
and exp3-boxes' claims are judged on the runs of all layouts together (their own evidence, one
value per run); per layout, their own analyses give each claim's point value and whether it
meets the criterion, the share of layouts where it does (95 % Wilson interval: a table row,
not a verdict) and the maps of the layouts where it does not. Every simulation parameter
(noise, particles, motion model) is the same for every method and every layout.

    kiseki experiment run layouts-exp2-exp3 --workers 2      # 20 layouts x 2 runs, ~42 CPU-min
    kiseki experiment run layouts-exp2-exp3 --set runs_per_layout=1 --workers 2   # ~21 CPU-min

A layout is regenerated from the seed in the per-layout table with
``kiseki.sim.layouts.generate_layout(seed)``.
"""

from __future__ import annotations

import math
import tempfile
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.colors import ListedColormap

from kiseki.core import derive_seed
from kiseki.metrics import wilson_interval
from kiseki.plots import new_figure
from kiseki.sim.layouts import generate_layout, write_layout
from kiseki.sim.scene import load_scene
from kiseki.teach.environment_map import MERGE_RULES
from kiseki.teach.local_maps import METHODS
from kiseki_experiments.harness.base import Analysis, Experiment, TrialOutput
from kiseki_experiments.harness.config import Boxes, Particles, Runs
from kiseki_experiments.harness.verdict import Evidence
from kiseki_experiments.teach import teach_playback as tp

REFUSED = "crosses occupied space"  # kiseki.apps.teach.playback.check_route's refusal
GENERAL = 0.8  # a claim generalises when it holds in at least this share of layouts
SHADES = ListedColormap(["white", "#a0a0a0", "black"])
LOW_BAND_M, HIGH_BAND_M = (0.05, 0.6), (0.6, 2.0)  # the layout pictures' two height bands
# the layout parameters in the report's per-layout table (all of them are in trials.parquet)
LAYOUT_COLUMNS = [
    "seed",
    "leg1_width",
    "leg2_width",
    "final_width",
    "final_left_behind",
    "final_left_wall_behind",
    "final_right_behind",
    "final_right_wall_behind",
    "goal_shelf_side",
]


@dataclass(frozen=True)
class LayoutsConfig:
    # Runs of each experiment per layout. The thesis' claims are means and counts over runs:
    # 2 is the fewest with a mean over runs and an SD (Exp. 3). One run of both experiments
    # took 63 s of CPU (1000 particles; 89 s when a refused route makes exp2 run per method),
    # so 20 layouts x 2 runs take about 42 min on one core; 3 runs would take over an hour.
    runs_per_layout: Runs = 2
    methods: list[str] = field(
        default_factory=lambda: ["conventional", "proposal1", "proposal2", "both"]
    )
    particles: Particles = 1000
    boxes: Boxes = 3
    merge: str = "thesis"
    plays: str = ""  # negative controls: exp2-turn's methods played as others (Exp2Config)


def _configs(config: LayoutsConfig, scene: Path, method: str | None = None) -> dict:
    common = {"scene": str(scene), "particles": config.particles, "merge": config.merge}
    methods = list(config.methods) if method is None else [method]
    return {
        "exp2": tp.Exp2Config(methods=methods, plays=config.plays, **common),
        "exp3": tp.Exp3Config(boxes=config.boxes, **common),
    }


def _run(cfg, index: int, seed: int, prefix: str, refusals: bool = True, taught=None) -> dict:
    """One call of exp2-turn's / exp3-boxes' trial (with the run's teaching `taught`, when
    given), its record keys prefixed. When playback refuses the route (a leg crosses occupied
    cells of the taught map), the record says so (with `refusals`; else the ValueError
    propagates)."""
    try:
        record = tp.trial(cfg, index, seed, taught=taught).record
    except ValueError as err:
        if not refusals or REFUSED not in str(err):
            raise
        return {f"{prefix}{m}_refused": str(err) for m in cfg.methods}
    return {f"{prefix}{k}": v for k, v in record.items()}


def _exp2(
    config: LayoutsConfig, scene: Path, index: int, seed: int, prefix: str, taught=None
) -> dict:
    """exp2-turn's trial with every method; when playback refuses the route, once per method
    (the same teaching seed gives the same taught maps and results), so that one method's
    refusal does not hide the others' stops."""
    try:
        return _run(_configs(config, scene)["exp2"], index, seed, prefix, False, taught)
    except ValueError as err:
        if REFUSED not in str(err):
            raise
    record = {}
    for m in config.methods:
        record |= _run(_configs(config, scene, m)["exp2"], index, seed, prefix, taught=taught)
    return record


def trial(config: LayoutsConfig, index: int, seed: int) -> TrialOutput:
    """Layout `seed`: per run, exp2-turn's trial (all methods, see :func:`_exp2`) and
    exp3-boxes' trial, both with the run's seed, so the same teaching: it is run once per run
    (exp2-turn's and exp3-boxes' teaching differ in nothing: scene, merge rule and seed) and
    both trials play back on it."""
    layout = generate_layout(seed)
    record = {f"layout_{k}": v for k, v in layout.params.items()}
    timings = {}
    with tempfile.TemporaryDirectory() as tmp:
        scene = write_layout(layout, Path(tmp) / f"layout_{index}.yaml")
        for r in range(config.runs_per_layout):
            run_seed = derive_seed(seed, 10 + r)
            configs = _configs(config, scene)
            start = time.perf_counter()
            taught = tp.teach_route(configs["exp2"], run_seed, Path(tmp) / f"teach_r{r}")
            timings[f"teach_r{r}_seconds"] = time.perf_counter() - start
            start = time.perf_counter()
            record |= _exp2(config, scene, index, run_seed, f"exp2_r{r}_", taught)
            timings[f"exp2_r{r}_seconds"] = time.perf_counter() - start
            start = time.perf_counter()
            record |= _run(configs["exp3"], index, run_seed, f"exp3_r{r}_", taught=taught)
            timings[f"exp3_r{r}_seconds"] = time.perf_counter() - start
    return TrialOutput(record, timings)


def _runs(row: pd.Series, name: str, runs: int) -> pd.DataFrame:
    """One layout's runs of one experiment as that experiment's trials frame. A method whose
    route playback refused in a run never stops: its stop and estimate errors are infinite
    there, its other columns empty."""
    rows = []
    for r in range(runs):
        prefix = f"{name}_r{r}_"
        rec = {k[len(prefix) :]: v for k, v in row.items() if k.startswith(prefix)}
        rows.append({"trial": r, "error": None, **{k: v for k, v in rec.items() if _set(v)}})
    frame = pd.DataFrame(rows)
    for m in _refused(frame):
        template = next((c for c in frame if c.endswith("_stop_error") and c[:-11] != m), None)
        if template is not None:  # give the method every column the others have
            other = template[: -len("_stop_error")]
            names = [m + c[len(other) :] for c in frame if c.startswith(f"{other}_")]
            missing = [c for c in names if c not in frame]
            frame = pd.concat([frame, pd.DataFrame(np.nan, frame.index, missing)], axis=1)
        refused = frame[f"{m}_refused"].notna()
        for c in ("stop_error", "estimate_error"):
            frame[f"{m}_{c}"] = frame.get(f"{m}_{c}", np.nan)
            frame.loc[refused, f"{m}_{c}"] = np.inf
    return frame


def _set(value) -> bool:
    return not (value is None or (isinstance(value, float) and math.isnan(value)))


def _refused(frame: pd.DataFrame) -> list[str]:
    """The methods whose playback refused the route in at least one run of the frame."""
    return [c[: -len("_refused")] for c in frame if c.endswith("_refused")]


def _names(method: str) -> set[str]:
    return {method, method.replace("proposal", "proposal ")}


def _layout_claims(config: LayoutsConfig, ok: pd.DataFrame, scratch: Path) -> pd.DataFrame:
    """Per layout and claim of exp2-turn / exp3-boxes: its measured value and whether it holds
    (exp2-turn's and exp3-boxes' own analyses on the layout's runs). A claim that names a
    method whose playback refused the route in some run does not hold there."""
    analyses = {"exp2": tp.analyze_exp2, "exp3": tp.analyze_exp3}
    found: dict[tuple[int, str], list[Point]] = {}
    refusals: dict[tuple[int, str], list[str]] = {}
    for _, row in ok.iterrows():
        for name, cfg in _configs(config, Path("layout.yaml")).items():
            frame = _runs(row, name, config.runs_per_layout)
            key = (int(row["trial"]), name)
            refusals[key] = _refused(frame)
            if any(c.endswith("_stop_error") and np.isfinite(frame[c]).any() for c in frame):
                analysis = analyses[name](cfg, frame, pd.DataFrame(), scratch)
                found[key] = [_point(e) for e in analysis.evidence]
    templates = {name: claims for (_, name), claims in found.items()}
    rows = []
    for _, row in ok.iterrows():
        for name in analyses:
            key = (int(row["trial"]), name)
            refused = set().union(*(_names(m) for m in refusals[key]))
            claims = found.get(key, templates.get(name, []))
            for c in claims:
                blocked = any(n in c.claim for n in refused)
                rows.append(
                    {
                        "layout": key[0],
                        "seed": int(row["layout_seed"]),
                        "final_left_behind": row["layout_final_left_behind"],
                        "final_right_behind": row["layout_final_right_behind"],
                        "experiment": name,
                        "claim": c.claim,
                        "paper_value": c.paper_value,
                        "measured_value": "route refused" if blocked else c.measured_value,
                        "holds": bool(c.holds) and not blocked,
                    }
                )
    return pd.DataFrame(rows)


@dataclass(frozen=True)
class Point:
    """One layout's value of a claim and whether it meets the criterion (no interval: a row of
    the per-layout table, never a verdict)."""

    claim: str
    paper_value: str
    measured_value: str
    unit: str
    holds: bool


def _point(evidence: Evidence) -> Point:
    """One layout's value of an exp2-turn or exp3-boxes claim (the mean of its few runs'
    values) and whether that value meets the claim's criterion: a point verdict, for the
    per-layout table; the claim itself is judged on all layouts' runs (`_pooled`)."""
    spec = next(s for s in (*tp.EXP2_CLAIMS, *tp.EXP3_CLAIMS) if s.key == evidence.key)
    values = np.asarray(evidence.values, dtype=float)
    value = float(values[np.isfinite(values)].mean()) if np.isfinite(values).any() else np.nan
    low, high = spec.criterion.band()
    return Point(
        spec.claim,
        spec.criterion.paper_value,
        f"{value:.3f} ({evidence.shown})",
        spec.unit,
        bool(low <= value <= high),
    )


def _pooled(config: LayoutsConfig, ok: pd.DataFrame, scratch: Path) -> list[Evidence]:
    """exp2-turn's and exp3-boxes' evidence over every run of every layout (a run: a random
    layout and its seeds), one Evidence per claim. A run whose route playback refused counts
    with an infinite stop error (exp3-boxes' claims: the robot never stopped at the goal)."""
    values: dict[str, list[float]] = {}
    layouts: dict[str, int] = {}
    analyses = {"exp2": tp.analyze_exp2, "exp3": tp.analyze_exp3}
    for name, cfg in _configs(config, Path("layout.yaml")).items():
        for _, row in ok.iterrows():
            frame = _runs(row, name, config.runs_per_layout)
            if not any(c.endswith("_stop_error") and np.isfinite(frame[c]).any() for c in frame):
                continue  # every method refused the route in every run: no stop to compare
            for e in analyses[name](cfg, frame, pd.DataFrame(), scratch).evidence:
                values.setdefault(e.key, []).extend(e.values)
                layouts[e.key] = layouts.get(e.key, 0) + 1
    return [
        Evidence.of(key, v, shown=f"{layouts[key]} layouts x {config.runs_per_layout} run(s)")
        for key, v in values.items()
    ]


def _shares(per: pd.DataFrame) -> pd.DataFrame:
    rows = []
    for (name, claim), g in per.groupby(["experiment", "claim"], sort=False):
        k, n = int(g["holds"].sum()), len(g)
        lo, hi = wilson_interval(k, n)
        fails = ", ".join(str(v) for v in g.loc[~g["holds"], "layout"])
        rows.append(
            {
                "experiment": name,
                "claim": claim,
                "paper_value": g["paper_value"].iloc[0],
                "layouts_holding": k,
                "layouts": n,
                "share": k / n,
                "ci95_low": lo,
                "ci95_high": hi,
                "fails_in_layouts": fails,
                "generalises": _verdict(lo, hi),
            }
        )
    return pd.DataFrame(rows)


def _stops(config: LayoutsConfig, ok: pd.DataFrame) -> pd.DataFrame:
    """Per layout: each method's mean stop error over its runs (Exp. 2; Exp. 3 with and
    without the boxes), the best method, and what lies behind the final leg."""
    rows = []
    for _, row in ok.iterrows():
        out = {
            "layout": int(row["trial"]),
            "final_left_behind": row["layout_final_left_behind"],
            "final_right_behind": row["layout_final_right_behind"],
        }
        for m in config.methods:
            out[f"{m}_stop_m"] = _runs(row, "exp2", config.runs_per_layout)[
                f"{m}_stop_error"
            ].mean()
        exp3 = _runs(row, "exp3", config.runs_per_layout)
        for key, col in (
            ("boxes", "proposal2_stop_error"),
            ("noboxes", "proposal2_nobox_stop_error"),
        ):
            out[f"exp3_{key}_stop_m"] = exp3[col].mean() if col in exp3 else np.inf
        best = min(config.methods, key=lambda m: out[f"{m}_stop_m"])
        out["best_method"] = best if np.isfinite(out[f"{best}_stop_m"]) else "none (refused)"
        rows.append(out)
    return pd.DataFrame(rows)


def _refusals(ok: pd.DataFrame) -> pd.DataFrame:
    """Each run in which playback refused the route: layout, experiment, run, method, why."""
    rows = []
    for _, row in ok.iterrows():
        for c, v in row.items():
            if c.endswith("_refused") and _set(v):
                name, run, rest = c.split("_", 2)
                method = rest[: -len("_refused")]
                rows.append(
                    {
                        "layout": int(row["trial"]),
                        "experiment": name,
                        "run": run[1:],
                        "method": method,
                        "why": v,
                    }  # fmt: skip
                )
    return pd.DataFrame(rows, columns=["layout", "experiment", "run", "method", "why"])


def _by_behind(per: pd.DataFrame) -> pd.DataFrame:
    """Share of layouts holding each claim, by what lies behind the final leg's left and right
    boundary lines."""
    rows = []
    for side in ("left", "right"):
        for behind, g in per.groupby(f"final_{side}_behind"):
            shares = g.groupby("claim", sort=False)["holds"].mean()
            rows.append(
                {"side": side, "behind": behind, "layouts": g["layout"].nunique(), **shares}
            )
    return pd.DataFrame(rows)


def _layout_picture(seed: int) -> tuple[np.ndarray, list[float], np.ndarray, dict]:
    """Layout `seed` from above: shades (0 free, 1 at 0.6-2.0 m only, 2 at 0.05-0.6 m), the
    picture's extent, the route and the layout's parameters."""
    layout = generate_layout(seed)
    with tempfile.TemporaryDirectory() as tmp:
        scene = load_scene(write_layout(layout, Path(tmp) / "layout.yaml"))
    low, high = scene.ground_truth(*LOW_BAND_M), scene.ground_truth(*HIGH_BAND_M)
    shade = np.where(low.cells == 100, 2, np.where(high.cells == 100, 1, 0))
    o, r = low.origin, low.resolution
    extent = [o.x, o.x + low.width * r, o.y, o.y + low.height * r]
    return shade, extent, np.asarray(scene.route["waypoints"], dtype=float), layout.params


def _draw_layouts(
    pictures: dict, layouts: list[int], title: str, path: Path, measured: dict | None = None
) -> Path:
    """A small multiple of the layouts from above (black: obstacles at 0.05-0.6 m, the plane
    at 0.4 m among them; grey: higher, up to 2.0 m, table tops and shelves) with the route."""
    cols = min(4, len(layouts))
    nrows = math.ceil(len(layouts) / cols)
    fig = new_figure(figsize=(4.4 * cols, 3.0 * nrows + 0.6), dpi=100)
    axes = np.atleast_1d(fig.subplots(nrows, cols, squeeze=False)).ravel()
    for ax, index in zip(axes, layouts, strict=False):
        shade, extent, route, p = pictures[index]
        ax.imshow(shade, origin="lower", extent=extent, cmap=SHADES, vmin=0, vmax=2)
        ax.plot(route[:, 0], route[:, 1], "-o", color="tab:blue", lw=1.2, ms=3)
        value = f"\nmeasured {measured[index]}" if measured else ""
        ax.set_title(
            f"layout {index}: behind the final leg left {p['final_left_behind']}, "
            f"right {p['final_right_behind']}{value}",
            fontsize=7,
        )
        ax.tick_params(labelsize=6)
    for ax in axes[len(layouts) :]:
        ax.set_visible(False)
    fig.suptitle(title, fontsize=10)
    fig.savefig(path, bbox_inches="tight")
    return path


def _slug(text: str) -> str:
    keep = "".join(ch if ch.isalnum() else "_" for ch in text.lower())
    return "_".join(part for part in keep.split("_") if part)[:60]


def analyze(config: LayoutsConfig, trials, timings, figures: Path) -> Analysis:
    ok = trials[trials["error"].isna()]
    with tempfile.TemporaryDirectory() as scratch:
        per = _layout_claims(config, ok, Path(scratch))
    shares = _shares(per)
    wide = per.pivot_table(index="layout", columns="claim", values="holds", aggfunc="first")
    table = ok.set_index("trial")[[f"layout_{c}" for c in LAYOUT_COLUMNS]]
    table = table.rename(columns=lambda c: c[len("layout_") :]).join(wide.astype(str))
    pictures = {int(r["trial"]): _layout_picture(int(r["layout_seed"])) for _, r in ok.iterrows()}
    figs = [_draw_layouts(pictures, sorted(pictures), "all layouts", figures / "layouts.png")]
    for (name, claim), g in per.groupby(["experiment", "claim"], sort=False):
        fails = g[~g["holds"]]
        if len(fails):
            measured = dict(zip(fails["layout"], fails["measured_value"], strict=True))
            path = figures / f"fails_{name}_{_slug(claim)}.png"
            title = f"{name}: {claim} fails (thesis: {g['paper_value'].iloc[0]})"
            figs.append(_draw_layouts(pictures, sorted(measured), title, path, measured))
    with tempfile.TemporaryDirectory() as scratch:
        evidence = _pooled(config, ok, Path(scratch))
    return Analysis(
        tables={
            "claim_shares": shares,
            "per_layout": table.reset_index(),
            "claims_per_layout": per,
            "by_behind": _by_behind(per),
            "stops_per_layout": _stops(config, ok),
            "refusals": _refusals(ok),
        },
        figures=figs,
        notes=_notes(config, len(ok), len(trials)),
        evidence=evidence,
    )


# exp2-turn's claims judged on the runs of all layouts together; their control plays the
# proposals as conventional (cheap: one run per layout, no boxes, few particles) on 6
# layouts: the first 5 of seed 0 hold one whose route playback refuses, and an interval needs
# 5 runs with stops; 6 layouts, each taught and played back: 63 s beside another test
CLAIMS = tuple(
    replace(
        spec,
        claim=f"exp2: {spec.claim} (all layouts' runs)",
        control=replace(
            tp.ALL_CONVENTIONAL,
            overrides=(*tp.ALL_CONVENTIONAL.overrides, "runs_per_layout=1", "boxes=0"),
            runs=6,
            minutes=True,
        ),
    )
    for spec in tp.EXP2_CLAIMS
) + tuple(
    # exp3-boxes' claims on proposal 2 with the boxes, judged on the runs of all layouts
    # together (a refused route counts as never stopping at the goal); their control is
    # exp3-boxes' own (one particle: dead reckoning) on 6 layouts, one run each
    replace(
        spec,
        claim=f"exp3: {spec.claim} (all layouts' runs)",
        control=replace(
            spec.control,
            overrides=(*spec.control.overrides, "runs_per_layout=1"),
            runs=6,
            minutes=True,
        ),
    )
    for spec in tp.EXP3_CLAIMS
    if spec.key.startswith("boxes_")
)


def _verdict(low: float, high: float) -> str:
    """Whether a claim's share of layouts is above GENERAL (its 95 % interval above it),
    below it, or undecided by this many layouts."""
    if low >= GENERAL:
        return f"general: holds in >= {GENERAL:.0%} of layouts (95 % interval)"
    if high < GENERAL:
        return f"layout-specific: holds in < {GENERAL:.0%} of layouts (95 % interval)"
    return f"undecided by this many layouts (the 95 % interval spans {GENERAL:.0%})"


def _notes(config: LayoutsConfig, ok: int, total: int) -> str:
    n = config.runs_per_layout
    return (
        f"{ok} of {total} layouts ran (kiseki.sim.layouts states every range and its reason). "
        f"Each layout: {config.runs_per_layout} run(s) of exp2-turn's trial (teaching, then "
        "conventional, proposal 1, proposal 2 and both on the taught maps) and of exp3-boxes' "
        f"trial ({config.boxes} unknown boxes, proposal 2, and the control without them), "
        f"{config.particles} particles, merge rule {config.merge!r}; a layout's claims are "
        "exp2-turn's and exp3-boxes' own analyses applied to its runs. exp2-turn's claims "
        "(paired differences between methods) and exp3-boxes' (proposal 2's stop and "
        "estimate errors with the boxes) are judged on the runs of all layouts together "
        "(claims.csv); per layout, table `claims_per_layout` gives the mean of its "
        f"{n} run(s) and whether that point value meets the criterion (the thesis ran "
        f"{tp.THESIS_RUNS}; {n} run(s) per layout decide no interval). Table `claim_shares` "
        "counts the layouts whose point value meets each criterion (a table row, not a "
        f"verdict): column `generalises` says whether the share's 95 % Wilson interval lies "
        f"above {GENERAL:.0%} of layouts (general), below it (layout-specific) or across it. "
        "Table `by_behind` splits the shares by what lies behind the final leg's boundary "
        "lines; figures `fails_*.png` draw the layouts where a claim fails (ground truth "
        f"{LOW_BAND_M[0]:g}-{HIGH_BAND_M[1]:g} m, route P0 -> T1 -> T2 -> G)."
    )


def _preflight(config: LayoutsConfig) -> None:
    if config.runs_per_layout < 1:
        raise ValueError(f"runs_per_layout must be at least 1, got {config.runs_per_layout}")
    tp.stand_ins(config)  # a malformed `plays` stops here, named
    unknown = [m for m in config.methods if m not in METHODS]
    if unknown:
        raise ValueError(f"unknown method(s) {unknown} (known: {', '.join(METHODS)})")
    if config.merge not in MERGE_RULES:
        raise ValueError(f"unknown merge rule {config.merge!r} (known: {', '.join(MERGE_RULES)})")


EXPERIMENT = Experiment(
    name="layouts-exp2-exp3",
    paper="000_7c5a0f8de3fa28f5.txt",
    artefact="Tables 4.5-4.7 across layouts",
    description="Exp. 2 and Exp. 3 on 20 seeded factory layouts: share of layouts per claim",
    config_type=LayoutsConfig,
    trial=trial,
    analyze=analyze,
    default_runs=20,
    preflight=_preflight,
    claims=CLAIMS,
)
