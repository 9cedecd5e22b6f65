"""One answer per sample from a campaign's trials: their joint fits pooled (issue 41;
``estimation.jointfit.pooling``), with a verdict: ``ok``, ``suspect`` when the pooled record
contradicts a stated belief (which one, by how much) or when most trials are suspect for a
reason pooling does not remove (outside the trusted domain, misaligned, ...), ``none``
without two trials to pool. A sample most of whose trials relax in their hold answers with
its relaxed modulus instead (``estimation.relaxation.pooled``; ``PooledSample.modulus`` says
which), judged on the trials' relaxed verdicts::

    for name, p in pooled_by_sample(outcomes).items():
        print(name, p.fit.modulus, p.status, p.reasons)
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from palpate.estimation.jointfit.beliefcheck import CONTRADICTED
from palpate.estimation.jointfit.pooling import PooledFit, pool
from palpate.estimation.relaxation.pooled import pool_relaxed
from palpate.robot.trial.outcome import Outcome


@dataclass(frozen=True)
class PooledSample:
    """A sample's pooled fit and its verdict (status and reasons)."""

    fit: PooledFit
    status: str
    reasons: tuple[str, ...]
    modulus: str = "elastic"  # or "relaxed": the sample relaxes, its answer is E_inf


POOLABLE = (CONTRADICTED, "imprecise")
"""Suspect reasons the pooled fit decides afresh: the belief check (on the pooled record) and
a wide interval (pooling narrows it). A trial suspect for any other reason (outside the
trusted domain, misaligned, slipping, not done) does not enter a sample's ``ok`` answer."""


def _fitted(o: Outcome) -> bool:
    """A modulus trial (not a rigid reference's calibration) whose joint fit succeeded, with
    a verdict that is not ``none``."""
    j = o.joint
    return o.calibration is None and j is not None and j.success and o.status != "none"


def _clean(o: Outcome) -> bool:
    """A fitted trial whose verdict is ok but for the reasons pooling decides again."""
    reasons = () if o.verdict is None else o.verdict.reasons
    return all(r.startswith(POOLABLE) for r in reasons)


def pooled_sample(outcomes: list[Outcome]) -> PooledSample:
    """A sample's trials pooled: those that are ``ok`` (but for the belief check and a wide
    interval); when fewer than two are, every fitted trial, and the answer is ``suspect`` with
    the reason most of the others share."""
    fitted = [o for o in outcomes if _fitted(o) and o.joint is not None and o.joint.terms]
    relaxing = [o for o in fitted if o.relaxation is not None and o.relaxation.relaxes]
    if len(relaxing) >= 2 and 2 * len(relaxing) > len(fitted):
        return _relaxed(relaxing)
    clean = [o for o in fitted if _clean(o)]
    used: list[Outcome] = clean
    why: tuple[str, ...] = ()
    if len(clean) < 2 and len(fitted) >= 2:
        used = fitted
        first = next(o.verdict.reasons[0] for o in fitted if not _clean(o) and o.verdict)
        why = (f"{len(fitted) - len(clean)} of {len(fitted)} trials are suspect, e.g. {first}",)
    fit = pool([o.joint.terms for o in used if o.joint is not None and o.joint.terms])
    if fit.modulus is None:
        return PooledSample(fit, "none", (fit.message,))
    if fit.contradiction is not None:
        why = (fit.contradiction, *why)
    return PooledSample(fit, "suspect" if why else "ok", why)


CONTRADICTING = 2
"""Trials of a relaxing sample whose relaxed records contradict a stated belief for the sample
to say so (one trial in 72 raised it on the relaxing lung layers told the truth, on each of two
seeds: docs/viscoelastic.md)."""


def _relaxed(relaxing: list[Outcome]) -> PooledSample:
    """A relaxing sample's relaxed modulus: its trials whose relaxed verdict is ``ok``; fewer
    than two, every relaxing trial, ``suspect`` with the first suspect trial's reason; and
    ``suspect`` where ``CONTRADICTING`` or more trials' relaxed records contradict a belief."""
    verdicts = [o.relaxed_verdict for o in relaxing]
    why: tuple[str, ...]
    clean = [o for o, v in zip(relaxing, verdicts, strict=True) if v and v.status == "ok"]
    used, why = clean, ()
    said = [
        w
        for o in relaxing
        if o.relaxation
        for w in o.relaxation.warnings
        if w.startswith(CONTRADICTED)
    ]
    if len(said) >= CONTRADICTING:
        why = (f"{len(said)} of {len(relaxing)} relaxed records say: {said[0]}",)
    if len(clean) < 2:
        used = relaxing
        first = next((v.reasons[0] for v in verdicts if v and v.reasons), "no relaxed verdict")
        suspect = len(relaxing) - len(clean)
        why = (*why, f"{suspect} of {len(relaxing)} relaxed moduli are suspect, e.g. {first}")
    fit = pool_relaxed([o.relaxation for o in used if o.relaxation is not None])
    if fit.modulus is None:
        return PooledSample(fit, "none", (fit.message,), "relaxed")
    return PooledSample(fit, "suspect" if why else "ok", why, "relaxed")


def pooled_by_sample(pairs: Iterable[tuple[str, Outcome]]) -> dict[str, PooledSample]:
    """Per sample name, in the order first met, its trials pooled: ``pairs`` is (sample,
    outcome) of every trial of the run."""
    groups: dict[str, list[Outcome]] = {}
    for name, o in pairs:
        groups.setdefault(name, []).append(o)
    return {name: pooled_sample(outs) for name, outs in groups.items()}


def pooled_fields(p: PooledSample | None, against: float | None) -> dict[str, object]:
    """A sample record's pooled columns (kPa), the relative error and whether the interval
    holds ``against`` (Pa: the true modulus in simulation, the reference on the bench) when it
    is known; ``pooled_delta_chi2``: how much better the best alternative to the stated point
    beliefs fits (negative: worse; None: no point belief)."""
    if p is None:
        return dict.fromkeys(POOLED_COLUMNS)
    f = p.fit
    rel = covered = None
    if f.modulus is not None and against:
        rel = (f.modulus - against) / against
        covered = f.covers(against)
    return {
        "pooled_modulus": p.modulus,
        "pooled_kpa": None if f.modulus is None else f.modulus / 1e3,
        "pooled_ci_low_kpa": None if f.ci_low is None else f.ci_low / 1e3,
        "pooled_ci_high_kpa": None if f.ci_high is None else f.ci_high / 1e3,
        "pooled_verdict": p.status,
        "pooled_reasons": "; ".join(p.reasons),
        "pooled_trials": f.trials,
        "pooled_delta_chi2": max(f.gains.values(), default=None),
        "pooled_relative_error": rel,
        "pooled_interval_holds_truth": covered,
    }


POOLED_COLUMNS = (
    "pooled_modulus",
    "pooled_kpa",
    "pooled_ci_low_kpa",
    "pooled_ci_high_kpa",
    "pooled_verdict",
    "pooled_reasons",
    "pooled_trials",
    "pooled_delta_chi2",
    "pooled_relative_error",
    "pooled_interval_holds_truth",
)
