# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Gaussian-process magnetic maps (printed, never asserted), kiseki beside scikit-learn and the
magnetic-navigation thesis (chapter 6) in one run:

1. exact GP, kiseki's ExactGP against scikit-learn's GaussianProcessRegressor with the same model:
   kernel sigma_f^2 exp(-r^2 / 2 l^2) + sigma_n^2 (sklearn: ConstantKernel * RBF + WhiteKernel),
   a constant mean (the training mean of each column; subtracted by hand for sklearn, whose
   normalize_y stays False), one kernel shared by the three field components (sklearn's
   multi-output y sums the columns' likelihoods, as kiseki does; --per-component: one GP per
   component in both), the same start (kiseki's data-derived one) and bounds, and R seeded random
   restarts in both (sklearn n_restarts_optimizer=R, kiseki restarts=R; each library draws its
   own; kiseki also starts from the best of an 18-point scan of l and sigma_n, values only,
   when that is not the data's start itself, so the evaluations each spent are printed; kiseki's
   line search asks for the gradient only at the points it accepts, so its count says how many
   of its evaluations carried one). kiseki searches its starts in two stages by default (on a
   quarter of the points, at least 256; each distinct optimum found then climbed on every
   point): its one-stage search on every point is printed beside it (up to 3,000 points).
   Fit + predict (mean and standard deviation) times, held-out RMSE, the log marginal likelihood
   (eq. 6.11) each reached on all training points, and the likelihood evaluations each spent:
   a. the Aalto robot data (Solin et al. 2018): every 40th sample of runs 1-4 of the invensense
      sensor, 2-D; held out: every 10th sample of run 5 (uT);
   b. the thesis' 2-D floor: the simulated 450 m^2 floor (data/worlds/magnetic_floor.yaml),
      mapper_2d's three sensors read every 0.1 m of its route (about 6,400 readings, noise
      0.01 G); held out: the noise-free field on the scene's 0.2 m measurement grid in free space.
      Here kiseki fits its hyperparameters on every point, as sklearn does (its default would
      use a seeded subsample: printed too), with --restarts-large (0) restarts: one sklearn
      likelihood evaluation takes a minute or more at this size. When sklearn is stopped
      (--sklearn-timeout), one evaluation with its gradient is timed in both instead.
2. the thesis' 3-D floor: mapper_3d's arm sensors at 10 Hz, averaged into 0.2 m voxels (about
   6,400); hyperparameters on the default seeded subsample, the factorisation of every
   voxel, and prediction with variance on the floor's 123,750 voxels of 0.2 m (up to 2.2 m):
   each timed apart, beside the thesis' 29 hours.
3. the reduced-rank HilbertGP: 40,000 noisy 3-D readings at seeded random points of the thesis'
   elevator hall (data/worlds/magnetic_hall.yaml, 3.0 x 3.0 x 2.0 m) to a 0.05 m map with
   variance (144,000 voxels), against the 60 s goal and Menzen, Fetter and Kok (FUSION 2023:
   40,000 readings in under 2 min on a laptop); its agreement with the exact GP when both fit the
   same 6,000 readings with the same kernel.

Times are the best of --repeats runs, except fits on more than 3,000 points (one run). BLAS
uses every core in both libraries; the load average is printed (other work slows every time).

Needs ../shared/data for case 1a. Run: python benchmarks/bench_gp.py (--quick: small sizes;
--skip-sklearn-large; --help for the rest).
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np
from sklearn.gaussian_process import GaussianProcessRegressor

from gp_cases_3d import case_hilbert, case_tiled, case_volume, rmse, search_note  # beside this file
from gp_reference import run_sklearn_limited, sklearn_kernel, start_kernel
from kiseki.datasets import read_aalto_run
from kiseki.gp import ExactGP
from kiseki.gp.kernel import log_marginal_likelihood
from kiseki.sim.scene import load_scene
from kiseki_experiments.gp.gp_common import (
    FLOOR,
    free_mask,
    magnetic_world,
    survey_2d,
)
from timing import best_of, machine_line

