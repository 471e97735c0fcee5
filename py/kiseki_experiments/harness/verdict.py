# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
"""Verdicts that can fail and say how sure they are.

A claim is declared before any trial runs (:class:`ClaimSpec`): its text, its :class:`Criterion`
(the paper's value, the comparison, the threshold and tolerance, why that tolerance, and the
bounds of the measured quantity) and its :class:`Control` (a config override under which the
criterion must fail). The analysis then hands the harness the per-trial evidence of each claim
(:class:`Evidence`: one value per trial, or k successes of n); the harness gives the measured
value, a 95 % interval (percentile bootstrap of the mean or median, B. Efron and R. Tibshirani,
*An Introduction to the Bootstrap*, 1993, ch. 13, with a generator seeded from the run's seed;
the Wilson score interval for a share) and the verdict: ``holds`` when the whole interval meets
the criterion, ``fails`` when none of it does, ``inconclusive`` when it straddles it."""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass
from typing import Literal

import numpy as np

from kiseki.metrics import wilson_interval

__all__ = [
    "BOOTSTRAP_RESAMPLES",
    "MIN_TRIALS",
    "MOST_TRIALS",
    "SEARCH_RESAMPLES",
    "UNMIGRATED",
    "VERDICT_COLUMNS",
    "ClaimSpec",
    "Control",
    "Criterion",
    "Estimate",
    "Evidence",
    "Verdict",
    "decide",
    "estimate",
    "judge",
    "trials_to_decide",
]

BOOTSTRAP_RESAMPLES = 4000
"""Resamples of a percentile bootstrap: the 2.5 % and 97.5 % quantiles of 4000 resampled means
move by well under a tenth of the interval's width between generators."""
SEARCH_RESAMPLES = 1000
"""Resamples per trial count tried when searching the trials that would decide a claim: an
estimate, so fewer than the interval's own."""
MOST_TRIALS = 10_000
"""The most trials that search tries for per-trial values: a claim no count up to it decides
sits on its threshold for any run kiseki would make."""
MIN_TRIALS = 5
"""Fewest per-trial values a bootstrap interval is computed from: below it the resamples take
too few distinct values and the interval is far too narrow (no verdict, ``inconclusive``)."""
UNMIGRATED = "no interval (not yet migrated)"
"""The verdict shown for a claim of a results folder written before claims had intervals (a
point verdict): never counted as decided."""

Compare = Literal["<=", ">=", "within"]
Outcome = Literal["holds", "fails", "inconclusive"]


@dataclass(frozen=True)
class Criterion:
    """What the measured quantity must satisfy, fixed before the run.

    ``compare`` is ``"<="`` or ``">="`` against ``threshold``, or ``"within"``: inside
    ``threshold +- tolerance``. ``why`` says where the threshold and tolerance come from (the
    paper, a sensor's resolution, a share of v_max). ``bounds`` is the quantity's own range (a
    share [0, 1], an error [0, inf), a difference of shares [-1, 1]): a criterion that its bounds
    already satisfy cannot fail and is refused by :meth:`problems`. ``paper_number`` is the
    paper's printed number when there is one (checked against the scenes' calibration marks)."""

    paper_value: str
    compare: Compare
    threshold: float
    why: str
    tolerance: float = 0.0
    bounds: tuple[float, float] = (-math.inf, math.inf)
    paper_number: float | None = None

    def band(self) -> tuple[float, float]:
        """The values that meet the criterion, as a closed interval."""
        if self.compare == "<=":
            return (-math.inf, self.threshold)
        if self.compare == ">=":
            return (self.threshold, math.inf)
        return (self.threshold - self.tolerance, self.threshold + self.tolerance)

    def text(self) -> str:
        if self.compare == "within":
            return f"within {self.threshold:g} +- {self.tolerance:g}"
        return f"{self.compare} {self.threshold:g}"

    def problems(self) -> list[str]:
        """Why this criterion cannot decide anything (empty when it can): met by every value
        in the quantity's bounds, or by none of them."""
        low, high = self.bounds
        a, b = self.band()
        out = []
        if self.compare not in ("<=", ">=", "within"):
            out.append(f"unknown comparison {self.compare!r}")
        if not self.why.strip():
            out.append("no reason given for the threshold (why)")
        if self.compare == "within" and not self.tolerance > 0:
            out.append("'within' needs a tolerance > 0")
        if a <= low and b >= high:
            out.append(f"{self.text()} holds for every value in the bounds [{low:g}, {high:g}]")
        if b < low or a > high:
            out.append(f"{self.text()} holds for no value in the bounds [{low:g}, {high:g}]")
        return out


