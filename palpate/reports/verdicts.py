"""Verdict tallies of a campaign: how many trials are ok, suspect or none, and what the numbers
are worth. Medians and worst errors are taken over ``ok`` trials only; the interval's coverage
over every trial with a number (``ok`` and ``suspect``), so a suspect estimate is never
silently counted as good, and its interval is still held to account."""

from __future__ import annotations

import re
import statistics
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from palpate.estimation.jointfit import JointFit
from palpate.estimation.verdict import STATUSES
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


Reading = Callable[[TrialOutcome], tuple[str, float | None, bool]]


def joint_reading(o: TrialOutcome) -> tuple[str, float | None, bool]:
    """The joint fit's (verdict, modulus Pa, whether its interval holds the truth)."""
    jf = o.joint
    return (
        o.status,
        None if jf is None else jf.modulus,
        jf is not None and jf.covers(o.spec.modulus),
    )


def relaxed_reading(o: TrialOutcome) -> tuple[str, float | None, bool]:
    """The relaxed modulus's (verdict, modulus Pa, whether its interval holds the truth)."""
    fit, verdict = o.relaxation, o.relaxed_verdict
    status = "none" if verdict is None else verdict.status
    return (
        status,
        None if fit is None else fit.relaxed,
        fit is not None and fit.covers(o.spec.modulus),
    )


def tally(outcomes: Iterable[TrialOutcome], reading: Reading = joint_reading) -> Tally:
    """The :class:`Tally` of ``outcomes`` (rigid references are left out) by ``reading``: the
    joint fit's estimate, or another of each trial's numbers (``relaxed_reading``)."""
    outs = estimating(outcomes)
    read = [(o, *reading(o)) for o in outs]
    counts: dict[str, int] = {s: sum(1 for r in read if r[1] == s) for s in STATUSES}
    numbered = [r for r in read if r[1] != "none" and r[2] is not None]
    errors = [(abs(m / o.spec.modulus - 1), status) for o, status, m, _ in numbered if m]
    ok = [e for e, status in errors if status == "ok"]
    every = [e for e, _ in errors]
    seconds = [o.joint_seconds for o in outs if o.joint_seconds is not None]
    return Tally(
        trials=len(outs),
        counts=counts,
        numbers=len(numbered),
        covered=sum(1 for r in numbered if r[3]),
        median_ok=_median(ok),
        worst_ok=max(ok) if ok else None,
        median_all=_median(every),
        worst_all=max(every) if every else None,
        ms_per_trial=1e3 * statistics.median(seconds) if seconds else None,
    )


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
    """``suspect``/``none`` reasons with how many trials give each (the most frequent first);
    reasons that differ only in their figures count as one, shown by their first ("e.g.")."""
    seen: dict[tuple[str, str], list[str]] = {}
    for o in estimating(outcomes):
        if o.verdict is None or o.verdict.status == "ok":
            continue
        for r in o.verdict.reasons:
            text = _headline(r)
            seen.setdefault((o.verdict.status, _FIGURE.sub("#", text)), []).append(text)
    ranked = sorted(seen.items(), key=lambda kv: -len(kv[1]))[:limit]
    return [
        f"{len(texts):>4} x {status}: {'' if len(set(texts)) == 1 else 'e.g. '}{texts[0]}"
        for (status, _), texts in ranked
    ]


_FIGURE = re.compile(r"[-+]?\d+(?:\.\d+)?")


def _headline(reason: str) -> str:
    """A reason without its parenthesis and a belief check's ": delta chi^2 = ...".

    >>> _headline("the record prefers a 5 mm layer to the stated 10 mm: delta chi^2 = 125")
    'the record prefers a 5 mm layer to the stated 10 mm'
    """
    head, _, _ = reason.partition(" (")
    head, _, _ = head.partition(": delta chi^2 =")
    return head


@dataclass(frozen=True)
class RelaxedTally:
    """The trials that held after buckling: how many, how many relax, and the :class:`Tally`
    of their relaxed moduli (``relaxed_reading``)."""

    held: int
    relaxes: int
    numbers: Tally

    def as_dict(self) -> dict[str, object]:
        out = self.numbers.as_dict()
        del out["fit_ms_per_trial"], out["trials"]
        return {"held": self.held, "relaxes": self.relaxes, **out}


def relaxed_tally(outcomes: Iterable[TrialOutcome]) -> RelaxedTally:
    """The :class:`RelaxedTally` of the trials among ``outcomes`` that held."""
    held = [o for o in estimating(outcomes) if o.relaxation is not None]
    relaxes = sum(1 for o in held if o.relaxation is not None and o.relaxation.relaxes)
    return RelaxedTally(len(held), relaxes, tally(held, relaxed_reading))