ROOT = Path(__file__).resolve().parents[1]
AALTO = ROOT.parent / "shared" / "data" / "magnetic" / "aalto" / "invensense"
THESIS_2D_S = 30 * 60.0  # sec. 6.5: about 30 min


# --- the exact GP in both libraries -----------------------------------------------------------


def one_evaluation(x, y, repeats: int) -> tuple[float, float]:
    """Seconds of one log marginal likelihood with its gradient at the start kernel: (kiseki,
    sklearn); both on all points and all three columns."""
    k0, yc = start_kernel(x, y), y - y.mean(axis=0)
    ks, _ = best_of(lambda: log_marginal_likelihood(x, y, k0), repeats)
    reg = GaussianProcessRegressor(sklearn_kernel(k0), optimizer=None).fit(x, yc)
    theta = reg.kernel_.theta
    ss, _ = best_of(lambda: reg.log_marginal_likelihood(theta, eval_gradient=True), repeats)
    return ks, ss


def run_kiseki(x, y, xs, restarts, per_component, max_points, repeats, search_points=None) -> dict:
    def fit():
        return ExactGP.fit(
            x,
            y,
            restarts=restarts,
            seed=0,
            max_points=max_points,
            per_component=per_component,
            search_points=search_points,
        )

    fit_s, gp = best_of(fit, repeats if len(x) <= 3000 else 1)  # minutes beyond
    # the factorisation alone (the rest of the fit is the hyperparameter search)
    cols = [[c] for c in range(y.shape[1])] if per_component else [list(range(y.shape[1]))]
    factor_s, _ = best_of(
        lambda: [ExactGP.fit(x, y[:, c], k) for c, k in zip(cols, gp.kernels, strict=True)],
        repeats,
    )
    predict_s, (mean, var) = best_of(lambda: gp.predict(xs), repeats)
    std = np.sqrt(var[:, [0]] if not per_component else var)
    return {
        "fit": fit_s,
        "factor": factor_s,
        "hyper": fit_s - factor_s,  # the hyperparameter search
        "predict": predict_s,
        "mean": mean,
        "std": std,
        "lml": gp.log_marginal_likelihood(),
        "evaluations": sum(f.evaluations for f in gp.hyperparameter_fits),
        "gradients": sum(f.gradients for f in gp.hyperparameter_fits),
        # what the two-stage search's first stage (on a subsample) spent, as text
        "search": "".join(search_note(f) for f in gp.hyperparameter_fits),
        "kernels": [str(k) for k in gp.kernels],
    }


def show_kiseki(label: str, k: dict, truth) -> None:
    """One kiseki fit's line: times, evaluations (on every point, then what the search's first
    stage on a subsample spent, when made), RMSE, LML and kernels."""
    print(
        f"  {label}: fit {k['fit']:.2f} s (hyperparameters {k['hyper']:.2f} s, {k['evaluations']}"
        f" evaluations on every point{k['search']}, {k['gradients']} of them with the gradient, "
        f"{k['hyper'] / k['evaluations']:.3f} s each; factorisation "
        f"{k['factor']:.2f} s), predict {k['predict']:.3f} s, RMSE {rmse(k['mean'], truth):.5g}, "
        f"LML {k['lml']:.2f}\n           {'; '.join(k['kernels'])}",
        flush=True,
    )


