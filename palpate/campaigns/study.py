"""A coverage study's statistics: how wrong the estimates are and how often the interval holds
the truth, each figure with its own 95 % confidence bounds.

Distribution-free and deterministic (no resampling, so a study's report is a function of its
trials):

- a proportion (interval coverage, the fraction of trials with a number) gets the Wilson score
  interval (:func:`wilson`), which keeps its level near 0 and 1 where the normal one does not;
- a quantile of |relative error| (the median, the 95th percentile) gets the order-statistic
  interval (:func:`quantile_interval`): the ranks r < s with
  P(r <= B <= s - 1) >= 95 %, B ~ Binomial(n, q), so [x_(r), x_(s)] covers the true quantile
  whatever the distribution; a bound that would need a rank outside 1..n is None (too few trials);
- the worst |relative error| is the sample maximum, reported as seen: no interval of any kind
  bounds a maximum from a finite sample, so the 95th percentile carries the bounds for the tail.

:func:`summarize_study` applies them per sample and over all trials, for the joint fit (whose
interval is the one tested) and for the paper's estimate (which has none).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

Z95 = 1.959963984540054  # two-sided 95 % normal quantile
LEVEL = 0.95


@dataclass(frozen=True)
class Bounded:
    """An estimate with its confidence interval (None: not enough data for that bound)."""

    value: float | None
    low: float | None
    high: float | None

    def as_dict(self) -> dict[str, float | None]:
        return {"value": self.value, "low": self.low, "high": self.high}


def wilson(successes: int, trials: int, z: float = Z95) -> Bounded:
    """The proportion successes/trials with its Wilson score interval (None if no trials)."""
    if not 0 <= successes <= trials:
        raise ValueError(f"need 0 <= successes <= trials, got {successes} of {trials}")
    if trials == 0:
        return Bounded(None, None, None)
    p = successes / trials
    z2 = z * z
    centre = (p + z2 / (2 * trials)) / (1 + z2 / trials)
    half = z / (1 + z2 / trials) * math.sqrt(p * (1 - p) / trials + z2 / (4 * trials * trials))
    low = 0.0 if successes == 0 else max(0.0, centre - half)  # exact ends, not 1 - 1e-16
    high = 1.0 if successes == trials else min(1.0, centre + half)
    return Bounded(p, low, high)


def quantile_interval(values: Sequence[float], q: float, level: float = LEVEL) -> Bounded:
    """The q-quantile of ``values`` (numpy's linear interpolation) with the distribution-free
    order-statistic interval at ``level`` (see the module docstring)."""
    if not 0 < q < 1 or not 0 < level < 1:
        raise ValueError(f"need 0 < q < 1 and 0 < level < 1, got q={q}, level={level}")
    x = np.sort(np.asarray(values, dtype=float))
    n = x.size
    if n == 0:
        return Bounded(None, None, None)
    value = float(np.quantile(x, q))
    tail = (1 - level) / 2
    cdf = binomial_cdf(n, q)  # cdf[k] = P(B <= k)
    below = np.nonzero(cdf <= tail)[0]  # r - 1 = the largest k with P(B <= k) <= tail
    above = np.nonzero(cdf >= 1 - tail)[0]  # s - 1 = the smallest k with P(B <= k) >= 1 - tail
    r = int(below[-1]) + 1 if below.size else 0
    s = int(above[0]) + 1 if above.size else n + 1
    low = float(x[r - 1]) if r >= 1 else None
    high = float(x[s - 1]) if s <= n else None
    return Bounded(value, low, high)


def binomial_cdf(n: int, p: float) -> NDArray[np.float64]:
    """P(B <= k) for k = 0..n, B ~ Binomial(n, p), 0 < p < 1 (log-space terms: no underflow
    of p**k for the thousands of trials of a study)."""
    k = np.arange(n + 1, dtype=float)
    log_choose = np.array(
        [math.lgamma(n + 1) - math.lgamma(i + 1) - math.lgamma(n - i + 1) for i in range(n + 1)]
    )
    log_pmf = log_choose + k * math.log(p) + (n - k) * math.log1p(-p)
    cdf: NDArray[np.float64] = np.minimum(np.cumsum(np.exp(log_pmf)), 1.0)
    return cdf


@dataclass(frozen=True)
class TrialErrors:
    """What the study needs from one trial: the truth, both estimates and the joint interval."""

    sample: str
    truth: float  # Pa
    joint: float | None
    joint_low: float | None
    joint_high: float | None
    paper: float | None


@dataclass(frozen=True)
class MethodStats:
    """One estimator over a group of trials."""

    trials: int
    with_number: Bounded  # fraction of trials with an estimate
    median_abs_rel_error: Bounded
    p95_abs_rel_error: Bounded
    max_abs_rel_error: float | None  # the worst seen (no interval: see the module docstring)
    coverage: Bounded | None = None  # fraction of intervals holding the truth (joint fit only)

    def as_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "trials": self.trials,
            "with_number": self.with_number.as_dict(),
            "median_abs_rel_error": self.median_abs_rel_error.as_dict(),
            "p95_abs_rel_error": self.p95_abs_rel_error.as_dict(),
            "max_abs_rel_error": self.max_abs_rel_error,
        }
        if self.coverage is not None:
            out["coverage"] = self.coverage.as_dict()
        return out


def method_stats(
    truth: Sequence[float],
    estimates: Sequence[float | None],
    intervals: Sequence[tuple[float | None, float | None]] | None = None,
) -> MethodStats:
    """Errors (and, with ``intervals``, coverage) of one estimator over a group of trials.

    Coverage counts the trials whose interval has both ends and holds the truth, over the trials
    with an interval."""
    errors = [abs(e - a) / a for a, e in zip(truth, estimates, strict=True) if e is not None and a]
    n = len(truth)
    coverage = None
    if intervals is not None:
        closed = [
            (a, lo, hi)
            for a, (lo, hi) in zip(truth, intervals, strict=True)
            if lo is not None and hi is not None
        ]
        held = sum(1 for a, lo, hi in closed if lo <= a <= hi)
        coverage = wilson(held, len(closed))
    return MethodStats(
        trials=n,
        with_number=wilson(sum(1 for e in estimates if e is not None), n),
        median_abs_rel_error=quantile_interval(errors, 0.5),
        p95_abs_rel_error=quantile_interval(errors, 0.95),
        max_abs_rel_error=max(errors) if errors else None,
        coverage=coverage,
    )


@dataclass(frozen=True)
class GroupStats:
    """The joint fit and the paper's estimate over one group (a sample, or every trial)."""

    name: str
    truth: float | None  # Pa, the group's true modulus (None for the whole study)
    joint: MethodStats
    paper: MethodStats

    def as_dict(self) -> dict[str, Any]:
        return {
            "group": self.name,
            "true_kpa": None if self.truth is None else self.truth / 1e3,
            "joint": self.joint.as_dict(),
            "paper": self.paper.as_dict(),
        }


@dataclass(frozen=True)
class StudySummary:
    per_sample: list[GroupStats] = field(default_factory=list)
    overall: GroupStats | None = None

    def as_dict(self) -> dict[str, Any]:
        return {
            "per_sample": [g.as_dict() for g in self.per_sample],
            "overall": None if self.overall is None else self.overall.as_dict(),
            "level": LEVEL,
        }


def _group(name: str, truth: float | None, trials: Sequence[TrialErrors]) -> GroupStats:
    truths = [t.truth for t in trials]
    return GroupStats(
        name,
        truth,
        joint=method_stats(
            truths, [t.joint for t in trials], [(t.joint_low, t.joint_high) for t in trials]
        ),
        paper=method_stats(truths, [t.paper for t in trials]),
    )


def summarize_study(trials: Iterable[TrialErrors]) -> StudySummary:
    """Per sample (in the order first seen) and overall."""
    groups: dict[str, list[TrialErrors]] = {}
    for t in trials:
        groups.setdefault(t.sample, []).append(t)
    per_sample = [_group(name, ts[0].truth, ts) for name, ts in groups.items()]
    everything = [t for ts in groups.values() for t in ts]
    return StudySummary(per_sample, _group("all", None, everything))
