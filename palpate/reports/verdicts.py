"""Verdict tallies of a campaign: how many trials are ok, suspect or none, and what the numbers
are worth. Medians and worst errors are taken over ``ok`` trials only; the interval's coverage
over every trial with a number (``ok`` and ``suspect``), so a suspect estimate is never
silently counted as good, and its interval is still held to account."""

from __future__ import annotations

import statistics
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from estimation.verdict import STATUSES
from palpate.simulation.trial import TrialOutcome


@dataclass(frozen=True)
class Tally:
    """One group of trials' verdicts and errors (relative errors as fractions).

    Attributes:
        trials: trials that estimate a modulus (rigid references left out).
        counts: trials per verdict (``ok``, ``suspect``, ``none``).
        numbers: trials with a number (``ok`` and ``suspect``); covered: of those, the ones
            whose interval holds the true modulus.
        median_ok, worst_ok: |relative error| over ``ok`` trials (None without one).
        median_all, worst_all: the same over every trial with a number.
        ms_per_trial: median wall time of the joint fit (None without one).
    """

    trials: int
    counts: dict[str, int]
    numbers: int
    covered: int
    median_ok: float | None
    worst_ok: float | None
    median_all: float | None
    worst_all: float | None
    ms_per_trial: float | None

    @property
    def coverage(self) -> float | None:
        return self.covered / self.numbers if self.numbers else None

    def as_dict(self) -> dict[str, object]:
        return {
            "trials": self.trials,
            "verdicts": dict(self.counts),
            "with_number": self.numbers,
            "covered": self.covered,
            "coverage": self.coverage,
            "median_abs_rel_err_ok": self.median_ok,
            "worst_abs_rel_err_ok": self.worst_ok,
            "median_abs_rel_err_all": self.median_all,
            "worst_abs_rel_err_all": self.worst_all,
            "fit_ms_per_trial": self.ms_per_trial,
        }


def estimating(outcomes: Iterable[TrialOutcome]) -> list[TrialOutcome]:
    """The trials that estimate a modulus (not the calibrations on rigid references)."""
    return [o for o in outcomes if o.calibration is None]


def tally(outcomes: Iterable[TrialOutcome]) -> Tally:
    """The :class:`Tally` of ``outcomes`` (rigid references are left out)."""
    outs = estimating(outcomes)
    counts: dict[str, int] = {s: sum(1 for o in outs if o.status == s) for s in STATUSES}
    numbered = [o for o in outs if o.status != "none" and o.joint is not None]
    errors = {id(o): _error(o) for o in numbered}
    ok = [abs(errors[id(o)]) for o in numbered if o.status == "ok"]
    every = [abs(e) for e in errors.values()]
    covered = sum(1 for o in numbered if o.joint is not None and o.joint.covers(o.spec.modulus))
    seconds = [o.joint_seconds for o in outs if o.joint_seconds is not None]
    return Tally(
        trials=len(outs),
        counts=counts,
        numbers=len(numbered),
        covered=covered,
        median_ok=_median(ok),
        worst_ok=max(ok) if ok else None,
        median_all=_median(every),
        worst_all=max(every) if every else None,
        ms_per_trial=1e3 * statistics.median(seconds) if seconds else None,
    )


def _error(o: TrialOutcome) -> float:
    m = o.joint.modulus if o.joint is not None else None
    return 0.0 if m is None else (m - o.spec.modulus) / o.spec.modulus


def _median(values: Sequence[float]) -> float | None:
    return statistics.median(values) if values else None


def counts_text(t: Tally) -> str:
    """``12 ok, 3 suspect, 1 none``."""
    return ", ".join(f"{t.counts[s]} {s}" for s in STATUSES)


def counts_column(t: Tally) -> str:
    """``12/3/1``: the tables' ok/sus/none column."""
    return "/".join(str(t.counts[s]) for s in STATUSES)


def by_sample(outcomes: Iterable[TrialOutcome]) -> dict[str, Tally]:
    """A :class:`Tally` per sample (rigid references left out), in the outcomes' order."""
    groups: dict[str, list[TrialOutcome]] = {}
    for o in estimating(outcomes):
        groups.setdefault(o.spec.sample, []).append(o)
    return {name: tally(outs) for name, outs in groups.items()}


def reason_lines(outcomes: Iterable[TrialOutcome], limit: int = 8) -> list[str]:
    """``suspect``/``none`` reasons with how many trials give each (the most frequent first)."""
    seen: dict[tuple[str, str], int] = {}
    for o in estimating(outcomes):
        if o.verdict is None or o.verdict.status == "ok":
            continue
        for r in o.verdict.reasons:
            key = (o.verdict.status, _generic(r))
            seen[key] = seen.get(key, 0) + 1
    ranked = sorted(seen.items(), key=lambda kv: -kv[1])[:limit]
    return [f"{n:>4} x {status}: {reason}" for (status, reason), n in ranked]


def _generic(reason: str) -> str:
    """A reason without its numbers after the first colon (so trials group by kind)."""
    head, _, _ = reason.partition(" (")
    return head


def summary_lines(outcomes: Sequence[TrialOutcome]) -> list[str]:
    """What ``palpate sim`` prints under its table: the verdicts, the coverage, the errors."""
    t = tally(outcomes)
    lines = [f"verdicts: {counts_text(t)} (of {t.trials} trials estimating a modulus)"]
    if t.numbers:
        lines.append(
            f"95 % interval holds the true modulus in {t.covered}/{t.numbers} trials with a "
            "number (ok and suspect)"
        )
    if t.median_ok is not None and t.worst_ok is not None:
        lines.append(
            f"|relative error| over ok trials: median {100 * t.median_ok:.1f} %, "
            f"worst {100 * t.worst_ok:.1f} %"
        )
    lines += reason_lines(outcomes)
    return lines