def compare(name, x, y, xs, truth, args, sklearn: bool, r: int, rows) -> None:
    """Both libraries on one data set with r restarts, kiseki's hyperparameters on every point
    as sklearn's: details printed, summary rows appended to `rows`."""
    print(f"\n{name}: {len(x):,} training points, {len(xs):,} predicted, restarts {r}", flush=True)
    k = run_kiseki(x, y, xs, r, args.per_component, len(x), args.repeats)
    show_kiseki("kiseki ", k, truth)
    if len(x) <= 3000:  # the one-stage search on every point beside it (before the two stages)
        one = run_kiseki(x, y, xs, r, args.per_component, len(x), args.repeats, len(x))
        show_kiseki("one stage", one, truth)
        rows.append(
            (
                f"{name}: fit + predict, kiseki's one-stage search",
                f"{one['fit'] + one['predict']:.2f} s",
                "",
                f"{(one['fit'] + one['predict']) / (k['fit'] + k['predict']):.1f}x slower",
            )
        )
    kt, runs = k["fit"] + k["predict"], []
    for _ in range(args.repeats if sklearn and len(x) <= 3000 else int(sklearn)):
        runs.append(run_sklearn_limited(x, y, xs, r, args.per_component, args.sklearn_timeout))
    if not runs:
        print("  sklearn: skipped")
        rows.append((f"{name}: fit + predict", f"{kt:.2f} s", "skipped", ""))
        return
    if runs[-1] is None:
        limit = args.sklearn_timeout
        ks, ss = one_evaluation(x, y, args.repeats)
        print(f"  sklearn: stopped after {limit:.0f} s; one likelihood evaluation with its "
              f"gradient at the start: {ss:.2f} s (kiseki {ks:.2f} s)", flush=True)  # fmt: skip
        rows.append((f"{name}: fit + predict", f"{kt:.1f} s", f"> {limit:.0f} s (stopped)",
                     f"> {limit / kt:.1f}x"))  # fmt: skip
        rows.append((f"{name}: one likelihood + gradient", f"{ks:.2f} s", f"{ss:.2f} s",
                     f"{ss / ks:.1f}x"))  # fmt: skip
        return
    s = runs[-1] | {t: min(run[t] for run in runs) for t in ("fit", "predict")}
    st, rk, rs = s["fit"] + s["predict"], rmse(k["mean"], truth), rmse(s["mean"], truth)
    std_gap = np.max(np.abs(k["std"] - s["std"]) / np.maximum(s["std"], 1e-12))
    agree = "within" if abs(rk - rs) <= 0.02 * rs else "NOT within"
    print(
        f"  sklearn: fit {s['fit']:.2f} s ({s['evaluations']} evaluations, "
        f"{s['fit'] / s['evaluations']:.3f} s each), predict {s['predict']:.3f} s, RMSE "
        f"{rs:.5g}, LML {s['lml']:.2f}\n           {'; '.join(s['kernels'])}\n  RMSE "
        f"{100 * (rk - rs) / rs:+.2f} % ({agree} 2 %), means differ by "
        f"{rmse(k['mean'], s['mean']):.3g} RMS, noise-free SD by {100 * std_gap:.2g} % at most",
        flush=True,
    )
    fit_ratio, predict_ratio = s["fit"] / k["fit"], s["predict"] / k["predict"]
    k_each, s_each = k["hyper"] / k["evaluations"], s["fit"] / s["evaluations"]
    rows += [
        (f"{name}: fit + predict", f"{kt:.2f} s", f"{st:.2f} s", f"{st / kt:.1f}x"),
        (
            f"{name}: fit / predict",
            f"{k['fit']:.2f} / {k['predict']:.3f} s",
            f"{s['fit']:.2f} / {s['predict']:.3f} s",
            f"{fit_ratio:.1f}x / {predict_ratio:.1f}x",
        ),
        (
            f"{name}: likelihood evaluations (s each)",
            f"{k['evaluations']}, {k['gradients']} with gradient ({k_each:.3f} s)" + k["search"],
            f"{s['evaluations']} ({s_each:.3f} s)",
            f"{s_each / k_each:.1f}x each",
        ),
        (f"{name}: held-out RMSE", f"{rk:.5g}", f"{rs:.5g}", f"{rk / rs:.4f}"),
        (
            f"{name}: LML reached",
            f"{k['lml']:.2f}",
            f"{s['lml']:.2f}",
            f"{k['lml'] - s['lml']:+.2f}",
        ),
    ]