@dataclass(frozen=True)
class Control:
    """A named config override (``--set`` items) under which the claim's criterion must fail,
    and the trials (``runs``) it needs to fail decidedly; ``why`` says why it must fail.
    ``minutes`` marks a control whose run takes minutes (a teaching route played back several
    times): the test suite runs it only when asked to (KISEKI_TEST_HEAVY=1)."""

    name: str
    overrides: tuple[str, ...]
    runs: int
    why: str = ""
    minutes: bool = False


@dataclass(frozen=True)
class ClaimSpec:
    """A claim as declared before the run: ``key`` joins it to its :class:`Evidence`;
    ``measure`` says what one trial contributes (the statistic over trials is the Evidence's)."""

    key: str
    claim: str
    unit: str
    criterion: Criterion
    control: Control | None
    measure: str = ""


@dataclass(frozen=True)
class Evidence:
    """The per-trial evidence of a declared claim: ``values`` (one per trial; a difference
    between two arms is one value per trial of arm a - arm b on the same seed) summarised by
    ``statistic``, or ``successes`` of ``trials`` for a share. ``subject`` names what the claim
    is about when it is made once per log or setting; ``shown`` adds context to the value."""

    key: str
    values: tuple[float, ...] = ()
    statistic: Literal["mean", "median"] = "mean"
    successes: int | None = None
    trials: int | None = None
    subject: str = ""
    shown: str = ""
    note: str = ""

    @classmethod
    def of(cls, key: str, values, statistic: Literal["mean", "median"] = "mean", **kw):
        return cls(key, tuple(float(v) for v in values), statistic, **kw)

    @classmethod
    def share(cls, key: str, successes: int, trials: int, **kw):
        return cls(key, successes=int(successes), trials=int(trials), **kw)


@dataclass(frozen=True)
class Estimate:
    value: float
    low: float
    high: float
    n: int
    share: bool = False  # a Wilson interval of k of n (not a bootstrap)


def _generator(seed: int, evidence: Evidence) -> np.random.Generator:
    """One generator per (run seed, claim, subject): a claim's interval does not depend on
    which other claims were judged before it."""
    return np.random.default_rng([int(seed) % 2**63, _tag(evidence)])


def _tag(evidence: Evidence) -> int:
    return zlib.crc32(f"{evidence.key}\0{evidence.subject}".encode())


def estimate(evidence: Evidence, seed: int) -> Estimate:
    """The measured value and its 95 % interval (NaN ends when there is too little evidence)."""
    if evidence.trials is not None:
        k, n = int(evidence.successes or 0), int(evidence.trials)
        low, high = wilson_interval(k, n)
        return Estimate(k / n if n else math.nan, low, high, n, share=True)
    x, stat = _values(evidence)
    if x.size == 0:
        return Estimate(math.nan, math.nan, math.nan, 0)
    value = float(stat(x))
    if x.size < MIN_TRIALS:
        return Estimate(value, math.nan, math.nan, int(x.size))
    low, high = _percentile_interval(
        x, stat, x.size, BOOTSTRAP_RESAMPLES, _generator(seed, evidence)
    )
    return Estimate(value, low, high, int(x.size))


def _values(evidence: Evidence):
    """The per-trial values (an infinite one, never back or never converged, stays and counts)
    and the statistic over them."""
    x = np.asarray(evidence.values, dtype=float)
    return x[~np.isnan(x)], np.median if evidence.statistic == "median" else np.mean


