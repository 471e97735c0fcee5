# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""layouts-exp2-exp3's analysis (kiseki_experiments.teach.layouts): exp2-turn's and
exp3-boxes' own analyses applied to each layout's runs and to all layouts' runs together, the
share of layouts per claim, the per-layout tables and the pictures of the layouts, every number
from the trials' records."""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from kiseki.metrics import wilson_interval
from kiseki.plots import new_figure
from kiseki.sim.layouts import generate_layout, write_layout
from kiseki.sim.scene import load_scene
from kiseki_experiments.harness.base import Analysis
from kiseki_experiments.harness.verdict import Evidence
from kiseki_experiments.teach import teach_playback as tp
from kiseki_experiments.teach.layouts_config import LayoutsConfig, experiment_configs

__all__ = ["GENERAL", "HIGH_BAND_M", "LAYOUT_COLUMNS", "LOW_BAND_M", "Point", "analyze"]

GENERAL = 0.8  # a claim generalises when it holds in at least this share of layouts
SHADES = ("white", "#a0a0a0", "black")  # the layout pictures' colours of shades 0, 1 and 2
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
        for name, cfg in experiment_configs(config, Path("layout.yaml")).items():
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
    for name, cfg in experiment_configs(config, Path("layout.yaml")).items():
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
            # a column never played (no boxes, or without_boxes=false) is not a refusal: NaN
            out[f"exp3_{key}_stop_m"] = exp3[col].mean() if col in exp3 else np.nan
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


def _shades():
    from matplotlib.colors import ListedColormap  # imported when a picture is drawn

    return ListedColormap(SHADES)


def _draw_layouts(
    pictures: dict, layouts: list[int], title: str, path: Path, measured: dict | None = None
) -> Path:
    """A small multiple of the layouts from above (black: obstacles at 0.05-0.6 m, the plane
    at 0.4 m among them; grey: higher, up to 2.0 m, table tops and shelves) with the route."""
    cols = min(4, len(layouts))
    nrows = math.ceil(len(layouts) / cols)
    height = 3.0 * nrows + 0.6  # inches; the title's 0.5 in above the rows, however many
    fig = new_figure(figsize=(4.4 * cols, height), dpi=100)
    margins = {"top": 1 - 0.5 / height, "bottom": 0.3 / height}
    axes = np.atleast_1d(fig.subplots(nrows, cols, squeeze=False, gridspec_kw=margins)).ravel()
    for ax, index in zip(axes, layouts, strict=False):
        shade, extent, route, p = pictures[index]
        ax.imshow(shade, origin="lower", extent=extent, cmap=_shades(), vmin=0, vmax=2)
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
    fig.suptitle(title, fontsize=10, y=1 - 0.1 / height, va="top")
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