def classified(outcomes: Iterable[TrialOutcome], threshold: float) -> dict[str, object]:
    """How the joint fit's numbers sort the samples at a diagnostic ``threshold`` (Pa): of the
    trials with a number (ok, suspect), how many fall on the true side, and of the ok ones; and
    of those whose 95 % interval lies wholly on one side (``decided``: the trial's own call;
    the others say the side is not known), how many on the true side."""
    rows = [
        (o.status, o.joint, o.joint.modulus, o.spec.modulus)
        for o in estimating(outcomes)
        if o.status != "none" and o.joint is not None and o.joint.modulus is not None
    ]
    calls = [
        (s, modulus >= threshold, true >= threshold, _side(j, threshold))
        for s, j, modulus, true in rows
    ]
    right = [s for s, m, true, _ in calls if m == true]
    decided = [(side, true) for _, _, true, side in calls if side is not None]
    return {
        "threshold_kpa": threshold / 1e3,
        "with_number": len(rows),
        "right_side": len(right),
        "ok": sum(1 for s, *_ in rows if s == "ok"),
        "ok_right_side": sum(1 for s in right if s == "ok"),
        "decided": len(decided),
        "decided_right_side": sum(1 for side, true in decided if side == true),
    }


def _side(joint: JointFit, threshold: float) -> bool | None:
    """True: the interval lies above ``threshold``, False: below, None: across it (or none)."""
    if joint.ci_low is None or joint.ci_high is None:
        return None
    if joint.ci_low >= threshold:
        return True
    return False if joint.ci_high < threshold else None


def classified_line(outcomes: Sequence[TrialOutcome], threshold: float | None) -> list[str]:
    """``palpate sim``'s line of :func:`classified` (none without a threshold)."""
    if threshold is None:
        return []
    c = classified(outcomes, threshold)
    return [
        f"at the scene's threshold of {c['threshold_kpa']:g} kPa: {c['right_side']}/"
        f"{c['with_number']} trials with a number on the true side ({c['ok_right_side']}/"
        f"{c['ok']} ok); {c['decided_right_side']}/{c['decided']} of those whose interval lies "
        "on one side (the others' intervals cross it)"
    ]


def verdict_payload(
    outcomes: Sequence[TrialOutcome], threshold: float | None = None
) -> dict[str, object]:
    """``--json``'s ``verdicts`` (and ``relaxed`` when trials held, ``classified`` with a
    diagnostic threshold, Pa)."""
    out: dict[str, object] = {"verdicts": tally(outcomes).as_dict()}
    if threshold is not None:
        out["classified"] = classified(outcomes, threshold)
    held = relaxed_tally(outcomes)
    if held.held:
        out["relaxed"] = held.as_dict()
    return out


def relaxed_lines(outcomes: Sequence[TrialOutcome]) -> list[str]:
    """The relaxed moduli's lines of ``palpate sim`` (none without a hold)."""
    held = relaxed_tally(outcomes)
    if not held.held:
        return []
    r = held.numbers
    lines = [
        f"held after buckling: {held.held} trials, {held.relaxes} relax; relaxed modulus "
        f"verdicts: {counts_text(r)}"
    ]
    if r.numbers:
        lines.append(
            f"95 % interval of the relaxed modulus holds the truth in {r.covered}/{r.numbers}"
        )
    if r.median_ok is not None and r.worst_ok is not None:
        lines.append(
            f"relaxed modulus |relative error| over ok: median {100 * r.median_ok:.1f} %, "
            f"worst {100 * r.worst_ok:.1f} %"
        )
    return lines


def summary_lines(outcomes: Sequence[TrialOutcome]) -> list[str]:
    """What ``palpate sim`` prints under its table: the verdicts, the coverage, the errors (and
    the relaxed moduli of trials that held)."""
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
    return lines + retried_lines(outcomes) + relaxed_lines(outcomes)


def retried_lines(outcomes: Sequence[TrialOutcome]) -> list[str]:
    """How many trials buckled unread and ran again at a shorter exposed length
    (``campaign.retry_lengths_mm``), and how many of those then read (none without one)."""
    again = [o for o in outcomes if o.tried]
    if not again:
        return []
    read = sum(1 for o in again if o.modulus("joint") is not None)
    return [
        f"{len(again)} trials buckled without an estimate and ran again at a shorter exposed "
        f"length (campaign.retry_lengths_mm): {read} of them read there"
    ]