def _percentile_interval(x, stat, size: int, resamples: int, rng) -> tuple[float, float]:
    """The percentile bootstrap's 95 % interval of ``stat`` over ``resamples`` samples of
    ``size`` values drawn from ``x``: the empirical quantiles themselves (no interpolation
    between resamples: an infinite value gives an infinite end, not inf - inf). Drawn in blocks
    of about four million values; up to 1,000 values at 4,000 resamples that is one draw."""
    rows = max(1, 4 * 10**6 // size)
    resampled = np.concatenate(
        [
            stat(x[rng.integers(0, x.size, (min(rows, resamples - k), size))], axis=1)
            for k in range(0, resamples, rows)
        ]
    )
    low, high = np.quantile(resampled, [0.025, 0.975], method="inverted_cdf")
    return float(low), float(high)


def decide(criterion: Criterion, est: Estimate) -> Outcome:
    """holds: the interval lies inside the criterion's band; fails: it lies outside;
    inconclusive: it straddles an edge (or there is no interval)."""
    if math.isnan(est.low) or math.isnan(est.high):
        return "inconclusive"
    a, b = criterion.band()
    if a <= est.low and est.high <= b:
        return "holds"
    if est.high < a or est.low > b:
        return "fails"
    return "inconclusive"


def trials_to_decide(
    criterion: Criterion, est: Estimate, evidence: Evidence | None = None, seed: int = 0
) -> int | None:
    """Trials that would decide an undecided claim. An estimate: the value itself moves with
    more trials. None when no count decides it (the value sits on an edge of the band).

    * a share: the fewest trials whose Wilson interval at the same share is decided (searched);
    * per-trial values given (``evidence``): the fewest trials m whose bootstrap interval, of m
      values drawn from the ones measured, is decided (searched up to :data:`MOST_TRIALS`). A
      rare large value (a lost seed among tracked ones) keeps the interval wide until a
      resample without it is rarer than 2.5 %, which no 1/sqrt(n) scaling foresees;
    * an interval alone: its half-width h at n trials scaling as 1/sqrt(n): n * (h / d)^2, d
      the distance from the value to the nearest edge of the criterion's band and h the
      interval's arm on that side (the interval must shrink inside the band, or away from it).
    """
    if est.n == 0 or math.isnan(est.value):
        return None
    if est.share:
        return _searched(est.n, _share_decides(criterion, est), 10**7)
    if math.isnan(est.low):  # too few trials for an interval
        return MIN_TRIALS
    if evidence is not None and evidence.values:
        decided = _bootstrap_decides(criterion, est, evidence, seed)
        return _searched(est.n, decided, MOST_TRIALS)
    a, b = criterion.band()
    edge = a if abs(est.value - a) <= abs(est.value - b) else b
    d = abs(est.value - edge)
    # the interval's arm on the edge's side (a Wilson interval is not symmetric)
    half = est.value - est.low if edge <= est.value else est.high - est.value
    if d == 0 or not math.isfinite(d) or not math.isfinite(half):
        return None
    return max(est.n + 1, math.ceil(est.n * (half / d) ** 2))


def _share_decides(criterion: Criterion, est: Estimate):
    """Whether m trials at the same share decide the claim (a share at 0 or 1 narrows as 1/m,
    not 1/sqrt(m))."""

    def decided(m: int) -> bool:
        low, high = wilson_interval(round(est.value * m), m)
        return decide(criterion, Estimate(est.value, low, high, m)) != "inconclusive"

    return decided


def _bootstrap_decides(criterion: Criterion, est: Estimate, evidence: Evidence, seed: int):
    """Whether the bootstrap interval of m values drawn from the measured ones decides the
    claim; each m with its own generator (from the run's seed), so the answer is reproducible."""
    x, stat = _values(evidence)

    def decided(m: int) -> bool:
        rng = np.random.default_rng([int(seed) % 2**63, _tag(evidence), m])
        low, high = _percentile_interval(x, stat, m, SEARCH_RESAMPLES, rng)
        return decide(criterion, Estimate(est.value, low, high, m)) != "inconclusive"

    return decided


def _searched(n: int, decided, most: int) -> int | None:
    """The fewest trials m > n with decided(m), found by doubling, then bisection; None when
    no m up to ``most`` decides it."""
    low, high = n, max(n + 1, 2 * n)
    while not decided(high):
        low, high = high, 2 * high
        if high > most:
            return None  # on the threshold: no number of trials decides it
    while high - low > 1:
        mid = (low + high) // 2
        low, high = (low, mid) if decided(mid) else (mid, high)
    return high


@dataclass(frozen=True)
class Verdict:
    """A claim's row in claims.csv and the reports."""

    claim: str
    paper_value: str
    measured_value: float | str
    ci_low: float
    ci_high: float
    unit: str
    criterion: str
    verdict: str
    trials: int
    trials_to_decide: float  # NaN when decided (or when no number of trials decides it)
    control: str
    note: str
    # verdict == "holds" (the tests read it; in an old results folder, the point verdict). No
    # report counts it; the verdict decides.
    holds: bool = False


VERDICT_COLUMNS = [f for f in Verdict.__dataclass_fields__]


def judge(specs: tuple[ClaimSpec, ...], evidence: list[Evidence], seed: int) -> list[Verdict]:
    """The verdict of every piece of evidence, in the order given, against its declared claim;
    evidence for a key no claim declares is a ValueError (a claim is declared before the run)."""
    by_key = {s.key: s for s in specs}
    out = []
    for e in evidence:
        if e.key not in by_key:
            raise ValueError(f"evidence for {e.key!r}, which no claim declares")
        spec = by_key[e.key]
        est = estimate(e, seed)
        outcome = decide(spec.criterion, est)
        more = trials_to_decide(spec.criterion, est, e, seed) if outcome == "inconclusive" else None
        shown = f"{est.value:.4g}" + (f" ({e.shown})" if e.shown else "")
        out.append(
            Verdict(
                claim=spec.claim + (f" [{e.subject}]" if e.subject else ""),
                paper_value=spec.criterion.paper_value,
                measured_value=shown,
                ci_low=est.low,
                ci_high=est.high,
                unit=spec.unit,
                criterion=spec.criterion.text() + f" ({spec.criterion.why})",
                verdict=outcome,
                trials=est.n,
                trials_to_decide=math.nan if more is None else float(more),
                control=spec.control.name if spec.control else "",
                note=e.note,
                holds=outcome == "holds",
            )
        )
    return out