def default_fit(x, y, xs, truth, args, rows) -> None:
    """kiseki as a user runs it: ExactGP.fit's defaults (hyperparameters on a subsample)."""
    fit_s, gp = best_of(lambda: ExactGP.fit(x, y), args.repeats)
    predict_s, (mean, _) = best_of(lambda: gp.predict(xs), args.repeats)
    used, total = gp.hyperparameter_fit.points_used, fit_s + predict_s
    print(
        f"  kiseki, ExactGP.fit's defaults ({used:,}-point subsample, "
        f"{gp.hyperparameter_fit.evaluations} evaluations): fit {fit_s:.2f} s, predict "
        f"{predict_s:.3f} s, RMSE {rmse(mean, truth):.5g}, LML on every point "
        f"{gp.log_marginal_likelihood():.2f}\n           {gp.kernel}",
        flush=True,
    )
    name = f"2-D floor, kiseki's defaults ({used:,}-point subsample): fit + predict"
    rows.append((name, f"{total:.1f} s", "thesis: 30 min", f"{THESIS_2D_S / total:.0f}x"))


# --- data --------------------------------------------------------------------------------------


def aalto(quick: bool):
    runs = [read_aalto_run(AALTO / str(i)) for i in range(1, 6)]
    step = 160 if quick else 40
    x = np.vstack([r.positions[::step] for r in runs[:4]])
    y = np.vstack([r.field[::step] for r in runs[:4]])
    return x, y, runs[4].positions[::10], runs[4].field[::10]


def floor_2d(seed: int):
    """mapper_2d's survey (readings in the world frame, G) and the noise-free field on the free
    points of the scene's 0.2 m measurement grid, at the sensors' height."""
    scene = load_scene(FLOOR)
    survey = survey_2d(scene, seed)
    grid = scene.measurement_grid.points()
    grid = grid[free_mask(scene, grid, grid[0, 2])]
    return survey.positions, survey.field, grid[:, :2], magnetic_world(scene).static_field_at(grid)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="small sizes (a smoke run)")
    parser.add_argument("--restarts", type=int, default=3, help="random restarts, both libraries")
    parser.add_argument("--restarts-large", type=int, default=0, help="the same, 2-D floor")
    parser.add_argument("--per-component", action="store_true", help="one GP per field column")
    parser.add_argument("--skip-sklearn-large", action="store_true")
    parser.add_argument("--sklearn-timeout", type=float, default=900.0, help="s, 2-D floor")
    parser.add_argument("--repeats", type=int, default=2, help="best of, for times")
    parser.add_argument("--hilbert-points", type=int, default=1000, help="hyperparameter subsample")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--floor-csv", type=Path, help="write the tiled case's readings here (x,y,z,mx,my,mz, G)"
    )
    parser.add_argument("--cases", default="aalto,floor,volume,hilbert,tiled")
    args = parser.parse_args()
    print(machine_line(), flush=True)
    if args.quick:
        args.restarts, args.restarts_large, args.repeats = min(args.restarts, 1), 0, 1
    cases = set(args.cases.split(","))
    rows: list[tuple[str, str, str, str]] = []
    if "aalto" in cases:
        if AALTO.is_dir():
            x, y, xs, ys = aalto(args.quick)
            compare("Aalto 2-D (uT)", x, y, xs, ys, args, True, args.restarts, rows)
        else:
            print(f"\nAalto data not found at {AALTO}: case 1a skipped")
    if "floor" in cases:
        x, y, xs, truth = floor_2d(args.seed)
        if args.quick:
            keep = np.random.default_rng(args.seed).choice(len(x), 800, replace=False)
            x, y, xs = x[keep], y[keep], xs[::4]
            truth = truth[::4]
        large = not args.skip_sklearn_large
        compare("2-D floor (G)", x, y, xs, truth, args, large, args.restarts_large, rows)
        default_fit(x, y, xs, truth, args, rows)
    if "volume" in cases:
        case_volume(args, rows)
    if "hilbert" in cases:
        case_hilbert(args, rows)
    if "tiled" in cases:
        case_tiled(args, rows)
    print(f"\nload average {os.getloadavg()[0]:.1f} at the end\n")
    print("| case | kiseki | scikit-learn (or paper) | ratio |\n|---|---|---|---|")
    for row in rows:
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
